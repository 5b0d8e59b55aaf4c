//! R2 localisation: accuracy, coverage and speed, release only.
//!
//! `cargo run --release -p palpate-tools --bin localize_r2 -- --rd 6
//!  [--records 50] [--h-record 1.5] [--step-record 1] [--noise 0.01]
//!  [--cache DIR] [--plot OUT.svg] [--record r2|r2-1] [--record-only]
//!  [--predict-r2-at X,X,..]`
//!
//! 1. Builds (or loads from the cache) the localisation model of RD: the
//!    FE scan surrogate (h = 2 mm) and the nodule-free pass; prints the
//!    build time (wall and CPU) and the surrogate's held-out error.
//! 2. Runs the FE model of docs/benchmarks.md R2 (three nodules 37.5:10, 75:15,
//!    112.5:20) at a FINER mesh (`--h-record`, default 1.5 mm) every
//!    `--step-record` mm (cached too), and prints the error of the
//!    localisation model at the true nodules against it: translation
//!    invariance + superposition + surrogate + mesh, all together.
//! 3. For `--records` seeds, adds Gaussian noise of SD `--noise` x the
//!    record's peak force, samples the posterior, and prints per nodule how
//!    often it is identifiable, the errors of the posterior means where it
//!    is, and the coverage of the 94 % HDIs; and the posterior time.

use palpate_core::ForwardModel;
use palpate_fe::{Nodule, R2Rolling};
use palpate_material::Law;
use palpate_studies::apps::localize::posterior::{localize, LocOptions};
use palpate_studies::apps::localize::record::Record;
use palpate_studies::apps::localize::{LocModel, LocSetup};
use palpate_studies::run::surrogate::{default_cache_dir, load_or_compute};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let mut rd = 6.0;
    let mut records = 50usize;
    let mut h_record = 1.5;
    let mut step_record = 1.0;
    let mut noise = 0.01;
    let mut cache = default_cache_dir();
    let mut plot: Option<PathBuf> = None;
    let mut which = "r2".to_string();
    let mut record_only = false;
    // positions where the model of R2's three nodules is printed (to set
    // beside FE presses of r2_paper_tables)
    let mut predict_at: Vec<f64> = Vec::new();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut v = || it.next().expect("a value after the option").clone();
        match a.as_str() {
            "--rd" => rd = v().parse()?,
            "--records" => records = v().parse()?,
            "--h-record" => h_record = v().parse()?,
            "--step-record" => step_record = v().parse()?,
            "--noise" => noise = v().parse()?,
            "--cache" => cache = PathBuf::from(v()),
            "--plot" => plot = Some(PathBuf::from(v())),
            "--record" => which = v(),
            "--record-only" => record_only = true,
            "--predict-r2-at" => {
                predict_at = v().split(',').map(|x| x.parse().expect("mm")).collect()
            }
            o => anyhow::bail!("unknown option {o}"),
        }
    }
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "R2 localisation bench, RD {rd} mm, {cores} cores, load average {}",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );

    // 2. the finer-mesh FE record
    let mut fe = R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd);
    fe.element_size = Some(h_record);
    if which == "r2-1" {
        // R2-1's nodule 75:15, rolled over 75 +- 30 mm only (cheaper)
        fe = fe.with_nodules(vec![Nodule {
            x: 75.0,
            depth: 15.0,
        }]);
        fe.press_x = 45.0;
        fe.roll_to = 105.0;
    } else {
        anyhow::ensure!(which == "r2", "--record r2|r2-1, got {which}");
    }
    let positions = fe.pass_positions(step_record);
    let truth: Vec<(f64, f64)> = fe.nodules.iter().map(|n| (n.x, n.depth)).collect();
    let desc = format!("{:?}; positions {:?}", fe, positions);
    let t1 = Instant::now();
    let (force, status): (Vec<f64>, _) = load_or_compute("r2-record", &desc, &cache, || {
        let bar = palpate_studies::run::limits::Progress::new(
            positions.len() as u64,
            "finer-mesh FE record",
            "{msg} [{bar:40}] {pos}/{len} positions ({elapsed}, eta {eta})",
        );
        let tick = || bar.inc(1);
        let r = fe.rolled_pass(&R2Rolling::BENCHMARK_PARAMS, &positions, 2, Some(&tick));
        bar.finish();
        Ok(r.map_err(|e| anyhow::anyhow!("{e}"))?
            .0
            .iter()
            .map(|r| r[0])
            .collect())
    })?;
    println!(
        "FE record: {} ({}), h = {h_record} mm, {} positions every {step_record} mm, {:.1} s",
        status.word(),
        fe.name(),
        positions.len(),
        t1.elapsed().as_secs_f64()
    );
    if record_only {
        return Ok(());
    }
    // 1. the model (after the record: `--record-only` stops there)
    let setup = LocSetup::r2(rd);
    let t0 = Instant::now();
    let model = LocModel::load_or_build(&setup, &cache)?;
    if !predict_at.is_empty() {
        let r2: Vec<(f64, f64)> = Nodule::r2_default()
            .iter()
            .map(|n| (n.x, n.depth))
            .collect();
        let (p, var) = model.predict(&predict_at, &r2, 1.0)?;
        for ((x, f), v) in predict_at.iter().zip(&p).zip(&var) {
            println!(
                "model of R2 (3 nodules) at x = {x} mm: {f:.5} N (surrogate error SD {:.5} N); F0 {:.5} N",
                v.sqrt(),
                model.baseline_at(*x)
            );
        }
    }
    let v = model.scan.validation();
    println!(
        "model: {} ({}) in {:.1} s; scan surrogate {} FE scans built in {:.1} s wall / {} CPU, nodule-free pass {:.1} s wall",
        model.scan_status.as_ref().map_or("-", |s| s.word()),
        model.scan_status.as_ref().map_or(String::new(), |s| s.path().display().to_string()),
        t0.elapsed().as_secs_f64(),
        model.scan.fe_runs,
        model.scan.build_time_s,
        model.scan.build_cpu_s.map_or("?".into(), |c| format!("{c:.1} s")),
        model.baseline.time_s
    );
    println!(
        "surrogate held-out error: max {:.3e}, RMS {:.3e} of the peak force; max abs {:.4} N",
        v.max_relative_error,
        v.rms_relative_error,
        v.max_abs_error.first().copied().unwrap_or(0.0)
    );

    let (pred, _) = model.predict(&positions, &truth, 1.0)?;
    let peak = force.iter().cloned().fold(0.0, f64::max);
    let (k, worst) = pred
        .iter()
        .zip(&force)
        .enumerate()
        .map(|(k, (p, f))| (k, (p - f) / f))
        .fold(
            (0, 0.0f64),
            |a, b| if b.1.abs() > a.1.abs() { b } else { a },
        );
    let rms = (pred
        .iter()
        .zip(&force)
        .map(|(p, f)| ((p - f) / f).powi(2))
        .sum::<f64>()
        / force.len() as f64)
        .sqrt();
    println!(
        "model at the true nodules vs the finer-mesh FE record: max {:+.3} % at x = {} mm, RMS {:.3} % (noise SD {:.2} % of the peak)",
        100.0 * worst,
        positions[k],
        100.0 * rms,
        100.0 * noise
    );
    for &(x, _) in &truth {
        let i = positions
            .iter()
            .position(|&p| (p - x).abs() < 0.5 * step_record + 1e-9)
            .unwrap_or(0);
        println!(
            "  over the nodule at {x}: FE {:.4} N, model {:.4} N ({:+.3} %), excess over F0 {:.4} N",
            force[i],
            pred[i],
            100.0 * (pred[i] - force[i]) / force[i],
            force[i] - model.baseline_at(positions[i])
        );
    }

    if records == 0 {
        return Ok(());
    }
    // 3. noisy records
    let sd = noise * peak;
    let n = truth.len();
    let mut ident = vec![0usize; n];
    let mut cover = vec![[0usize; 2]; n];
    let mut cover_id = vec![[0usize; 2]; n];
    let mut err_max = vec![[0.0f64; 2]; n];
    let mut err_sum = vec![[0.0f64; 2]; n];
    let mut times = Vec::new();
    let mut unconverged = 0;
    for seed in 0..records as u64 {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1000 + seed);
        let normal = Normal::new(0.0, sd)?;
        let y: Vec<f64> = force.iter().map(|f| f + normal.sample(&mut rng)).collect();
        let rec = Record {
            file: PathBuf::from(format!("synthetic-{seed}")),
            positions: positions.clone(),
            force: y,
        };
        let o = LocOptions {
            nodules: n,
            seed: 7 + seed,
            ..Default::default()
        };
        let run = localize(&model, &rec.positions, &rec.force, &o, None)?;
        times.push(run.wall_s);
        if !run.converged {
            unconverged += 1;
        }
        if seed == 0 {
            print!(
                "{}",
                palpate_studies::cli::localize::summary_text(&model, &rec, &run)
            );
            if let Some(p) = &plot {
                std::fs::write(
                    p,
                    palpate_studies::cli::localize::plot_svg(&model, &rec, &run, Some(&truth)),
                )?;
            }
        }
        for (j, e) in run.result.nodules.iter().enumerate() {
            let (tx, td) = truth[j];
            let inside = |i: &palpate_studies::apps::localize::posterior::Interval, t: f64| {
                i.hdi_3 <= t && t <= i.hdi_97
            };
            let c = [inside(&e.x_mm, tx), inside(&e.depth_mm, td)];
            for q in 0..2 {
                cover[j][q] += c[q] as usize;
            }
            if e.identifiable {
                ident[j] += 1;
                let er = [(e.x_mm.mean - tx).abs(), (e.depth_mm.mean - td).abs()];
                for q in 0..2 {
                    err_max[j][q] = err_max[j][q].max(er[q]);
                    err_sum[j][q] += er[q];
                    cover_id[j][q] += c[q] as usize;
                }
            }
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "\n{records} records, noise SD {:.4} N ({} % of the peak {:.3} N); posterior time median {:.2} s, max {:.2} s; {unconverged} not converged at the draw cap",
        sd,
        100.0 * noise,
        peak,
        times[times.len() / 2],
        times.last().copied().unwrap_or(0.0)
    );
    println!("| nodule | identifiable | mean abs x err mm | max abs x err mm | mean abs depth err mm | max abs depth err mm | x 94 % coverage | depth 94 % coverage | coverage where identifiable (x, depth) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for j in 0..n {
        let m = ident[j].max(1) as f64;
        println!(
            "| {}:{} | {}/{records} | {:.3} | {:.3} | {:.3} | {:.3} | {:.0} % | {:.0} % | {:.0} %, {:.0} % |",
            truth[j].0,
            truth[j].1,
            ident[j],
            err_sum[j][0] / m,
            err_max[j][0],
            err_sum[j][1] / m,
            err_max[j][1],
            100.0 * cover[j][0] as f64 / records as f64,
            100.0 * cover[j][1] as f64 / records as f64,
            100.0 * cover_id[j][0] as f64 / m,
            100.0 * cover_id[j][1] as f64 / m
        );
    }
    Ok(())
}
