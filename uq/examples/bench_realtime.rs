//! Time per sample of the real-time surrogate and its held-out error table:
//! `cargo run --release -p palpate-uq --example bench_realtime -- SURROGATE.json`
//! (as `palpate surrogate build` stores it). Runs 2e6 samples of a 1 kHz
//! random history (ramps, holds, unloadings) on one thread.

use palpate_uq::surrogate::realtime::{random_history, RealTimeSurrogate};

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: bench_realtime SURROGATE.json");
    let text = std::fs::read_to_string(&path).expect("read the surrogate");
    let mut s = RealTimeSurrogate::from_json(&text).expect("a real-time surrogate");
    let h = random_history(7, s.depth_max, 400, 1e-3);
    let n = 2_000_000usize;
    let t0 = std::time::Instant::now();
    let mut sum = 0.0;
    let mut k = 0;
    for _ in 0..n {
        sum += s.force(h.depth[k], 1e-3).expect("in range");
        k = (k + 1) % h.depth.len();
    }
    let per = t0.elapsed().as_secs_f64() / n as f64;
    println!("{}", s.model);
    match &s.kernel {
        Some(k) => println!(
            "memory kernel: {} knots, {} time constants, {} stop operators, loss of contact {}",
            k.knots,
            k.taus.len(),
            k.stops.len(),
            if !k.lift_off {
                "clamps".to_string()
            } else if k.soft_contact[0] == 0.0 {
                "frees the surface".to_string()
            } else {
                format!("compliant over {:.3} mm", k.soft_contact[0])
            }
        ),
        None => println!("plain QLV on the force curve"),
    }
    println!(
        "| samples | time per sample | rate (one core) | target |\n|---|---|---|---|\n| {n} | {:.1} ns | {:.1} MHz | 10 us (1 kHz needs 1 ms) |",
        per * 1e9,
        1e-6 / per
    );
    println!("\n| held-out FE history | stations | peak force (N) | max error / peak | RMS error / peak | plain QLV |\n|---|---|---|---|---|---|");
    for (j, v) in s.validation.iter().enumerate() {
        let qlv = s.qlv_validation.get(j).map_or("".to_string(), |q| {
            format!("{:.2} %", 100.0 * q.max_relative_error)
        });
        println!(
            "| {} | {} | {:.4e} | {:.2} % | {} | {qlv} |",
            v.history,
            v.samples,
            v.peak_force_n,
            100.0 * v.max_relative_error,
            v.rms_relative_error
                .map_or("-".to_string(), |e| format!("{:.2} %", 100.0 * e))
        );
    }
    eprintln!("(checksum {sum:.3e})");
}
