//! Is a Q1 fit mesh's force smooth in the parameters at depth? The 5 mm
//! record's history (tests/data/two-stage-q1-5mm) run on a mesh of `H` mm
//! under a punch with an edge of `EDGE` mm at the point where a staged
//! polish stopped (C10 0.00166, g1 0.327, tau1 0.306 s, g2 0.206,
//! tau2 8.30 s), each `J:REL` changing parameter `J` by `REL` of itself;
//! prints the force at a half, three quarters and the end of the ramp, 20
//! samples into the hold and at its end:
//!
//!   cargo run --release -p palpate-tools --bin q1_fit_smoothness -- 0.3 0.2 3:0 3:1e-3 3:-1e-2
//!
//! With the 0.2 mm edge the 0.3 mm mesh jumps branch (g2 -1 %: +11 % at the
//! ramp's end); with a 0.6 mm edge it is smooth (docs/guide.md, two-stage).
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::Q1Punch;
use palpate_material::Law;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let h: f64 = a[1].parse().unwrap();
    let edge: f64 = a[2].parse().unwrap();
    let rec = std::fs::read_to_string(palpate_tools::repo(
        "tests/data/two-stage-q1-5mm/record.csv",
    ))
    .unwrap();
    let (mut t, mut d) = (vec![], vec![]);
    for l in rec.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        t.push(v[0]);
        d.push(v[1]);
    }
    let mut m = Q1Punch::new(Law::NeoHookean);
    m.set_edge_radius(edge).unwrap();
    m.set_fine_size(h);
    let mut m = m.with_prony_parameters(2);
    m.options.max_time_step = Some(1.0);
    let base = [0.00166, 0.327, 0.306, 0.206, 8.30];
    let ramp_end = d
        .iter()
        .enumerate()
        .fold(0, |k, (i, &x)| if x > d[k] { i } else { k });
    let loading = Loading::timed(Drive::DisplacementMm, t.clone(), d.clone());
    for r in &a[3..] {
        let (j, rel): (usize, f64) = {
            let mut p = r.split(':');
            (
                p.next().unwrap().parse().unwrap(),
                p.next().unwrap().parse().unwrap(),
            )
        };
        let mut th = base;
        th[j] *= 1.0 + rel;
        let t0 = std::time::Instant::now();
        match m.predict(&th, &loading) {
            Ok(f) => {
                let mid: Vec<String> = [
                    ramp_end / 2,
                    3 * ramp_end / 4,
                    ramp_end,
                    ramp_end + 20,
                    f.len() - 1,
                ]
                .iter()
                .map(|&k| format!("{:.6}", f[k]))
                .collect();
                println!(
                    "p{j} {rel:+e}: {} ({:.1} s)",
                    mid.join(" "),
                    t0.elapsed().as_secs_f64()
                );
            }
            Err(e) => println!("p{j} {rel:+e}: {e}"),
        }
    }
}
