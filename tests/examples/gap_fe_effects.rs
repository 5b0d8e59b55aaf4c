//! The gap diagnosis on the FE models beyond N1's default candidates
//! (issue 14, item 5), with what each costs: prints one table row per
//! record (verdict, misfit before/after, FE solves by model, wall and CPU
//! seconds).
//!
//! * Q1 `viscoelasticity`: the three records of `tests/data/gap-q1/`
//!   (`examples/make_gap_q1.rs`) against the elastic punch on mesh level 2
//!   (`-- q1 q1-relaxation,q1-none` for a subset).
//! * N1 -> N3 `modelling_space`: a 6 mm needle record made by the 3D model
//!   (N3 level 1, neo-Hookean C10 1e-3 MPa, frictionless, noise 1 % of the
//!   peak, seed 31; written once to `target/gap_n3_record.csv`), diagnosed
//!   against the coarse axisymmetric N1 base with `modelling_space` and
//!   `friction` as candidates; and an N1 (MEDIUM mesh) record of the same
//!   needle with the same candidates, where `modelling_space` must not be
//!   named.
//!
//! `cargo run --release -p palpate-tests --example gap_fe_effects [-- q1|n3|probe]`

use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace, Table,
};
use palpate_fe::{MeshDensity, N1Needle, N3Needle, Q1Punch};
use palpate_material::Law;
use palpate_uq::gap::{diagnose, GapOptions, GapReport};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// FE solves by the first word of the model's name (N1, N3, Q1).
static SOLVES: Mutex<BTreeMap<String, usize>> = Mutex::new(BTreeMap::new());

struct Counted(Arc<dyn ForwardModel>);

struct CountedEval<'a>(Box<dyn Evaluator + 'a>, String);

impl Evaluator for CountedEval<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        *SOLVES.lock().unwrap().entry(self.1.clone()).or_default() += 1;
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
        let tag = self
            .0
            .name()
            .split_whitespace()
            .next()
            .unwrap_or("")
            .to_string();
        Box::new(CountedEval(self.0.evaluator(), tag))
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

fn row(record: &str, candidates: &[Effect], run: impl FnOnce() -> GapReport) {
    SOLVES.lock().unwrap().clear();
    let (wall, cpu) = (Instant::now(), cpu_seconds());
    let r = run();
    let (wall, cpu) = (wall.elapsed().as_secs_f64(), cpu_seconds() - cpu);
    let names: Vec<&str> = candidates.iter().map(|e| e.name()).collect();
    let solves: Vec<String> = SOLVES
        .lock()
        .unwrap()
        .iter()
        .map(|(k, v)| format!("{k}: {v}"))
        .collect();
    let (before, after) = r
        .ranking
        .first()
        .map_or((r.base.misfit, r.base.misfit), |e| {
            (e.misfit_before, e.misfit_after)
        });
    println!(
        "| {record} | {} | {} | {:.3e} | {:.3e} -> {:.3e} | {} | {wall:.1} | {cpu:.1} |",
        names.join(", "),
        r.verdict,
        r.noise_sd,
        before,
        after,
        solves.join(", ")
    );
    for f in &r.failed {
        eprintln!("  {record} {}: failed: {}", f.effect, f.error);
    }
    for e in &r.ranking {
        eprintln!(
            "  {record} {}: misfit {:.3e} -> {:.3e}, held-out {:.3e} -> {:.3e}, earns {}, params {:?}",
            e.effect, e.misfit_before, e.misfit_after, e.heldout_before, e.heldout_after, e.earns, e.params
        );
    }
}

fn read(path: &Path) -> (Loading, Vec<f64>) {
    let t = Table::read(path).expect("record");
    let d = t.column("displacement_mm").unwrap().to_vec();
    let f = t.column("force_N").unwrap().to_vec();
    let loading = match t.column("time_s") {
        Ok(time) => Loading::timed(Drive::DisplacementMm, time.to_vec(), d),
        Err(_) => Loading::quasi_static(Drive::DisplacementMm, d),
    };
    (loading, f)
}

/// A needle record to 6 mm every 0.25 mm from `model`, noise 1 % of the
/// peak (seed), written once to `target/<name>.csv`.
fn needle_record(name: &str, model: &dyn ForwardModel, seed: u64) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../target/{name}.csv"));
    if !path.exists() {
        let depths: Vec<f64> = (0..=24).map(|i| 0.25 * i as f64).collect();
        let loading = Loading::quasi_static(Drive::DisplacementMm, depths.clone());
        let f = model.predict(&[1.0e-3], &loading).expect("needle record");
        let peak = f.iter().cloned().fold(0.0, f64::max);
        let noise = Normal::new(0.0, 0.01 * peak).expect("sd");
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut csv = format!(
            "# {} C10 1e-3, noise 1 % of peak, seed {seed}\ndisplacement_mm,force_N\n",
            model.name()
        );
        for (d, v) in depths.iter().zip(&f) {
            let _ = writeln!(csv, "{d},{:.6e}", v + noise.sample(&mut rng));
        }
        std::fs::write(&path, csv).expect("write record");
    }
    path
}

fn main() {
    let which: Option<String> = std::env::args().nth(1);
    let run = |w: &str| which.as_deref().is_none_or(|x| x == w);
    println!("| record | candidates | verdict | noise SD (N) | best misfit before -> after (N) | FE solves | wall s | CPU s |");
    println!("|---|---|---|---|---|---|---|---|");
    if which.as_deref() == Some("probe") {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/gap-q1");
        let (loading, _) = read(&dir.join("q1-relaxation.csv"));
        let mut base = Q1Punch::new(Law::NeoHookean);
        base.level = std::env::args().nth(3).map_or(1, |a| a.parse().unwrap());
        let mut v = palpate_fe::Q1Viscous::new(base);
        let dt: Option<f64> = std::env::args().nth(2).map(|a| a.parse().unwrap());
        v.max_time_step = dt;
        for theta in [
            [1e-3, 0.1, 1.0],
            [1e-3, 1e-5, 1.0],
            [1e-3, 0.1, 0.105],
            [1e-3, 0.3, 2.0],
        ] {
            let t0 = cpu_seconds();
            let r = v.predict(&theta, &loading);
            println!(
                "{theta:?}: {} in {:.1} s",
                match &r {
                    Ok(f) => format!("ok, F(end) {:.4e}", f[f.len() - 1]),
                    Err(e) => e.to_string(),
                },
                cpu_seconds() - t0
            );
        }
        return;
    }
    if run("q1") {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/gap-q1");
        let names: Vec<String> = match std::env::args().nth(2) {
            Some(list) => list.split(',').map(String::from).collect(),
            None => ["q1-relaxation", "q1-weak-relaxation", "q1-none"]
                .map(String::from)
                .to_vec(),
        };
        for name in &names {
            let name = name.as_str();
            let (loading, f) = read(&dir.join(format!("{name}.csv")));
            // level 2: level 1 does not converge at the first viscoelastic
            // hold increment (docs/gap-diagnosis.md)
            let mut base = Q1Punch::new(Law::NeoHookean);
            base.level = 2;
            let base = Counted(Arc::new(base));
            let effects = [Effect::Viscoelasticity];
            row(name, &effects, || {
                let options = GapOptions {
                    effects: Some(effects.to_vec()),
                    ..GapOptions::default()
                };
                diagnose(&base, &loading, &f, &options).expect("diagnosis")
            });
        }
    }
    if run("n3") {
        let mut n3 = N3Needle::new(Law::NeoHookean);
        n3.friction = 0.0;
        let mut n1 = N1Needle::new(Law::NeoHookean);
        n1.friction = 0.0;
        n1.mesh = MeshDensity::MEDIUM;
        let records = [
            (
                "n3-frictionless (3D record)",
                needle_record("gap_n3_record", &n3, 31),
            ),
            (
                "n1-frictionless (MEDIUM N1 record)",
                needle_record("gap_n1_medium_record", &n1, 32),
            ),
        ];
        for (name, path) in records {
            let (loading, f) = read(&path);
            let mut base = N1Needle::new(Law::NeoHookean);
            base.friction = 0.0;
            base.mesh = MeshDensity::COARSE;
            let base = Counted(Arc::new(base));
            let effects = [Effect::ModellingSpace, Effect::Friction];
            row(name, &effects, || {
                let options = GapOptions {
                    effects: Some(effects.to_vec()),
                    ..GapOptions::default()
                };
                diagnose(&base, &loading, &f, &options).expect("diagnosis")
            });
        }
    }
}
