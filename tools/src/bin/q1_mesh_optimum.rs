//! Where is a Q1 mesh's own least-squares optimum on the 5 mm record? One
//! Gauss-Newton step from a point, on a mesh of `H` mm under a punch with
//! an edge of `EDGE` mm (the fits' 1 s time step), with the Jacobian by
//! central differences of `REL` of each parameter:
//!
//!   cargo run --release -p palpate-tools --bin q1_mesh_optimum -- \
//!       0.1 0.2 0.01 0.0016055,0.311421,0.408215,0.201212,9.614416 [noise-free]
//!
//! The point is a corrected fit's estimate (`palpate calibrate --benchmark
//! Q1 ... --correct-mesh`); if the step from it is small against the
//! standard errors, that estimate is the mesh's own optimum and a bias in
//! it is the mesh's (not the correction's fixed point); if the step is
//! large, the correction settles elsewhere (docs/guide.md, two-stage). `noise-free` fits the record's noise-free force
//! (truth.json) instead of the record. It prints the forward and backward
//! differences' largest disagreement per parameter (a branch jump shows
//! there), the step and the point it reaches. 11 runs, in parallel; env
//! `RUNS_OUT=FILE` writes the points, their forces and the data as JSON.
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::Q1Punch;
use palpate_material::Law;
use rayon::prelude::*;

const NAMES: [&str; 5] = ["C10", "g1", "tau1_s", "g2", "tau2_s"];

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 5 {
        eprintln!("usage: q1_mesh_optimum H EDGE REL C10,g1,tau1,g2,tau2 [noise-free]");
        std::process::exit(2);
    }
    let h: f64 = a[1].parse().expect("H");
    let edge: f64 = a[2].parse().expect("EDGE");
    let rel: f64 = a[3].parse().expect("REL");
    let theta: Vec<f64> = a[4].split(',').map(|x| x.parse().expect("point")).collect();
    assert_eq!(theta.len(), 5, "five parameters");
    let noise_free = a.get(5).is_some_and(|s| s == "noise-free");
    let rec = std::fs::read_to_string(palpate_tools::repo(
        "tests/data/two-stage-q1-5mm/record.csv",
    ))
    .expect("record");
    let (mut t, mut d, mut f) = (vec![], vec![], vec![]);
    for l in rec.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        t.push(v[0]);
        d.push(v[1]);
        f.push(v[2]);
    }
    if noise_free {
        let truth: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(palpate_tools::repo(
                "tests/data/two-stage-q1-5mm/truth.json",
            ))
            .expect("truth"),
        )
        .expect("truth.json");
        f = truth["noise_free_force_N"]
            .as_array()
            .expect("noise_free_force_N")
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(f.len(), t.len(), "noise-free force and record");
    }
    let mut m = Q1Punch::new(Law::NeoHookean);
    m.set_edge_radius(edge).unwrap();
    m.set_fine_size(h);
    let mut m = m.with_prony_parameters(2);
    m.options.max_time_step = Some(1.0);
    let loading = Loading::timed(Drive::DisplacementMm, t.clone(), d.clone());
    // Run 0 the point, 1 + 2j the parameter j up, 2 + 2j down.
    let points: Vec<Vec<f64>> = (0..11)
        .map(|r| {
            let mut p = theta.clone();
            if r > 0 {
                let j = (r - 1) / 2;
                p[j] *= if r % 2 == 1 { 1.0 + rel } else { 1.0 - rel };
            }
            p
        })
        .collect();
    let t0 = std::time::Instant::now();
    let runs: Vec<Vec<f64>> = points
        .par_iter()
        .map(|p| m.predict(p, &loading).expect("FE run"))
        .collect();
    eprintln!("11 runs in {:.0} s", t0.elapsed().as_secs_f64());
    if let Ok(out) = std::env::var("RUNS_OUT") {
        let json = serde_json::json!({"points": points, "forces": runs, "data": f});
        std::fs::write(&out, json.to_string()).expect("RUNS_OUT");
    }
    let n = f.len();
    let r0: Vec<f64> = (0..n).map(|k| runs[0][k] - f[k]).collect();
    let sse: f64 = r0.iter().map(|x| x * x).sum();
    println!(
        "mesh {h} mm, edge {edge} mm, {} data; RMS at the point {:.4e} N",
        if noise_free { "noise-free" } else { "record" },
        (sse / n as f64).sqrt()
    );
    let mut jac = nalgebra::DMatrix::<f64>::zeros(n, 5);
    for j in 0..5 {
        let dp = theta[j] * rel;
        let (up, down) = (&runs[1 + 2 * j], &runs[2 + 2 * j]);
        let mut worst: f64 = 0.0;
        for k in 0..n {
            jac[(k, j)] = (up[k] - down[k]) / (2.0 * dp);
            let fwd = (up[k] - runs[0][k]) / dp;
            let back = (runs[0][k] - down[k]) / dp;
            let scale = jac.column(j).amax().max(1e-30);
            worst = worst.max((fwd - back).abs() / scale);
        }
        println!(
            "  {}: forward and backward differences differ by up to {:.1} % of the column",
            NAMES[j],
            100.0 * worst
        );
    }
    let jtj = jac.transpose() * &jac;
    let jtr = jac.transpose() * nalgebra::DVector::from_vec(r0);
    let inv = jtj.clone().try_inverse().expect("J^T J singular");
    let step = -(&inv * jtr);
    let s2 = sse / (n - 5) as f64;
    println!("parameter  point  step  step/SE  new point");
    for j in 0..5 {
        let se = (s2 * inv[(j, j)]).sqrt();
        println!(
            "  {:7} {:.6e} {:+.3e} {:+.2} {:.6e}",
            NAMES[j],
            theta[j],
            step[j],
            step[j] / se,
            theta[j] + step[j]
        );
    }
    let lin: f64 = (0..n)
        .map(|k| {
            let pred: f64 = runs[0][k] + (0..5).map(|j| jac[(k, j)] * step[j]).sum::<f64>();
            (pred - f[k]).powi(2)
        })
        .sum();
    println!(
        "RMS predicted at the new point (linear) {:.4e} N",
        (lin / n as f64).sqrt()
    );
}
