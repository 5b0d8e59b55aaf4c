//! Why the R2 wheel feels a horizontal force at x = 10 mm: a
//! frictionless wheel pressed into a block is pushed sideways only when the
//! block is not mirror-symmetric about the wheel. Presses to RD on the
//! block without nodules at positions near the left end (x = 0), mid-block,
//! and the mirror positions near the right end (x = 150): if the block end
//! is the cause, `force_x` decays with the distance to the end and changes
//! sign at the mirror position (`Fx(150 - x) = -Fx(x)`).
//!
//! `cargo run --release -p palpate-tools --bin r2_end_effect -- [--rd 6]
//!  [--h 2] [--nodules none]`

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{Nodule, R2Rolling};
use palpate_material::Law;

fn main() {
    let mut rd = 6.0;
    let mut h = 2.0;
    let mut nodules = "none".to_string();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().expect("a value after the option").clone();
        match a.as_str() {
            "--rd" => rd = value().parse().expect("mm"),
            "--h" => h = value().parse().expect("mm"),
            "--nodules" => nodules = value(),
            other => panic!("unknown option {other}"),
        }
    }
    let theta = R2Rolling::BENCHMARK_PARAMS;
    let mut model = R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd)
        .with_nodules(Nodule::parse_list(&nodules).expect("nodules X:DEPTH,..."));
    model.element_size = Some(h);
    let n = (rd / 0.5).round() as usize;
    let depths: Vec<f64> = (1..=n).map(|j| rd * j as f64 / n as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths);
    println!("R2 presses to RD {rd} mm, nodules {nodules}, h = {h} mm (block 0..150 mm)\n");
    println!("| x mm | distance to the nearer end mm | force_N | force_x_N |\n|---|---|---|---|");
    for x in [
        10.0, 12.5, 15.0, 20.0, 30.0, 75.0, 130.0, 135.0, 137.5, 140.0,
    ] {
        let mut m = model.clone();
        m.press_x = x;
        m.roll_to = x.max(m.roll_to);
        let mut ev = m.evaluator();
        let mut out = vec![0.0; 2 * n];
        ev.predict_outputs_into(&theta, &loading, &mut out)
            .unwrap_or_else(|e| panic!("press at {x}: {e}"));
        let f = &out[2 * (n - 1)..];
        println!(
            "| {x} | {} | {:.4} | {:+.4} |",
            x.min(150.0 - x),
            f[0],
            f[1]
        );
    }
}
