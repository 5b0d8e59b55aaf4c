//! Check of `palpate plan` against fits: N1 (needle, coarse mesh) with the
//! reduced polynomial law (C10 and C20 fitted), candidates over the depth
//! (2, 5, 10 mm) and the needle's tip radius (1 and 2.5 mm), noise SD
//! `--noise` N per sample. The plan's expected standard errors of C10 and
//! C20 (one run each, exact sensitivities) are then checked at two of the
//! candidates against the spread (sample SD) of Levenberg-Marquardt fits to
//! `--records` synthetic records (the model's force at the guess plus
//! Gaussian noise of that SD, seeded): the plan passes when every expected
//! SE is within 20 % of the spread.
//!
//! ```text
//! cargo run -p palpate-studies --example bench_plan_n1 -- [--records 50] [--noise 0.002] [--out docs/validation/plan.md]
//! ```
//!
//! Prints the plan's table, then per checked candidate the expected SEs,
//! the spread of the fits and their ratio, and the CPU seconds; with
//! `--out` it writes them as a Markdown page.

use std::fmt::Write;
use std::sync::Arc;

use palpate_core::ForwardModel;
use palpate_fe::experiment::Experiment;
use palpate_inverse::design::{Criterion, Noise};
use palpate_inverse::{fit, DataSet, FitOptions, Method, Objective, ResidualKind};
use palpate_studies::model::ExperimentSpec;
use palpate_studies::steps::plan::{candidates, plan, table, PlanOptions, Vary};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;

#[path = "../../forward/fe/examples/common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn num(name: &str, default: f64) -> f64 {
    arg(name).map_or(default, |v| {
        v.parse()
            .unwrap_or_else(|_| panic!("{name} {v}: expected a number"))
    })
}

/// N1 on its coarse mesh (level 1), the reduced polynomial law with C10
/// and C20 fitted, 20 samples per ramp.
fn description() -> Experiment {
    let text = Experiment::preset_toml("N1")
        .expect("the N1 preset")
        .replace("law = \"neo-hookean\"", "law = \"reduced-polynomial:2\"")
        .replace(
            "C10 = { start = 1.101295e-3 }",
            "C10 = { start = 1.1e-3 }\nC20 = { start = 2e-4 }",
        )
        .replace("samples = 40", "samples = 20")
        .replace("level = 2", "level = 1");
    Experiment::from_toml_str(&text, "N1, reduced polynomial, coarse").expect("a description")
}

fn main() {
    let records = num("--records", 50.0) as usize;
    let sd = num("--noise", 0.002);
    let out = arg("--out");
    let base = description();
    let vary: Vec<Vary> = vec![
        "protocol.segments[0].ramp_to=2,5,10"
            .parse()
            .expect("depths"),
        "tool.tip_radius=1,2.5".parse().expect("tip radii"),
    ];
    let options = PlanOptions {
        vary: vary.clone(),
        noise: Noise::Sd(sd),
        criterion: Criterion::WorstRelative,
        guess: Vec::new(),
    };
    let c0 = cpu_seconds(false);
    let p = plan(&ExperimentSpec::inline(base.clone()), &options).expect("a plan");
    let plan_cpu = cpu_seconds(false) - c0;
    let mut page = String::from(
        "# Experiment design: `palpate plan` against fits (N1, reduced polynomial)\n\n\
         Written by `cargo run -p palpate-studies --example bench_plan_n1 -- --out docs/validation/plan.md` \
         (studies/examples/bench_plan_n1.rs): the plan's expected standard errors of C10 and C20 \
         against the spread of Levenberg-Marquardt fits to synthetic records with the same noise.\n\n",
    );
    let _ = writeln!(
        page,
        "`palpate plan` on N1 (level 1, needle, reduced polynomial C10 = 1.1e-3, C20 = 2e-4 MPa), noise SD {sd} N per sample: {} candidates in {plan_cpu:.1} s of CPU.\n\n```\n{}```\n",
        p.candidates.len(),
        table(&p)
    );
    print!("{page}");
    let theta = p.guess.clone();
    let truth: Vec<f64> = theta.clone();
    let cands = candidates(&base, &vary).expect("candidates");
    // two candidates: the shallowest with the sharp tip, the deepest with the blunt one
    let checked = [
        "protocol.segments[0].ramp_to=5, tool.tip_radius=1",
        "protocol.segments[0].ramp_to=10, tool.tip_radius=2.5",
    ];
    let _ = writeln!(
        page,
        "| candidate | parameter | expected SE (plan) | SD of {records} fits | plan / fits | within 20 % |\n|---|---|---|---|---|---|"
    );
    let mut all_within = true;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(44);
    let normal = Normal::new(0.0, sd).expect("a normal");
    for label in checked {
        let c = cands
            .iter()
            .find(|c| c.label() == label)
            .expect("a checked candidate");
        let planned = p
            .candidates
            .iter()
            .find(|q| q.label == label)
            .expect("planned");
        let built = c.experiment.model().expect("a model");
        let loading = built.loading().expect("segments");
        let model: Arc<dyn ForwardModel> = Arc::from(built.boxed());
        let clean = model.predict(&truth, &loading).expect("the clean record");
        let c1 = cpu_seconds(false);
        let mut estimates: Vec<Vec<f64>> = Vec::new();
        for _ in 0..records {
            let observed: Vec<f64> = clean.iter().map(|f| f + normal.sample(&mut rng)).collect();
            let set = DataSet::new("synthetic", Arc::clone(&model), loading.clone(), observed)
                .with_model_sensitivities();
            let objective =
                Objective::new(vec![set], ResidualKind::Absolute, &[]).expect("an objective");
            let options = FitOptions {
                start: Some(truth.clone()),
                ..FitOptions::with_method(Method::LevenbergMarquardt(Default::default()))
            };
            match fit(&objective, &options) {
                Ok(r) => estimates.push(r.theta()),
                Err(e) => eprintln!("{label}: a fit failed: {e}"),
            }
        }
        let fits_cpu = cpu_seconds(false) - c1;
        for (j, name) in p.free.iter().enumerate() {
            let xs: Vec<f64> = estimates.iter().map(|t| t[j]).collect();
            let n = xs.len() as f64;
            let mean = xs.iter().sum::<f64>() / n;
            let spread = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let expected = planned.information.standard_errors[j].unwrap_or(f64::NAN);
            let ratio = expected / spread;
            let within = (ratio - 1.0).abs() <= 0.2;
            all_within &= within;
            let _ = writeln!(
                page,
                "| {label} | {name} | {expected:.4e} | {spread:.4e} | {ratio:.3} | {} |",
                if within { "yes" } else { "**no**" }
            );
        }
        eprintln!(
            "{label}: {} fits in {fits_cpu:.1} s of CPU",
            estimates.len()
        );
    }
    let _ = writeln!(
        page,
        "\n{}",
        if all_within {
            "Every expected standard error is within 20 % of the spread of the fits."
        } else {
            "NOT every expected standard error is within 20 % of the spread of the fits."
        }
    );
    println!("{}", &page[page.find("| candidate").unwrap_or(0)..]);
    if let Some(path) = out {
        std::fs::write(&path, &page).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
    if !all_within {
        std::process::exit(1);
    }
}
