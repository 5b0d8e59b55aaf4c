//! R2 mesh convergence and the presses compared with CalculiX
//! (docs/validation/fe.md, "R2"). With a frictionless wheel and pure-penalty
//! contact the state depends on the wheel position only, so the rolled force
//! at x is the force of a press to RD at x (tests/integration/r2_rolling.rs checks it);
//! each row presses the wheel to RD at x on element sizes h = 4, 2, 1 mm
//! (the default mesh, level 1, is h = 2) and prints the forces, the observed
//! order `p = log2((F4 - F2) / (F2 - F1))`, the Richardson estimate of the
//! error of h = 2 and h = 1 with the order stated by the model, and CPU
//! seconds. `--csv OUT` writes the rows (docs/validation/r2/fe_presses.csv).
//!
//! `cargo run --release -p palpate-tools --bin convergence_r2 -- [--rd 3,6]
//!  [--x 10,37.5,56.25,75,93.75,112.5] [--h 4,2,1] [--csv OUT]`

use palpate_core::{Drive, Loading};
use palpate_fe::R2Rolling;
use palpate_material::Law;

use cpu::cpu_seconds;
use palpate_tools::cpu;

fn list(v: &str) -> Vec<f64> {
    v.split(',').map(|x| x.parse().expect("a number")).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut rds = vec![3.0, 6.0];
    let mut xs = vec![10.0, 37.5, 56.25, 75.0, 93.75, 112.5];
    let mut hs = vec![4.0, 2.0, 1.0];
    let mut csv: Option<String> = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().expect("a value after the option").clone();
        match a.as_str() {
            "--rd" => rds = list(&value()),
            "--x" => xs = list(&value()),
            "--h" => hs = list(&value()),
            "--csv" => csv = Some(value()),
            other => panic!("unknown option {other}"),
        }
    }
    let theta = R2Rolling::BENCHMARK_PARAMS;
    let mut rows = String::from(
        "# R2 presses at x (frictionless, pure penalty 1000 mu0/h, smoothing 0.01 mm), nodules 37.5:10,75:15,112.5:20, palpate Q9 plane stress, exact incompressibility\nposition_mm,rd_mm,h_mm,force_N,force_x_N,cpu_s\n",
    );
    println!(
        "{:>8} {:>4} | {} | {:>6} | {:>9} {:>9}",
        "x mm",
        "RD",
        hs.iter()
            .map(|h| format!("F(h={h}) N  Fx N   cpu s"))
            .collect::<Vec<_>>()
            .join(" | "),
        "order",
        "err h=2",
        "err h=1"
    );
    for &rd in &rds {
        for &x in &xs {
            let mut f = Vec::new();
            let mut cells = Vec::new();
            for &h in &hs {
                let mut m = R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd);
                m.press_x = x;
                m.element_size = Some(h);
                let n = (rd / 0.5).round() as usize;
                let drive: Vec<f64> = (1..=n).map(|k| rd * k as f64 / n as f64).collect();
                let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
                let c0 = cpu_seconds(false);
                match m.simulate(&theta, &loading, None) {
                    Ok((sim, _)) => {
                        let o = sim.outputs.last().cloned().unwrap_or_default();
                        let cpu = cpu_seconds(false) - c0;
                        rows += &format!("{x},{rd},{h},{:.6},{:.6},{cpu:.1}\n", o[0], o[1]);
                        f.push(o[0]);
                        cells.push(format!("{:>9.5} {:>6.3} {:>7.1}", o[0], o[1], cpu));
                    }
                    Err(e) => {
                        f.push(f64::NAN);
                        cells.push(format!("failed: {e}"));
                    }
                }
            }
            let (order, e2, e1) = if f.len() == 3 {
                let p = ((f[0] - f[1]) / (f[1] - f[2])).abs().log2();
                let stated = R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd)
                    .convergence_order()
                    .order;
                let fi = f[2] + (f[2] - f[1]) / (2f64.powf(stated) - 1.0);
                (p, (f[1] - fi) / fi, (f[2] - fi) / fi)
            } else {
                (f64::NAN, f64::NAN, f64::NAN)
            };
            println!(
                "{x:>8} {rd:>4} | {} | {order:>6.2} | {:>8.3}% {:>8.3}%",
                cells.join(" | "),
                100.0 * e2,
                100.0 * e1
            );
        }
    }
    if let Some(path) = csv {
        std::fs::write(&path, rows).expect("write the CSV");
    }
}
