//! Writes the synthetic R2 withheld-effect records of `tests/data/gap-r2/`
//! (used by `gap_fe_effects -- r2` and
//! `tests/integration/gap_fe_effects.rs`): the R2 development pass (`palpate_tests::
//! r2_dev`: an 80 x 20 mm neo-Hookean block, wheel of diameter 8 mm rolled at
//! RD 3 mm from x = 28 to 52 mm, vertical force every 1 mm, 25 samples)
//! simulated on a mesh twice as fine as the diagnosis's base model (1 mm
//! elements against 2 mm), so the base does not share the record's
//! discretisation, plus Gaussian noise of a stated fraction of the largest
//! force, from a fixed seed.
//!
//! `expected` is decided from the noiseless record, before any diagnosis:
//! the base model (2 mm mesh, no nodule, frictionless, bonded) is fitted to
//! it by its least-squares C10 (exact: the model is homogeneous in C10), and
//! the RMS of what is left, in noise SDs, is the effect's visible size. At
//! 1 SD or more (a chi-square excess of about n = 25 noise variances) the
//! correct answer is the planted effect; below 0.4 SD (the diagnosis's
//! materiality threshold) it is `none`, "too weak to see"; the cases are
//! chosen to avoid the band between.
//!
//! `cargo run --release -p palpate-tools --bin make_gap_r2 [-- NAME,...]`
//! (a subset replaces only its entries of `truth.json`, so one process per
//! record can run them in parallel). The records are committed; rerun only
//! to change them.

use palpate_core::{Effect, ForwardModel};
use palpate_fe::R2Gap;
use palpate_tests::r2_dev;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

struct Case {
    name: &'static str,
    c10: f64,
    /// The planted effect and its parameters (after C10), or none.
    effect: Option<(Effect, &'static [f64])>,
    noise_fraction: f64,
    seed: u64,
}

fn main() {
    let cases = [
        Case {
            name: "r2-inclusion",
            c10: 2.5e-3,
            // rubber in RTV 6166 (docs/benchmarks.md R2: mu 73.4 / 4.98 kPa)
            effect: Some((Effect::Inclusion, &[14.7, 44.0, 11.0])),
            noise_fraction: 0.01,
            seed: 41,
        },
        Case {
            name: "r2-friction",
            c10: 2.0e-3,
            effect: Some((Effect::Friction, &[0.6])),
            noise_fraction: 0.01,
            seed: 42,
        },
        Case {
            name: "r2-sliding",
            c10: 2.5e-3,
            effect: Some((Effect::BoundaryCondition, &[])),
            noise_fraction: 0.01,
            seed: 43,
        },
        Case {
            name: "r2-none",
            c10: 3.0e-3,
            effect: None,
            noise_fraction: 0.01,
            seed: 44,
        },
    ];
    let only: Option<Vec<String>> = std::env::args()
        .nth(1)
        .map(|a| a.split(',').map(String::from).collect());
    let dir = palpate_tools::repo("tests/data/gap-r2");
    std::fs::create_dir_all(&dir).expect("create data/gap-r2");
    let loading = r2_dev::loading(1.0);
    let fine = R2Gap::new(r2_dev::rolling(1.0), 1.0);
    let base = R2Gap::new(r2_dev::rolling(2.0), 1.0);
    let base_f = base.predict(&[1e-3], &loading).expect("base pass");
    // truth.json: the whole file for a full run; a subset (`-- NAME,...`)
    // replaces only its own entries
    let truth_path = dir.join("truth.json");
    let mut all = serde_json::Map::new();
    for c in &cases {
        if only
            .as_ref()
            .is_some_and(|o| !o.iter().any(|n| n == c.name))
        {
            continue;
        }
        let (model, theta): (Box<dyn ForwardModel>, Vec<f64>) = match c.effect {
            Some((e, params)) => {
                let mut t = vec![c.c10];
                t.extend_from_slice(params);
                (Box::new(fine.enriched(e).expect("effect")), t)
            }
            None => (Box::new(fine.clone()), vec![c.c10]),
        };
        // a pass that does not converge writes no record (friction 0.6 on the
        // 1 mm mesh stalled at its first rolled increment until the stick
        // penalty was lowered, `R2Rolling::tangent_penalty`)
        let f = match model.predict(&theta, &loading) {
            Ok(f) => f,
            Err(e) => {
                eprintln!("{}: no record, the pass failed: {e}", c.name);
                continue;
            }
        };
        let fmax = f.iter().cloned().fold(0.0, f64::max);
        let sd = c.noise_fraction * fmax;
        // visible size: RMS of the noiseless record minus the base's
        // least-squares fit, in noise SDs
        let a = f.iter().zip(&base_f).map(|(y, b)| y * b).sum::<f64>()
            / base_f.iter().map(|b| b * b).sum::<f64>();
        let rms = (f
            .iter()
            .zip(&base_f)
            .map(|(y, b)| (y - a * b).powi(2))
            .sum::<f64>()
            / f.len() as f64)
            .sqrt();
        let size = rms / sd;
        let expected = match c.effect {
            Some((e, _)) if size >= 1.0 => e.name().to_string(),
            _ if size < 0.4 => "none".to_string(),
            _ => "borderline".to_string(),
        };
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(c.seed);
        let noise = Normal::new(0.0, sd).expect("noise sd");
        let mut csv = format!(
            "# synthetic R2 record (tools/src/bin/make_gap_r2.rs): {}, theta {:?}, 1 mm mesh, \
             noise sd {:.3e} N (seed {})\nposition_mm,force_N\n",
            model.name(),
            theta,
            sd,
            c.seed
        );
        for (x, v) in loading.drive.iter().zip(&f) {
            let _ = writeln!(csv, "{x:.4},{:.6e}", v + noise.sample(&mut rng));
        }
        std::fs::write(dir.join(format!("{}.csv", c.name)), csv).expect("write record");
        let names: Vec<String> = model
            .space()
            .names()
            .iter()
            .map(|n| n.to_string())
            .collect();
        let params: Vec<String> = names
            .iter()
            .zip(&theta)
            .map(|(n, v)| format!("\"{n}\": {v}"))
            .collect();
        let entry = format!(
            "{{\"benchmark\": \"R2 (development pass, palpate_tests::r2_dev)\", \
             \"base_model\": \"neo-Hookean, no nodule, frictionless, bonded bottom, 2 mm mesh\", \
             \"generator\": \"R2Gap on a 1 mm mesh\", \"effects\": [{}], \"params\": {{{}}}, \
             \"noise_sd_N\": {sd:.6e}, \"visible_rms_in_sd\": {size:.3}, \"expected\": \"{expected}\"}}",
            c.effect.map_or(String::new(), |(e, _)| format!("\"{e}\"")),
            params.join(", ")
        );
        // re-read just before writing: other processes may write other subsets
        let mut truth: serde_json::Map<String, serde_json::Value> = if only.is_some() {
            std::fs::read_to_string(&truth_path)
                .ok()
                .and_then(|t| serde_json::from_str(&t).ok())
                .unwrap_or_default()
        } else {
            std::mem::take(&mut all)
        };
        truth.insert(
            c.name.to_string(),
            serde_json::from_str(&entry).expect("truth entry"),
        );
        let mut text = serde_json::to_string_pretty(&truth).expect("truth.json");
        text.push('\n');
        std::fs::write(&truth_path, text).expect("write truth.json");
        if only.is_none() {
            all = truth;
        }
        eprintln!(
            "{}: peak {fmax:.4} N, noise sd {sd:.2e} N, visible {size:.2} SD -> {expected}",
            c.name
        );
    }
}
