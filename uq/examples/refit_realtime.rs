//! Refits the memory of a stored real-time surrogate (no FE run) and prints
//! the held-out error table and the worst station of each held-out history:
//! `cargo run --release -p palpate-uq --example refit_realtime -- SURROGATE.json [KNOTS]`
//! (a file from `palpate surrogate build`, which stores its FE runs).
//! For studying the kernel's form on FE data that took minutes to make.
//! With env `OUT=FILE` the refitted surrogate is written there.

use palpate_uq::surrogate::realtime::{History, RealTimeSurrogate};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .expect("usage: refit_realtime SURROGATE.json [KNOTS]");
    let knots: usize = args.next().map_or(10, |k| k.parse().expect("KNOTS"));
    let text = std::fs::read_to_string(&path).expect("read the surrogate");
    let mut s = RealTimeSurrogate::from_json(&text).expect("a real-time surrogate");
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
    if let Ok(out) = std::env::var("OUT") {
        std::fs::write(&out, s.to_json()).expect("write the refitted surrogate");
    }
    if std::env::var("STATIONS").is_ok() {
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
