//! How the excess force of one R2 nodule, E(p; x_n, d) = F(p) - F0(p),
//! changes with the nodule's distance to the block's end (the
//! localisation's x bias near the ends). For each nodule position x_n and
//! depth d the wheel is rolled over the window x_n - 30 .. x_n + 30 mm
//! (clipped to the path 10..140) and F0 is one nodule-free pass; the table
//! prints E at the offsets p - x_n.
//!
//! `cargo run --release -p palpate-tools --bin r2_excess_shape -- [--rd 6]
//!  [--x 20,35,50,75] [--depth 10,20] [--step 2] [--press-check]`
//! (`--press-check`: instead, presses at 12, 16, 22, 46 mm against the
//! rolled nodule-free pass, the path independence near the end).

use palpate_fe::r2_scan::R2NoduleScan;
use palpate_fe::R2Rolling;
use palpate_material::Law;

fn list(s: &str) -> Vec<f64> {
    s.split(',').map(|v| v.parse().expect("a number")).collect()
}

fn main() {
    let mut rd = 6.0;
    let mut xs = list("20,35,50,75");
    let mut depths = list("10,20");
    let mut step: f64 = 2.0;
    let mut press_check = false;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().expect("a value after the option").clone();
        match a.as_str() {
            "--rd" => rd = value().parse().expect("mm"),
            "--x" => xs = list(&value()),
            "--depth" => depths = list(&value()),
            "--step" => step = value().parse().expect("mm"),
            "--press-check" => press_check = true,
            other => panic!("unknown option {other}"),
        }
    }
    let template = R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd).with_nodules(vec![]);
    let (lo, hi) = (template.press_x, template.roll_to);
    // F0 every 1 mm: the scans' positions x_n + offset are whole mm
    let n = (hi - lo).round() as usize;
    let all: Vec<f64> = (0..=n).map(|k| lo + k as f64).collect();
    let t0 = std::time::Instant::now();
    let (f0, _) = template
        .rolled_pass(&R2Rolling::BENCHMARK_PARAMS, &all, 2, None)
        .expect("nodule-free pass");
    eprintln!("nodule-free pass {:.1} s", t0.elapsed().as_secs_f64());
    let f0_at = |p: f64| {
        assert!(
            (p - p.round()).abs() < 1e-9,
            "F0 is known at whole mm only, not {p}"
        );
        f0[(p - lo).round() as usize][0]
    };
    if press_check {
        // path independence near the end: a press at p against the rolled F0
        for p in [12.0f64, 16.0, 22.0, 46.0] {
            let mut m = template.clone();
            m.press_x = p;
            let (f, _) = m
                .rolled_pass(&R2Rolling::BENCHMARK_PARAMS, &[p], 1, None)
                .expect("press");
            println!("p {p}: press {:.5} rolled {:.5}", f[0][0], f0_at(p));
        }
        return;
    }
    let half = 30.0;
    let k = (half / step).round() as i64;
    let jobs: Vec<(f64, f64)> = depths
        .iter()
        .flat_map(|&d| xs.iter().map(move |&x| (x, d)))
        .collect();
    use rayon::prelude::*;
    let rows: Vec<(f64, f64, Vec<Option<f64>>, f64)> = jobs
        .par_iter()
        .map(|&(x, d)| {
            let mut scan = R2NoduleScan::new(template.clone(), false);
            scan.centre = x;
            let offs: Vec<f64> = (-k..=k)
                .map(|j| step * j as f64)
                .filter(|o| x + o >= lo - 1e-9 && x + o <= hi + 1e-9)
                .collect();
            let t = std::time::Instant::now();
            let f = scan.scan(&[d], &offs).expect("scan");
            let mut e = vec![None; (2 * k + 1) as usize];
            for (o, fi) in offs.iter().zip(&f) {
                let j = (o / step).round() as i64 + k;
                e[j as usize] = Some(fi - f0_at(x + o));
            }
            (x, d, e, t.elapsed().as_secs_f64())
        })
        .collect();
    println!("RD {rd} mm, excess force E (N) at offsets p - x_n (mm)\n");
    print!("| offset |");
    for (x, d, _, _) in &rows {
        print!(" x {x} d {d} |");
    }
    print!("\n|---|");
    for _ in &rows {
        print!("---|");
    }
    println!();
    for j in 0..(2 * k + 1) as usize {
        print!("| {} |", step * (j as f64 - k as f64));
        for (_, _, e, _) in &rows {
            match e[j] {
                Some(v) => print!(" {v:.5} |"),
                None => print!(" - |"),
            }
        }
        println!();
    }
    for (x, d, _, t) in &rows {
        eprintln!("x {x} d {d}: {t:.1} s");
    }
}
