//! Benchmark of `palpate calibrate --experiment FILE --data force=RECORD.csv`
//! (Levenberg-Marquardt, the description's fitted parameters, the default
//! options) on synthetic records made on a finer mesh than the fit's, with
//! seeded Gaussian noise, for two experiments:
//!
//! * `n1`: the N1 needle (a 70 x 80 mm cylinder, bonded base, the
//!   sphere-cone needle) with the neo-Hookean C10 and the needle's Coulomb
//!   friction both fitted (truth C10 = 1.101295e-3 MPa, friction 0.8; start
//!   2e-3 and 0.4), record to 10 mm (the friction on the needle's shaft
//!   grows with the depth, and with it what the record says of it);
//! * `gel`: a 2.5 mm sphere on a bonded gel disc 10 mm thick and 40 mm
//!   across (truth C10 = 5e-3 MPa, start 2e-3), record to 2 mm.
//!
//! The fit's mesh is 9-node Q2/P1 at level 1 of the cylinder's sizing rule
//! (`forward/fe/src/models/cylinder.rs`; `--level N` for another), the
//! record's one level finer. Prints, per case, the record's cost, then the fit's FE
//! runs (objective evaluations: one FE run each), LM iterations, CPU
//! seconds of this process, and each estimate with its standard error and
//! its distance from the truth in standard errors. The command line runs
//! in-process (`palpate_studies::cli`, parsed by the CLI's own clap
//! definitions), so the fit is the one `palpate calibrate` makes. Its
//! figures are in `docs/validation/fe.md`, "Calibration on an FE experiment
//! from the command line".
//!
//! ```text
//! nice cargo run -p palpate-studies --example bench_calibrate_experiment -- [n1] [gel] [--noise 0.005] [--level 1]
//! ```
//!
//! `--jacobian P1,P2,...` makes no fit: at that point of a case's
//! parameters (in the order of its truth) it prints, at the record's
//! depths on the fit's mesh, the exact derivatives of the force (one run
//! with sensitivities) beside central differences of whole runs (steps of
//! 1e-4 of each parameter), the check of the Jacobian a fit is given
//! (`-- n1 --jacobian 1.108e-3,0.345`: a point the N1 fit visits on its
//! way from the start to the truth); `--only NAME` differences that
//! parameter alone.

use clap::Parser;
use palpate_core::{Drive, Loading};
use palpate_fe::experiment::Experiment;
use palpate_studies::cli::{dispatch, Cli};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

#[path = "../../forward/fe/examples/common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

struct Case {
    name: &'static str,
    /// The description as a user writes it (fitted parameters as starts).
    description: String,
    truth: Vec<(&'static str, f64)>,
    depth: f64,
    samples: usize,
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "n1",
            description: r#"# N1 with the needle's friction fitted
[specimen]
shape = "cylinder"
radius = 35.0
height = 80.0
support = "bonded"

[materials.ecoflex]
law = "neo-hookean"
C10 = { start = 2e-3 }

[tool]
shape = "needle"
friction = { start = 0.4, upper = 2.0 }
"#
            .into(),
            truth: vec![("C10", 1.101295e-3), ("friction", 0.8)],
            depth: 10.0,
            samples: 10,
        },
        Case {
            name: "gel",
            description: include_str!("../experiments/gel-disc.toml").into(),
            truth: vec![("C10", 5e-3)],
            depth: 2.0,
            samples: 10,
        },
    ]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let noise = args
        .iter()
        .position(|a| a == "--noise")
        .and_then(|k| args.get(k + 1))
        .map_or(0.005, |v| v.parse().expect("--noise: a number"));
    let level: usize = args
        .iter()
        .position(|a| a == "--level")
        .and_then(|k| args.get(k + 1))
        .map_or(1, |v| v.parse().expect("--level: a level 1, 2, ..."));
    let jacobian_at: Option<Vec<f64>> = args
        .iter()
        .position(|a| a == "--jacobian")
        .and_then(|k| args.get(k + 1))
        .map(|v| {
            v.split(',')
                .map(|x| x.parse().expect("--jacobian: numbers separated by commas"))
                .collect()
        });
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|k| args.get(k + 1));
    let chosen: Vec<&String> = args
        .iter()
        .filter(|a| {
            !a.starts_with("--")
                && a.parse::<f64>().is_err()
                && !a.contains(',')
                && Some(*a) != only
        })
        .collect();
    let dir = tempfile::tempdir().expect("temporary folder");
    println!(
        "palpate calibrate --experiment on synthetic records (fit on mesh level {level}, record on level {}, noise {noise} of the largest force); {} cores",
        level + 1,
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    for case in cases() {
        if !chosen.is_empty() && !chosen.iter().any(|c| *c == case.name) {
            continue;
        }
        // the record, on a finer mesh (noiseless forces cached under
        // target/: a rerun reads them instead of recomputing them)
        let fine_text = format!(
            "{}\n[protocol]\nsegments = [{{ ramp_to = {} }}]\n\n[mesh]\nlevel = {}\n",
            case.description,
            case.depth,
            level + 1
        );
        let fine: Experiment = toml::from_str(&fine_text).expect("the record's description");
        let model = fine.model().expect("the record's model");
        let depths: Vec<f64> = (1..=case.samples)
            .map(|k| case.depth * k as f64 / case.samples as f64)
            .collect();
        let theta: Vec<f64> = case.truth.iter().map(|t| t.1).collect();
        if let Some(at) = &jacobian_at {
            jacobian_check(&case, level, at, &depths, only.map(String::as_str));
            continue;
        }
        let cache = record_cache(&fine_text, &theta, &depths);
        let (forces, record_cpu, cached) = match read_cached(&cache, depths.len()) {
            Some((f, cpu)) => (f, cpu, true),
            None => {
                let t0 = cpu_seconds(false);
                let f = model
                    .as_forward()
                    .predict(
                        &theta,
                        &Loading::quasi_static(Drive::DisplacementMm, depths.clone()),
                    )
                    .expect("the record's run");
                let cpu = cpu_seconds(false) - t0;
                write_cached(&cache, &depths, &f, cpu);
                (f, cpu, false)
            }
        };
        let top = forces.iter().fold(0.0f64, |m, f| m.max(f.abs()));
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(11);
        let normal = Normal::new(0.0, noise * top).expect("noise");
        let mut csv = String::from("displacement_mm,force_N\n");
        for (d, f) in depths.iter().zip(&forces) {
            csv += &format!("{d},{:.12e}\n", f + normal.sample(&mut rng));
        }
        let record = dir.path().join(format!("{}.csv", case.name));
        let file = dir.path().join(format!("{}.toml", case.name));
        let json = dir.path().join(format!("{}.json", case.name));
        std::fs::write(&record, csv).expect("write the record");
        std::fs::write(
            &file,
            format!("{}\n[mesh]\nlevel = {level}\n", case.description),
        )
        .expect("write the description");
        println!(
            "\n== {}: record to {} mm, {} samples, F max {top:.4e} N, on {} ({record_cpu:.1} s CPU{})",
            case.name,
            case.depth,
            case.samples,
            model.name(),
            if cached {
                format!(" when made; read from {}", cache.display())
            } else {
                String::new()
            }
        );
        // the fit, as the command line makes it
        let line = [
            "palpate".to_string(),
            "calibrate".into(),
            "--experiment".into(),
            file.display().to_string(),
            "--data".into(),
            format!("force={}", record.display()),
            "--json".into(),
            json.display().to_string(),
        ];
        println!("$ {}", line[..].join(" "));
        let cli = Cli::try_parse_from(&line).expect("the command line");
        let (t0, w0) = (cpu_seconds(false), std::time::Instant::now());
        if let Err(e) = dispatch(cli) {
            println!("calibrate failed: {e:#}");
            continue;
        }
        let (cpu, wall) = (cpu_seconds(false) - t0, w0.elapsed().as_secs_f64());
        let fit: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).expect("the fit's JSON"))
                .expect("JSON");
        println!(
            "{}: {} FE runs in the fit ({} Jacobians, each from one of them run with sensitivities) + 1 for the fitted curve, {} iterations, converged {} ({}), {cpu:.1} s CPU ({wall:.1} s wall)",
            case.name,
            fit["evaluations"],
            fit["fit"]["jacobians"],
            fit["iterations"],
            fit["converged"],
            fit["fit"]["termination"],
        );
        for (name, t) in &case.truth {
            let p = &fit["params"][name];
            let v = p["value"].as_f64().unwrap_or(f64::NAN);
            let se = p["standard_error"].as_f64().unwrap_or(f64::NAN);
            println!(
                "  {name} = {v:.6e} +- {se:.2e} (truth {t:.6e}: {:+.2} %, {:+.2} SE)",
                100.0 * (v / t - 1.0),
                (v - t) / se
            );
        }
    }
}

/// The exact derivatives of the force at `at` on the fit's mesh against
/// central differences of whole runs (steps of 1e-4 of each parameter).
fn jacobian_check(case: &Case, level: usize, at: &[f64], depths: &[f64], only: Option<&str>) {
    assert_eq!(
        at.len(),
        case.truth.len(),
        "--jacobian: one value per parameter of {}",
        case.name
    );
    let text = format!("{}\n[mesh]\nlevel = {level}\n", case.description);
    let exp: Experiment = toml::from_str(&text).expect("the fit's description");
    let model = exp.model().expect("the fit's model");
    let forward = model.as_forward();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths.to_vec());
    println!(
        "\n== {}: the exact Jacobian at {at:?} on {}",
        case.name,
        forward.name()
    );
    let t0 = cpu_seconds(false);
    let (forces, columns) = forward
        .as_sensitivities()
        .expect("FE models offer sensitivities")
        .predict_with_jacobian(at, &loading)
        .expect("the run with sensitivities");
    println!(
        "one run with sensitivities: {:.1} s CPU",
        cpu_seconds(false) - t0
    );
    for (j, (name, _)) in case.truth.iter().enumerate() {
        if only.is_some_and(|o| o != *name) {
            continue;
        }
        let h = 1e-4 * at[j].abs();
        let run = |s: f64| {
            let mut t = at.to_vec();
            t[j] += s * h;
            forward.predict(&t, &loading).expect("a whole run")
        };
        let (p, m) = (run(1.0), run(-1.0));
        println!("d F / d {name} (depth mm, F N, exact, central difference, relative deviation)");
        for k in 0..depths.len() {
            let fd = (p[k] - m[k]) / (2.0 * h);
            println!(
                "  {:5.2} {:.5e} {:+.6e} {:+.6e} {:+.2e}",
                depths[k],
                forces[k],
                columns[j][k],
                fd,
                (columns[j][k] - fd) / fd.abs().max(f64::MIN_POSITIVE)
            );
        }
    }
}

/// The file of a record's noiseless forces: under the workspace's
/// `target/`, named by a hash of the description, the parameters and the
/// depths (so that any change makes a new record).
fn record_cache(description: &str, theta: &[f64], depths: &[f64]) -> std::path::PathBuf {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    description.hash(&mut h);
    for x in theta.iter().chain(depths) {
        x.to_bits().hash(&mut h);
    }
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../target/bench_calibrate_experiment")
        .join(format!("record-{:016x}.csv", h.finish()))
}

/// The cached forces and the CPU seconds their run took, when the file
/// holds `n` of them.
fn read_cached(path: &std::path::Path, n: usize) -> Option<(Vec<f64>, f64)> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines();
    let cpu: f64 = lines.next()?.strip_prefix("# cpu_s ")?.parse().ok()?;
    lines.next()?; // the column names
    let forces: Vec<f64> = lines
        .map(|l| l.split(',').nth(1).and_then(|f| f.parse().ok()))
        .collect::<Option<_>>()?;
    (forces.len() == n).then_some((forces, cpu))
}

fn write_cached(path: &std::path::Path, depths: &[f64], forces: &[f64], cpu: f64) {
    let mut text = format!("# cpu_s {cpu}\ndisplacement_mm,force_N\n");
    for (d, f) in depths.iter().zip(forces) {
        text += &format!("{d},{f:e}\n");
    }
    let written = path
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .and_then(|()| std::fs::write(path, text));
    if let Err(e) = written {
        println!("(the record is not cached: {}: {e})", path.display());
    }
}
