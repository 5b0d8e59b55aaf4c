//! Refits the memory of a stored real-time model (no FE run) and prints
//! the held-out error table and the worst station of each held-out history:
//!
//! `cargo run --release -p palpate-realtime --example refit_realtime -- MODEL.json [KNOTS] [--out FILE.json] [--stations]`
//!
//! (a file from `palpate realtime build`, which stores its FE runs). For
//! studying the kernel's form on FE data that took minutes to make. With
//! `--out` the refitted model is written there; with `--stations` each
//! station's time, depth, FE force, model force and error is printed.

use palpate_realtime::{History, RealTimeModel};

const USAGE: &str = "usage: refit_realtime MODEL.json [KNOTS] [--out FILE.json] [--stations]";

fn main() {
    let mut path = None;
    let mut knots = 10usize;
    let mut out = None;
    let mut stations = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => out = Some(args.next().expect(USAGE)),
            "--stations" => stations = true,
            _ if path.is_none() => path = Some(a),
            _ => knots = a.parse().expect(USAGE),
        }
    }
    let path = path.expect(USAGE);
    let text = std::fs::read_to_string(&path).expect("read the model");
    let mut s = RealTimeModel::from_json(&text).expect("a real-time model");
    s.refit(knots).expect("refit");
    let k = s.kernel.as_ref().expect("a kernel");
    println!(
        "{} knots: training RMS {:.3e} N over {} stations, cv {:?} {:?}, lift_off {} {:?}",
        k.knots,
        k.training.rms_n,
        k.training.stations,
        k.training.cv_max_relative_error,
        k.training.cv_contacts,
        k.lift_off,
        k.soft_contact
    );
    println!(
        "cv with stop operators {:?}, stops {:?}",
        k.training.cv_stops, k.stops
    );
    for v in &s.validation {
        println!(
            "{}: {:.2} % of peak {:.4} N at (s, mm) {:?}, RMS {:.2} %",
            v.history,
            100.0 * v.max_relative_error,
            v.peak_force_n,
            v.worst_at,
            100.0 * v.rms_relative_error.unwrap_or(f64::NAN)
        );
    }
    if let Some(out) = out {
        std::fs::write(&out, s.to_json()).expect("write the refitted model");
    }
    if stations {
        for r in s.runs.clone() {
            let h = History::from_knots(r.knots.clone(), 1e-3);
            let f = s.run(&h.time, &h.depth).expect("in range");
            println!("# {}", r.name);
            for &(t, fe) in &r.stations {
                let i = h.sample_at(t);
                println!(
                    "{t:8.3} {:7.4} {fe:10.5} {:10.5} {:+8.5}",
                    h.depth[i],
                    f[i],
                    f[i] - fe
                );
            }
        }
    }
}
