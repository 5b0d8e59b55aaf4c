//! The gap diagnosis on the FE models beyond N1's default candidates
//! with what each costs: prints one table row per
//! record (verdict, misfit before/after, FE solves by model, wall and CPU
//! seconds).
//!
//! * Q1 `viscoelasticity`: the three records of `tests/data/gap-q1/`
//!   (`make_gap_q1`) against the elastic punch on mesh level 2
//!   (`-- q1 q1-relaxation,q1-none` for a subset).
//! * N1 -> N3 `modelling_space`: the records of `tests/data/gap-n3/`
//!   (`make_gap_n3`: a 6 mm needle record made by the 3D model,
//!   and a null one made by N1 on the MEDIUM mesh), diagnosed against the
//!   coarse axisymmetric N1 base with `modelling_space` and `friction` as
//!   candidates.
//! * R2 `inclusion`, `friction`, `boundary_condition`: the records of
//!   `tests/data/gap-r2/` (`make_gap_r2`) against the R2
//!   development pass on the 2 mm mesh ([`palpate_tests::r2_dev`]) with
//!   every effect it offers (`-- r2 r2-inclusion` for a subset;
//!   `-- r2probe [H [STEP]]` times one pass per effect).
//!
//! `cargo run --release -p palpate-tools --bin gap_fe_effects [-- q1|n3|r2|probe|r2probe]`

use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace, Table,
};
use palpate_fe::{MeshDensity, N1Needle, Q1Punch, R2Gap};
use palpate_material::Law;
use palpate_tests::r2_dev;
use palpate_uq::gap::{diagnose, GapOptions, GapReport};
use std::collections::BTreeMap;
use std::path::Path;
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

/// The R2 development records (`make_gap_r2`).
const R2_RECORDS: [&str; 4] = ["r2-inclusion", "r2-friction", "r2-sliding", "r2-none"];

/// Element size (mm) of the R2 base model of the diagnosis.
const R2_BASE_H: f64 = 2.0;

fn read_r2(path: &Path) -> (Loading, Vec<f64>) {
    let t = Table::read(path).expect("record");
    let x = t.column("position_mm").unwrap().to_vec();
    let f = t.column("force_N").unwrap().to_vec();
    (Loading::quasi_static(Drive::PositionMm, x), f)
}

/// Cost and size of each R2 effect on the development pass: one solve per
/// variant, its CPU seconds and the force at a few positions.
fn r2_probe() {
    let h: f64 = std::env::args()
        .nth(2)
        .map_or(R2_BASE_H, |a| a.parse().unwrap());
    let step: f64 = std::env::args().nth(3).map_or(1.0, |a| a.parse().unwrap());
    let loading = r2_dev::loading(step);
    let base = R2Gap::new(r2_dev::rolling(h), 1.0);
    let variants: Vec<(&str, Box<dyn ForwardModel>, Vec<f64>)> = vec![
        ("base", Box::new(base.clone()), vec![1e-3]),
        (
            "inclusion c14.7 x44 d10",
            base.as_enrichable()
                .unwrap()
                .enrich(Effect::Inclusion)
                .unwrap(),
            vec![1e-3, 14.7, 44.0, 10.0],
        ),
        (
            "inclusion c1 (off)",
            base.as_enrichable()
                .unwrap()
                .enrich(Effect::Inclusion)
                .unwrap(),
            vec![1e-3, 1.0, 40.0, 10.0],
        ),
        (
            "friction 0.5",
            base.as_enrichable()
                .unwrap()
                .enrich(Effect::Friction)
                .unwrap(),
            vec![1e-3, 0.5],
        ),
        (
            "sliding",
            base.as_enrichable()
                .unwrap()
                .enrich(Effect::BoundaryCondition)
                .unwrap(),
            vec![1e-3],
        ),
    ];
    let n = loading.len();
    for (name, m, theta) in variants {
        let t0 = cpu_seconds();
        let w0 = Instant::now();
        match m.predict(&theta, &loading) {
            Ok(f) => println!(
                "{name}: F[0] {:.5} F[n/4] {:.5} F[n/2] {:.5} F[3n/4] {:.5} F[n-1] {:.5}; {:.1} s CPU, {:.1} s wall",
                f[0],
                f[n / 4],
                f[n / 2],
                f[3 * n / 4],
                f[n - 1],
                cpu_seconds() - t0,
                w0.elapsed().as_secs_f64()
            ),
            Err(e) => println!("{name}: {e} ({:.1} s CPU)", cpu_seconds() - t0),
        }
    }
}

fn main() {
    let which: Option<String> = std::env::args().nth(1);
    let run = |w: &str| which.as_deref().is_none_or(|x| x == w);
    println!("| record | candidates | verdict | noise SD (N) | best misfit before -> after (N) | FE solves | wall s | CPU s |");
    println!("|---|---|---|---|---|---|---|---|");
    if which.as_deref() == Some("r2probe") {
        r2_probe();
        return;
    }
    if run("r2") {
        let dir = palpate_tools::repo("tests/data/gap-r2");
        let names: Vec<String> = match std::env::args().nth(2) {
            Some(list) => list.split(',').map(String::from).collect(),
            None => R2_RECORDS.map(String::from).to_vec(),
        };
        for name in &names {
            let (loading, f) = read_r2(&dir.join(format!("{name}.csv")));
            let base = Counted(Arc::new(R2Gap::new(r2_dev::rolling(R2_BASE_H), 1.0)));
            let effects = base.effects();
            row(name, &effects, || {
                diagnose(&base, &loading, &f, &GapOptions::default()).expect("diagnosis")
            });
        }
    }
    if which.as_deref() == Some("probe") {
        let dir = palpate_tools::repo("tests/data/gap-q1");
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
        let dir = palpate_tools::repo("tests/data/gap-q1");
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
        let dir = palpate_tools::repo("tests/data/gap-n3");
        let names: Vec<String> = match std::env::args().nth(2) {
            Some(list) => list.split(',').map(String::from).collect(),
            None => vec![
                "n3-3d".into(),
                "n3-3d-precise".into(),
                "n3-axisymmetric".into(),
            ],
        };
        for name in names.iter().map(String::as_str) {
            let (loading, f) = read(&dir.join(format!("{name}.csv")));
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
