//! The source paper's depth analysis from our FE (docs/benchmarks.md
//! R2-1): peak force against depth per RD, the empirical quadratic
//! depth = a F^2 + b F + c per RD (the paper's Table III), and the Table IV
//! exercise (the depth the quadratic predicts for the three nodules of R2,
//! 10, 15 and 20 mm, from their peak force, with its error).
//!
//! Peak force = the press to RD at the nodule's x: with a frictionless wheel
//! the state depends on the wheel position alone (tests/integration/r2_rolling.rs), and
//! the R2-1 block and mesh are symmetric about the nodule at x = 75 mm, so
//! the rolled force peaks there. For R2 (three nodules) the press at each
//! nodule's x (the peak within the 1 mm of tests/integration/r2_rolling.rs (c)).
//! The flat level F0 is the press at x = 75 mm without nodules.
//!
//! A nodule is "NI" (not identifiable) here when its peak excess over F0 is
//! below 2 % of F0 (twice a 1 % noise SD: the peak cannot be told from the
//! flat level in one record), or the quadratic's depth falls outside the
//! studied 8-24 mm. docs/validation/r2-localisation.md puts the table beside
//! the paper's and the posterior's identifiability.
//!
//! `cargo run --release -p palpate-tools --bin r2_paper_tables -- [--rd 3,4,5,6] [--level 1]`
//! (presses in parallel threads, 2 by default: `--threads N`).

use nalgebra::{Matrix3, Vector3};
use palpate_fe::{Nodule, R2Rolling};
use palpate_material::Law;
use std::sync::Mutex;
use std::time::Instant;

const DEPTHS: [f64; 8] = [8.0, 10.0, 12.0, 15.0, 18.0, 20.0, 22.0, 24.0];

/// The vertical force of the press to RD at x.
fn press(rd: f64, level: usize, nodules: Vec<Nodule>, x: f64) -> f64 {
    let mut m = R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd).with_nodules(nodules);
    m.level = level;
    m.press_x = x;
    let (rows, _) = m
        .rolled_pass(&R2Rolling::BENCHMARK_PARAMS, &[x], 1, None)
        .unwrap_or_else(|e| panic!("press RD {rd} at {x}: {e}"));
    rows[0][0]
}

/// Least squares depth = a F^2 + b F + c.
fn quadratic(f: &[f64], d: &[f64]) -> [f64; 3] {
    let mut a = Matrix3::zeros();
    let mut r = Vector3::zeros();
    for (&fi, &di) in f.iter().zip(d) {
        let row = Vector3::new(fi * fi, fi, 1.0);
        a += row * row.transpose();
        r += row * di;
    }
    let s = a.lu().solve(&r).expect("a solvable fit");
    [s[0], s[1], s[2]]
}

fn main() {
    let mut rds = vec![3.0, 4.0, 5.0, 6.0];
    let mut level = 1usize;
    let mut threads = 2usize;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut v = || it.next().expect("a value").clone();
        match a.as_str() {
            "--rd" => rds = v().split(',').map(|x| x.parse().expect("mm")).collect(),
            "--level" => level = v().parse().expect("a level"),
            "--threads" => threads = v().parse().expect("a count"),
            o => panic!("unknown option {o}"),
        }
    }
    // every press: (rd, kind, index) -> force; kind 0 R2-1 depth, 1 R2 nodule, 2 flat
    let mut jobs: Vec<(f64, usize, usize)> = Vec::new();
    for &rd in &rds {
        jobs.push((rd, 2, 0));
        for k in 0..DEPTHS.len() {
            jobs.push((rd, 0, k));
        }
        for k in 0..3 {
            jobs.push((rd, 1, k));
        }
    }
    let t0 = Instant::now();
    let next = Mutex::new(0usize);
    let results = Mutex::new(vec![f64::NAN; jobs.len()]);
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| loop {
                let i = {
                    let mut n = next.lock().unwrap();
                    let i = *n;
                    *n += 1;
                    i
                };
                let Some(&(rd, kind, k)) = jobs.get(i) else {
                    break;
                };
                let f = match kind {
                    0 => press(
                        rd,
                        level,
                        vec![Nodule {
                            x: 75.0,
                            depth: DEPTHS[k],
                        }],
                        75.0,
                    ),
                    1 => {
                        let n = Nodule::r2_default();
                        press(rd, level, n.clone(), n[k].x)
                    }
                    _ => press(rd, level, Vec::new(), 75.0),
                };
                results.lock().unwrap()[i] = f;
                eprintln!(
                    "press {}/{}: RD {rd} kind {kind} #{k}: {f:.5} N ({:.0} s)",
                    i + 1,
                    jobs.len(),
                    t0.elapsed().as_secs_f64()
                );
            });
        }
    });
    let res = results.into_inner().unwrap();
    let get = |rd: f64, kind: usize, k: usize| {
        let i = jobs.iter().position(|&j| j == (rd, kind, k)).unwrap();
        res[i]
    };
    println!(
        "R2-1 peak force (N) against depth, level {level} (h = {} mm), {:.0} s wall",
        2.0 / level as f64,
        t0.elapsed().as_secs_f64()
    );
    print!("| RD mm | F0 (no nodule) |");
    for d in DEPTHS {
        print!(" {d} mm |");
    }
    println!();
    for &rd in &rds {
        print!("| {rd} | {:.4} |", get(rd, 2, 0));
        for k in 0..DEPTHS.len() {
            print!(" {:.4} |", get(rd, 0, k));
        }
        println!();
    }
    println!("\nTable III (ours): depth = a F^2 + b F + c, least squares over the 8 depths");
    println!("| RD mm | a (mm/N^2) | b (mm/N) | c (mm) | max fit residual mm |");
    let mut fits = Vec::new();
    for &rd in &rds {
        let f: Vec<f64> = (0..DEPTHS.len()).map(|k| get(rd, 0, k)).collect();
        let q = quadratic(&f, &DEPTHS);
        let res = f
            .iter()
            .zip(DEPTHS)
            .map(|(f, d)| (q[0] * f * f + q[1] * f + q[2] - d).abs())
            .fold(0.0, f64::max);
        println!(
            "| {rd} | {:.5} | {:.5} | {:.4} | {:.3} |",
            q[0], q[1], q[2], res
        );
        fits.push(q);
    }
    println!("\nTable IV (ours): R2 nodules, depth from the quadratic of their peak force");
    println!("| RD mm | nodule | peak F N | excess over F0 % | predicted depth mm | error mm |");
    for (r, &rd) in rds.iter().enumerate() {
        let f0 = get(rd, 2, 0);
        for (k, n) in Nodule::r2_default().iter().enumerate() {
            let f = get(rd, 1, k);
            let q = fits[r];
            let d = q[0] * f * f + q[1] * f + q[2];
            let excess = (f - f0) / f0;
            let ni = excess < 0.02 || !(8.0..=24.0).contains(&d);
            println!(
                "| {rd} | {}:{} | {f:.4} | {:.2} | {} | {} |",
                n.x,
                n.depth,
                100.0 * excess,
                if ni {
                    format!("NI ({d:.2})")
                } else {
                    format!("{d:.2}")
                },
                if ni {
                    "-".into()
                } else {
                    format!("{:+.2}", d - n.depth)
                }
            );
        }
    }
}
