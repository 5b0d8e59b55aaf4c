//! Answers and cost of the gap diagnosis with explanations made of several
//! effects on the N1 two-effect records of `studies/data/gap-dev2/n1/`
//! (`cargo run -p palpate-tools --bin make_gap_two -- n1`: the needle to
//! 8 mm on the MEDIUM mesh with two planted effects, and noise-only
//! records). Goal: an N1 diagnosis with sets in under 3 minutes on 2 cores.
//!
//! Each record is diagnosed as `palpate diagnose --benchmark N1 --data
//! FILE --effects friction,boundary_condition,material_form,zero_offset`
//! does it: the CLI's N1 base (neo-Hookean, frictionless needle, bonded
//! base, coarse mesh, `palpate_studies::model::gap_base`), those four
//! candidates (the CLI's default for N1 is the first two; the records
//! plant the other two as well), every other option at its default. The
//! base is wrapped to count the FE simulations. Prints, per record, the
//! planted set, the explanation, the remainder over the noise, the FE
//! runs, CPU seconds (user + system of the process, all threads) and wall
//! seconds, and the load average before and after.
//!
//! The output is the page `docs/validation/gap-sets-n1.md`:
//! `cargo run -p palpate-tests --example bench_gap_sets_n1 > docs/validation/gap-sets-n1.md`
//! (`-- PREFIX...` for a subset: records' names or `null-`; `--explain` also
//! writes each report's explanation, its candidates and the FE runs by
//! model to stderr: where the runs go).

use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace, Table,
};
use palpate_fe::{MeshDensity, N1Needle};
use palpate_material::Law;
use palpate_uq::gap::{diagnose, GapOptions};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// FE simulations made through [`Counted`].
static RUNS: AtomicUsize = AtomicUsize::new(0);

/// FE simulations by model (`--explain`: where the runs go).
static BY_MODEL: Mutex<BTreeMap<String, usize>> = Mutex::new(BTreeMap::new());

/// A model that counts its predictions, and whose enrichments do too.
struct Counted(Arc<dyn ForwardModel>);

struct CountedEval<'a>(Box<dyn Evaluator + 'a>, String);

impl Evaluator for CountedEval<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        RUNS.fetch_add(1, Ordering::Relaxed);
        if let Ok(mut m) = BY_MODEL.lock() {
            *m.entry(self.1.clone()).or_default() += 1;
        }
        self.0.predict_into(theta, loading, out)
    }
}

impl ForwardModel for Counted {
    fn name(&self) -> String {
        self.0.name()
    }
    fn space(&self) -> &ParamSpace {
        self.0.space()
    }
    fn observable(&self) -> Observable {
        self.0.observable()
    }
    fn expensive(&self) -> bool {
        self.0.expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(CountedEval(self.0.evaluator(), self.0.name()))
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for Counted {
    fn effects(&self) -> Vec<Effect> {
        palpate_core::enrichable::effects_of(self.0.as_ref())
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        let rich = palpate_core::enrichable::enrich(self.0.as_ref(), effect)?;
        Ok(Box::new(Counted(Arc::from(rich))))
    }
    fn enrich_forms(
        &self,
        effect: Effect,
    ) -> Result<Vec<palpate_core::enrichable::EffectForm>, ForwardError> {
        let forms = palpate_core::enrichable::enrich_forms(self.0.as_ref(), effect)?;
        Ok(forms
            .into_iter()
            .map(|f| palpate_core::enrichable::EffectForm {
                name: f.name,
                model: Box::new(Counted(Arc::from(f.model))),
            })
            .collect())
    }
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        palpate_core::enrichable::embed(self.0.as_ref(), base_theta)
    }
}

/// User + system CPU seconds of this process.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// The 1-minute load average.
fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into())
}

/// The candidates: `--effects friction,boundary_condition,material_form,zero_offset`.
const CANDIDATES: [Effect; 4] = [
    Effect::Friction,
    Effect::BoundaryCondition,
    Effect::MaterialForm,
    Effect::ZeroOffset,
];

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/data/gap-dev2/n1");
    let args: Vec<String> = std::env::args().skip(1).collect();
    let explain = args.iter().any(|a| a == "--explain");
    let prefixes: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).expect("truth"))
            .expect("truth.json");
    let mut names: Vec<&String> = truth
        .as_object()
        .expect("object")
        .keys()
        .filter(|k| prefixes.is_empty() || prefixes.iter().any(|p| k.starts_with(p.as_str())))
        .collect();
    names.sort();
    let commit = std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "?".into());
    let load_before = load();
    println!(
        "# Gap diagnosis: explanations of N1 two-effect records\n\n\
         Generated by `cargo run -p palpate-tests --example bench_gap_sets_n1 > docs/validation/gap-sets-n1.md` \
         (dev profile) at commit {commit}, on a machine of {} cores (rayon threads) shared with other jobs \
         (load average below). Records: `studies/data/gap-dev2/n1/` \
         (`cargo run -p palpate-tools --bin make_gap_two -- n1`: the N1 needle to 8 mm, 33 samples, \
         simulated on the MEDIUM mesh with two planted effects, or none, noise 0.5-2 % of the peak force). \
         Each is diagnosed as `palpate diagnose --benchmark N1 --data FILE --effects \
         friction,boundary_condition,material_form,zero_offset` does it: the base neo-Hookean, \
         frictionless needle, bonded base, coarse mesh. A record is right when the explanation is \
         exactly the planted set. Each visible beside the other: the misfit the other planted \
         effect alone leaves (the diagnosis's first step), over the noise. FE runs: simulations of the FE model (cached predictions not counted); \
         CPU: user + system seconds of the diagnosis, all threads.\n",
        rayon::current_num_threads()
    );
    println!(
        "| record | planted | each visible beside the other | explanation | remainder / noise | FE runs | CPU s | wall s | form |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let (mut right, mut pairs, mut pairs_right) = (0, 0, 0);
    let (mut wall_max, mut cpu_total, mut runs_total) = (0.0f64, 0.0, 0);
    for name in &names {
        let table = Table::read(dir.join(format!("{name}.csv"))).expect("record");
        let d = table.column("displacement_mm").expect("d").to_vec();
        let f = table.column("force_N").expect("force").to_vec();
        let loading = Loading::quasi_static(Drive::DisplacementMm, d);
        let mut base = N1Needle::new(Law::NeoHookean);
        base.friction = 0.0;
        base.mesh = MeshDensity::COARSE;
        let base = Counted(Arc::new(base));
        let options = GapOptions {
            effects: Some(CANDIDATES.to_vec()),
            ..GapOptions::default()
        };
        RUNS.store(0, Ordering::Relaxed);
        if let Ok(mut m) = BY_MODEL.lock() {
            m.clear();
        }
        let (cpu0, wall0) = (cpu_seconds(), Instant::now());
        let r = diagnose(&base, &loading, &f, &options).expect("diagnosis");
        let (cpu, wall) = (cpu_seconds() - cpu0, wall0.elapsed().as_secs_f64());
        let runs = RUNS.load(Ordering::Relaxed);
        if explain {
            eprintln!("== {name}\n{}", r.explanation);
            for c in &r.ranking {
                eprintln!(
                    "  candidate {} {:?}: misfit {:.3e} -> {:.3e}, held-out gain {:.1}, earns {}, {:?}",
                    c.effect, c.form, c.misfit_before, c.misfit_after, c.heldout_gain, c.earns, c.params
                );
            }
            for m in &r.explanation_set {
                eprintln!("  member {}: {}", m.effect, m.evidence);
            }
            eprintln!("  dropped {:?}; failed {:?}", r.dropped, r.failed);
            if let Ok(m) = BY_MODEL.lock() {
                for (model, n) in m.iter() {
                    eprintln!("  FE runs of {model}: {n}");
                }
            }
        }
        let mut planted: Vec<String> = truth[name.as_str()]["expected"]
            .as_array()
            .expect("expected")
            .iter()
            .map(|e| e.as_str().unwrap_or("").to_string())
            .collect();
        planted.sort();
        let mut found: Vec<String> = r
            .explanation_set
            .iter()
            .map(|m| m.effect.name().to_string())
            .collect();
        found.sort();
        if found == planted {
            right += 1;
        }
        if planted.len() == 2 {
            pairs += 1;
            if found == planted {
                pairs_right += 1;
            }
        }
        wall_max = wall_max.max(wall);
        cpu_total += cpu;
        runs_total += runs;
        // what each planted effect's partner alone leaves (the first
        // step's candidates), in noise SDs: the effect's visibility
        let alone: Vec<String> = planted
            .iter()
            .rev()
            .map(|e| {
                r.ranking
                    .iter()
                    .find(|c| c.effect.name() == e)
                    .map_or("-".into(), |c| {
                        format!("{:.1}", c.misfit_after / r.noise_sd)
                    })
            })
            .collect();
        let forms: Vec<String> = r
            .explanation_set
            .iter()
            .filter_map(|m| m.form.clone())
            .collect();
        let set = |v: &[String]| {
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join(" + ")
            }
        };
        println!(
            "| {name} | {} | {} | {} | {:.2} | {runs} | {cpu:.1} | {wall:.1} | {} |",
            set(&planted),
            alone.join(" / "),
            set(&found),
            r.remainder.misfit_over_noise,
            forms.join(" ")
        );
    }
    let n = names.len().max(1);
    println!(
        "\n**{right} of {} right**; two-effect records: {pairs_right} of {pairs}; per diagnosis: \
         FE runs mean {:.0}, CPU mean {:.1} s, wall max {wall_max:.1} s; load average {load_before} \
         before, {} after.",
        names.len(),
        runs_total as f64 / n as f64,
        cpu_total / n as f64,
        load()
    );
}
