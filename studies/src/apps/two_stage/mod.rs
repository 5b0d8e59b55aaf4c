//! The two-stage identification of a quasi-linear viscoelastic material by
//! inverse finite elements on a Q1 ramp-and-hold record (docs/benchmarks.md Q1,
//! the third source study): Levenberg-Marquardt on the FE model
//! (`palpate_fe::Q1Punch`), in stages,
//!
//! 1. `elastic`: the law's parameters of an *elastic* FE model fitted to the
//!    ramp of the record (the samples up to the first reaching of the
//!    deepest point), quasi-static: no time steps, no hold;
//! 2. `relaxation`: the Prony terms `g_i, tau_i` of the viscoelastic FE model
//!    (`Q1Punch::with_prony_parameters`, Prony series on the isochoric second
//!    Piola-Kirchhoff stress) fitted to the whole record with the law's
//!    parameters held at the stage-1 values;
//! 3. `polish`: every parameter together, from the stage-2 point;
//!
//! and, for comparison, the one-stage fit of every parameter from the
//! default start. Each stage reports iterations, FE runs (objective
//! evaluations, each one FE run of the record), wall time, the estimates
//! with their standard errors (`palpate_inverse::statistics`), and the
//! polish also 95 % profile-likelihood intervals ([`profile`]).
//!
//! Why stage 1 on the ramp: the ramp (0.5 s) is the part of the record
//! nearest the instantaneous response (`G(0) = 1`), its shape against depth
//! is the elastic nonlinearity, and its elastic FE runs are the cheapest
//! (the ramp samples only, no time integration). The relaxation during the
//! ramp lowers the ramp force (by `sum g_i (1 - tau_i / t_r (1 - e^{-t_r /
//! tau_i}))` at its end: 11 % for g = 0.3 / 0.2, tau = 0.5 / 10 s), so
//! stage 1 underestimates the instantaneous modulus by a few per cent and
//! stage 2 compensates with its weights; the joint polish removes both
//! biases from a start close to the optimum. The long-time (end-of-hold)
//! force alone could not serve: it is `g_inf` times the elastic force, so it
//! confounds the modulus with the weights.
//!
//! FE runs are kept cheap: the stage fits run on the model's mesh (coarse by
//! default) while records come from a finer one; the Jacobian's columns are
//! computed in parallel (rayon, one FE evaluator per thread, kept between
//! calls: `palpate_inverse::jacobian_unbounded`); differences are forward
//! ([`TwoStageOptions::fd`]); the time step is fixed (`max_time_step`), so
//! the discretisation does not move with `tau_i`.

pub mod mesh_check;
pub mod profile;
pub mod ramp;
pub mod report;

use mesh_check::MeshCheck;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::Q1Punch;
use palpate_inverse::staged::{self, Round, Stage, StageModels, StageOptions};
use palpate_inverse::{DataSet, FdOptions, FitReport, LmOptions, Objective};
use palpate_material::Law;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

pub use profile::{Profile, CHI2_1_95};
pub use ramp::ramp_correction;
pub use report::report;

/// The correction rounds stop when every estimate moves by less than this
/// part of its standard error (`palpate_inverse::staged`).
pub use palpate_inverse::staged::{MeshCorrection, ROUND_TOLERANCE};

/// The stages `--stages` can name.
pub const STAGES: [&str; 2] = ["elastic", "relaxation"];

/// How to run the identification.
#[derive(Debug, Clone)]
pub struct TwoStageOptions {
    pub law: Law,
    /// Prony terms.
    pub terms: usize,
    /// Element size under the punch of the fits' mesh (mm), growing by
    /// `1 + h_fine` beyond the 3 mm fine zone.
    pub h_fine: f64,
    /// Element size under the punch of the mesh that corrects the fits
    /// (mm; `None`: no correction): each stage fits the fit mesh's model
    /// corrected, sample by sample, to this mesh at an anchor point
    /// (`palpate_inverse::FidelityCorrection`, output space mapping).
    pub correct_h: Option<f64>,
    /// Element size under the punch of a mesh the polish is checked on
    /// (mm; `None`: no check): one more round of the polish corrected to it
    /// gives the estimates' shift on that mesh
    /// ([`crate::apps::two_stage::mesh_check`]).
    pub check_h: Option<f64>,
    /// Rounds of the polish and the one-stage fit with the correction: the
    /// anchor moves to each round's estimate until the estimates move by
    /// less than [`ROUND_TOLERANCE`] of their standard errors.
    pub correction_rounds: usize,
    /// Time step of the viscoelastic runs (s), fixed for every parameter.
    pub max_time_step: f64,
    /// Radius of the punch's rounded edge (mm; `Q1Punch::edge_radius`).
    pub edge_radius: f64,
    /// Radius of the edge of the fit mesh's punch when the fits are
    /// corrected (`correct_h`; `None`: `edge_radius`). The correcting mesh
    /// keeps `edge_radius`, so the corrected model is the record's punch at
    /// each anchor; a rounding the fit mesh resolves (a few of its cells)
    /// keeps its force smooth in the parameters: at 5 mm the 0.3 mm mesh
    /// with the 0.2 mm edge jumps branch (+11 % at the ramp's end for g2
    /// -1 %), with a 0.6 mm edge it is smooth and 3 x faster (docs/guide/two-stage.md).
    pub fit_edge_radius: Option<f64>,
    /// Stages in order (`elastic`, `relaxation`); the polish follows.
    pub stages: Vec<String>,
    /// Also fit every parameter at once from the default start.
    pub one_stage: bool,
    /// Profile-likelihood intervals of the polished parameters.
    pub profile: bool,
    pub lm: LmOptions,
    pub fd: FdOptions,
}

impl TwoStageOptions {
    /// Defaults: two terms, 0.3 mm elements under the punch (3 s CPU a run
    /// to 1 mm and a 60 s hold; the force is 1.2 % above the 0.2 mm mesh's
    /// at 1.5 mm), time step 1 s, both stages, the
    /// one-stage comparison and the profiles; LM until the SSE changes by
    /// less than 1e-4 of itself or the step by less than 1e-4 of the
    /// parameters (a change of `SSE / sigma^2` by 1e-4 (n - p), under 0.01
    /// for a hundred samples: far inside the 3.84 of a 95 % interval, so
    /// the estimates are converged well within their standard errors), at
    /// most 20 iterations;
    /// forward differences of relative step 1e-4 in parallel.
    pub fn new(law: Law) -> Self {
        TwoStageOptions {
            law,
            terms: 2,
            h_fine: 0.3,
            correct_h: None,
            check_h: None,
            correction_rounds: 3,
            max_time_step: 1.0,
            edge_radius: palpate_fe::q1::DEFAULT_EDGE_RADIUS,
            fit_edge_radius: None,
            stages: STAGES.iter().map(|s| s.to_string()).collect(),
            one_stage: true,
            profile: true,
            lm: LmOptions {
                ftol: 1e-4,
                xtol: 1e-4,
                gtol: 1e-8,
                max_iterations: 20,
                ..LmOptions::default()
            },
            fd: FdOptions {
                relative_step: 1e-4,
                central: false,
                parallel: true,
            },
        }
    }

    /// Parses `--stages elastic,relaxation` (the only order: the relaxation
    /// stage needs the elastic estimate; `relaxation` alone starts the
    /// elastic part at the law's default).
    pub fn parse_stages(text: &str) -> anyhow::Result<Vec<String>> {
        let stages: Vec<String> = text
            .split(',')
            .map(|s| s.trim().to_ascii_lowercase())
            .filter(|s| !s.is_empty())
            .collect();
        anyhow::ensure!(
            !stages.is_empty(),
            "--stages `{text}`: give elastic,relaxation (or one of them)"
        );
        for s in &stages {
            anyhow::ensure!(
                STAGES.contains(&s.as_str()),
                "--stages `{text}`: unknown stage `{s}`; expected {}",
                STAGES.join(", ")
            );
        }
        anyhow::ensure!(
            stages.len() == 1 || stages == ["elastic", "relaxation"],
            "--stages `{text}`: the stages run in the order elastic,relaxation, each once"
        );
        Ok(stages)
    }

    /// Sets the number of Prony terms (1 to 4), or says why not.
    pub fn set_terms(&mut self, n: usize) -> Result<(), String> {
        if !(1..=4).contains(&n) {
            return Err("give 1 to 4 Prony terms".into());
        }
        self.terms = n;
        Ok(())
    }

    /// Sets the fit mesh's element size under the punch (mm, 0.02..1), or
    /// says why not.
    pub fn set_fit_mesh(&mut self, h: f64) -> Result<(), String> {
        if !(h.is_finite() && (0.02..=1.0).contains(&h)) {
            return Err("the element size under the punch must lie in 0.02..1 mm".into());
        }
        self.h_fine = h;
        Ok(())
    }

    /// Sets the element size under the punch of the correcting mesh (mm,
    /// 0.02..1, finer than the fit mesh: set that first), or says why not.
    pub fn set_correct_mesh(&mut self, h: f64) -> Result<(), String> {
        if !(h.is_finite() && (0.02..=1.0).contains(&h)) {
            return Err("the element size under the punch must lie in 0.02..1 mm".into());
        }
        if h >= self.h_fine {
            return Err(format!(
                "the correcting mesh must be finer than the fit mesh ({} mm)",
                self.h_fine
            ));
        }
        self.correct_h = Some(h);
        Ok(())
    }

    /// Sets the element size under the punch of the check mesh (mm,
    /// 0.02..1, not the mesh the estimates are of: the correcting mesh, or
    /// the fit mesh without one; set those first), or says why not.
    pub fn set_mesh_check(&mut self, h: f64) -> Result<(), String> {
        if !(h.is_finite() && (0.02..=1.0).contains(&h)) {
            return Err("the element size under the punch must lie in 0.02..1 mm".into());
        }
        let of = self.correct_h.unwrap_or(self.h_fine);
        if h == of {
            return Err(format!(
                "the estimates are already of the {of} mm mesh: check them on another"
            ));
        }
        self.check_h = Some(h);
        Ok(())
    }

    /// Sets the largest time step of the viscoelastic fits (s, > 0), or
    /// says why not.
    pub fn set_time_step(&mut self, dt: f64) -> Result<(), String> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err("must be a positive number of seconds".into());
        }
        self.max_time_step = dt;
        Ok(())
    }

    /// Sets the punch's edge radius (mm), or says why `rho` is not one
    /// ([`Q1Punch::set_edge_radius`]).
    pub fn set_edge_radius(&mut self, rho: f64) -> Result<(), String> {
        Q1Punch::new(self.law).set_edge_radius(rho)?;
        self.edge_radius = rho;
        Ok(())
    }

    /// Sets the edge radius of the fit mesh's punch (mm), for fits
    /// corrected to a finer mesh (set `correct_h` first), or says why not.
    pub fn set_fit_edge_radius(&mut self, rho: f64) -> Result<(), String> {
        Q1Punch::new(self.law).set_edge_radius(rho)?;
        if self.correct_h.is_none() {
            return Err(
                "the fit mesh's punch may differ from the record's only when the fits are corrected to a finer mesh that keeps it (give the correcting mesh too)"
                    .into(),
            );
        }
        self.fit_edge_radius = Some(rho);
        Ok(())
    }

    /// The elastic FE model of the fits.
    pub fn elastic_model(&self) -> Q1Punch {
        self.model_with(
            self.h_fine,
            self.fit_edge_radius.unwrap_or(self.edge_radius),
        )
    }

    /// The viscoelastic FE model of the fits (law, then `g_i, tau_i_s`).
    pub fn viscoelastic_model(&self) -> Q1Punch {
        self.viscous(self.elastic_model())
    }

    /// The elastic FE model with elements of `h` mm under the punch and the
    /// record's punch (`edge_radius`).
    pub fn elastic_model_at(&self, h: f64) -> Q1Punch {
        self.model_with(h, self.edge_radius)
    }

    fn model_with(&self, h: f64, edge_radius: f64) -> Q1Punch {
        let mut m = Q1Punch::new(self.law);
        m.edge_radius = edge_radius;
        m.set_fine_size(h);
        m
    }

    /// The viscoelastic FE model with elements of `h` mm under the punch
    /// and the record's punch.
    pub fn viscoelastic_model_at(&self, h: f64) -> Q1Punch {
        self.viscous(self.elastic_model_at(h))
    }

    fn viscous(&self, elastic: Q1Punch) -> Q1Punch {
        let mut m = elastic.with_prony_parameters(self.terms);
        m.options.max_time_step = Some(self.max_time_step);
        m
    }
}

/// A Q1 record: depth and force against time.
#[derive(Debug, Clone)]
pub struct Q1Record {
    pub name: String,
    pub time: Vec<f64>,
    pub depth: Vec<f64>,
    pub force: Vec<f64>,
}

impl Q1Record {
    /// Checks the record: at least 3 samples, times increasing, depths
    /// finite and >= 0, a ramp (some depth > 0) followed by a hold.
    pub fn new(
        name: &str,
        time: Vec<f64>,
        depth: Vec<f64>,
        force: Vec<f64>,
    ) -> anyhow::Result<Q1Record> {
        anyhow::ensure!(
            time.len() == depth.len() && depth.len() == force.len() && time.len() >= 3,
            "{name}: a Q1 record needs time_s, displacement_mm and force_N on at least 3 rows"
        );
        for k in 1..time.len() {
            anyhow::ensure!(
                time[k] > time[k - 1],
                "{name}: row {}: time_s {} does not increase (previous {})",
                k + 1,
                time[k],
                time[k - 1]
            );
        }
        let r = Q1Record {
            name: name.into(),
            time,
            depth,
            force,
        };
        let k = r.ramp_end();
        anyhow::ensure!(
            r.depth[k] > 0.0 && k + 1 < r.depth.len(),
            "{name}: a Q1 record is a ramp to a depth > 0 and a hold after it (deepest point at row {} of {})",
            k + 1,
            r.depth.len()
        );
        Ok(r)
    }

    /// Reads a record file (`time_s,displacement_mm,force_N`, as `palpate
    /// simulate --benchmark Q1 --csv` writes).
    pub fn read(path: &std::path::Path) -> anyhow::Result<Q1Record> {
        let d = crate::records::TestData::read("Q1", crate::records::TestKind::N1, path)?;
        let time = d.loading.time.clone().ok_or_else(|| {
            anyhow::anyhow!(
                "{}: a Q1 record is a timed ramp-and-hold: it needs a time_s column",
                path.display()
            )
        })?;
        Q1Record::new(
            &path.display().to_string(),
            time,
            d.loading.drive.clone(),
            d.observed,
        )
    }

    /// Index of the first sample at the deepest point (the end of the ramp).
    pub fn ramp_end(&self) -> usize {
        let max = self.depth.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        self.depth.iter().position(|&d| d == max).unwrap_or(0)
    }

    /// The whole record's loading (timed).
    pub fn loading(&self) -> Loading {
        Loading::timed(Drive::DisplacementMm, self.time.clone(), self.depth.clone())
    }

    /// The ramp as a quasi-static loading and its forces.
    pub fn ramp(&self) -> (Loading, Vec<f64>) {
        let k = self.ramp_end();
        (
            Loading::quasi_static(Drive::DisplacementMm, self.depth[..=k].to_vec()),
            self.force[..=k].to_vec(),
        )
    }
}

/// One stage's result.
#[derive(Debug, Clone, Serialize)]
pub struct StageResult {
    /// `elastic`, `relaxation`, `polish` or `one-stage`.
    pub stage: String,
    /// Free parameters.
    pub free: Vec<String>,
    /// Samples fitted.
    pub samples: usize,
    pub iterations: u64,
    /// FE runs (objective evaluations, finite-difference ones included).
    pub fe_runs: usize,
    pub wall_s: f64,
    pub converged: bool,
    pub termination: String,
    /// Every parameter of the viscoelastic model at the end of the stage
    /// (held ones at their values), in the model's order.
    pub theta: Vec<f64>,
    /// Stage 1: the factor on the moduli from the force-level QLV
    /// correction of the ramp ([`ramp_correction`]), when made.
    pub correction: Option<f64>,
    /// The mesh corrections, one per round (empty without `correct_h`).
    pub mesh_corrections: Vec<MeshCorrection>,
    /// LM iterations of each round (one round without `correct_h`).
    pub round_iterations: Vec<u64>,
    /// Whether LM accepted any step: `false` when every round ended where
    /// it started (every trial step raised the SSE until the step test
    /// stopped it), which a report flags.
    pub moved: bool,
    /// With a correcting mesh: whether the last round's estimate stayed
    /// within [`ROUND_TOLERANCE`] SE of its anchor (a stage corrected once,
    /// or without correction: true). `false`: the rounds ran out with the
    /// anchor still moving, so the estimate is not the correcting mesh's
    /// optimum, which a report flags.
    pub settled: bool,
    /// The largest move of the last round, in standard errors of the
    /// estimate (0 without correction rounds).
    pub last_round_move_se: f64,
    pub fit: FitReport,
}

/// The whole identification.
#[derive(Debug, Clone, Serialize)]
pub struct TwoStageResult {
    pub record: String,
    pub model: String,
    pub names: Vec<String>,
    pub stages: Vec<StageResult>,
    pub profiles: Vec<Profile>,
    pub one_stage: Option<StageResult>,
    /// The polish's estimates on the check mesh, if asked.
    pub mesh_check: Option<MeshCheck>,
    /// The fit mesh's element size under the punch (mm).
    pub fit_mesh_mm: f64,
    /// The correcting mesh's element size under the punch (mm), if any.
    pub correcting_mesh_mm: Option<f64>,
    /// The edge radius of the fit mesh's punch when it differs from the
    /// record's (mm).
    pub fit_edge_radius_mm: Option<f64>,
    /// Totals of the staged route (stages, polish, without profiles).
    pub staged_fe_runs: usize,
    pub staged_wall_s: f64,
}

/// Progress of the stages (the CLI prints it).
pub type Say<'a> = &'a (dyn Fn(&str) + Sync);

pub(crate) fn lm_fit(
    objective: &Objective,
    start: Vec<f64>,
    options: &TwoStageOptions,
    lm: LmOptions,
) -> anyhow::Result<(FitReport, f64)> {
    Ok(staged::lm_fit(objective, start, lm, options.fd)?)
}

impl TwoStageOptions {
    /// The LM settings of every stage.
    pub fn stage_options(&self) -> StageOptions {
        StageOptions {
            lm: self.lm,
            fd: self.fd,
        }
    }
}

/// The progress line of a correction round (the fit mesh corrected to the
/// correcting or check mesh).
pub(crate) fn say_round(say: Say<'_>) -> impl FnMut(&Round<'_>) + '_ {
    move |r: &Round<'_>| {
        let (lo, hi) = r.ratio_range;
        say(&format!(
            "  round {}: the fit mesh's force corrected by x {lo:.4} .. {hi:.4} at [{}] ({:.0} s)",
            r.round + 1,
            r.anchor
                .iter()
                .map(|v| format!("{v:.4e}"))
                .collect::<Vec<_>>()
                .join(", "),
            r.wall_s
        ));
    }
}

/// Runs one stage ([`staged::run_stage`]: LM from `start`, with correction
/// rounds when the models have a correcting mesh). Returns the result and
/// the data set of the last round (the profiles refit it).
pub(crate) fn run_stage(
    data: &Stage,
    models: &StageModels,
    start: Vec<f64>,
    rounds: usize,
    options: &TwoStageOptions,
    say: Say<'_>,
) -> anyhow::Result<(StageResult, DataSet)> {
    let out = staged::run_stage(
        data,
        models,
        start,
        rounds,
        &options.stage_options(),
        &mut say_round(say),
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", data.stage))?;
    Ok(stage_result(&data.stage, out))
}

/// A stage's result from the generic outcome.
pub(crate) fn stage_result(stage: &str, out: staged::StageOutcome) -> (StageResult, DataSet) {
    (
        StageResult {
            stage: stage.into(),
            free: out.free,
            samples: out.samples,
            iterations: out.iterations,
            fe_runs: out.runs,
            wall_s: out.wall_s,
            converged: out.converged,
            termination: out.termination,
            theta: out.theta,
            correction: None,
            mesh_corrections: out.corrections,
            round_iterations: out.round_iterations,
            moved: out.moved,
            settled: out.settled,
            last_round_move_se: out.last_round_move_se,
            fit: out.fit,
        },
        out.set,
    )
}

/// Past this depth (mm) a fit mesh coarser than [`DEEP_FIT_MESH`] is stiff
/// under the punch's rounded edge (18 % at 5 mm for 0.3 mm cells, 7 % for
/// 0.15 mm; docs/guide/two-stage.md).
pub const DEEP_RECORD: f64 = 2.0;
/// The element size under the punch below which deep fits are left alone.
pub const DEEP_FIT_MESH: f64 = 0.15;

/// A note for a record deeper than [`DEEP_RECORD`] fitted on a mesh coarser
/// than [`DEEP_FIT_MESH`] without a correcting mesh, naming the remedy.
pub fn deep_record_note(record: &Q1Record, options: &TwoStageOptions) -> Option<String> {
    let depth = record.depth[record.ramp_end()];
    (depth > DEEP_RECORD && options.h_fine > DEEP_FIT_MESH && options.correct_h.is_none()).then(|| {
        format!(
            "note: the record reaches {depth} mm; past {DEEP_RECORD} mm the {} mm fit mesh is stiff under the \
             punch's edge (18 % at 5 mm for 0.3 mm cells), and the estimates carry its error: \
             --correct-mesh 0.1 (manifest: correct_mesh) corrects each fit to a 0.1 mm mesh at a few runs of it",
            options.h_fine
        )
    })
}

/// Runs the stages, the polish, the profiles and the one-stage comparison
/// on `record`.
pub fn identify(
    record: &Q1Record,
    options: &TwoStageOptions,
    say: Say<'_>,
) -> anyhow::Result<TwoStageResult> {
    if let Some(h) = options.correct_h {
        anyhow::ensure!(
            h < options.h_fine,
            "the correcting mesh ({h} mm under the punch) must be finer than the fit mesh ({} mm)",
            options.h_fine
        );
    }
    anyhow::ensure!(
        options.fit_edge_radius.is_none() || options.correct_h.is_some(),
        "the fit mesh's punch edge ({:?} mm) differs from the record's ({} mm) only with a correcting mesh",
        options.fit_edge_radius,
        options.edge_radius
    );
    if let Some(note) = deep_record_note(record, options) {
        say(&note);
    }
    let visco: Arc<dyn ForwardModel> = Arc::new(options.viscoelastic_model());
    let elastic = StageModels {
        coarse: Arc::new(options.elastic_model()),
        fine: options
            .correct_h
            .map(|h| Arc::new(options.elastic_model_at(h)) as Arc<dyn ForwardModel>),
    };
    let viscous = StageModels {
        coarse: visco.clone(),
        fine: options
            .correct_h
            .map(|h| Arc::new(options.viscoelastic_model_at(h)) as Arc<dyn ForwardModel>),
    };
    let space = visco.space().clone();
    let names = space.names();
    let n_law = elastic.coarse.space().len();
    let mut theta: Vec<f64> = space.params.iter().map(|p| p.initial).collect();
    let whole = |stage: &str, fixed| Stage {
        stage: stage.into(),
        set: record.name.clone(),
        loading: record.loading(),
        observed: record.force.clone(),
        fixed,
    };
    let done = |s: &StageResult| {
        say(&format!(
            "  {} iterations {:?}, {} FE runs, {:.1} s",
            s.iterations, s.round_iterations, s.fe_runs, s.wall_s
        ))
    };
    let mut stages = Vec::new();
    for stage in &options.stages {
        match stage.as_str() {
            "elastic" => {
                let (loading, observed) = record.ramp();
                let data = Stage {
                    stage: stage.clone(),
                    set: format!("{} (ramp)", record.name),
                    loading,
                    observed,
                    fixed: Vec::new(),
                };
                say(&format!(
                    "stage 1 (elastic): {} on the ramp ({} samples), elastic FE",
                    names[..n_law].join(", "),
                    data.observed.len()
                ));
                let (mut result, _) =
                    run_stage(&data, &elastic, theta[..n_law].to_vec(), 1, options, say)?;
                theta[..n_law].copy_from_slice(&result.theta);
                let t0 = Instant::now();
                if let Some((scale, prony)) =
                    ramp_correction(record, &result.fit.sets[0].predicted, options.terms)
                {
                    for (k, p) in space.params[..n_law].iter().enumerate() {
                        if p.is_modulus() {
                            theta[k] *= scale;
                        }
                    }
                    theta[n_law..].copy_from_slice(&prony);
                    result.correction = Some(scale);
                    say(&format!(
                        "  force-level QLV correction of the ramp (no FE run): moduli x {scale:.4}, Prony start {prony:.4?}"
                    ));
                }
                result.theta = theta.clone();
                result.wall_s += t0.elapsed().as_secs_f64();
                stages.push(result);
            }
            _ => {
                let fixed: Vec<(String, f64)> =
                    (0..n_law).map(|k| (names[k].clone(), theta[k])).collect();
                say(&format!(
                    "stage 2 (relaxation): {} on the whole record ({} samples), the law held",
                    names[n_law..].join(", "),
                    record.force.len()
                ));
                let (result, _) = run_stage(
                    &whole(stage, fixed),
                    &viscous,
                    theta.clone(),
                    1,
                    options,
                    say,
                )?;
                theta = result.theta.clone();
                stages.push(result);
            }
        }
        done(stages.last().expect("a stage"));
    }
    say("polish: every parameter on the whole record");
    let rounds = options.correction_rounds;
    let (polish, full) = run_stage(
        &whole("polish", Vec::new()),
        &viscous,
        theta,
        rounds,
        options,
        say,
    )?;
    done(&polish);
    stages.push(polish.clone());
    let staged_fe_runs = stages.iter().map(|s| s.fe_runs).sum();
    let staged_wall_s = stages.iter().map(|s| s.wall_s).sum();
    let mesh_check = match options.check_h {
        Some(h) => {
            say(&format!(
                "mesh check: the polish corrected to a {} mm mesh from its estimate",
                crate::apps::two_stage::mesh_check::mm(h)
            ));
            let se: Vec<Option<f64>> = polish
                .fit
                .parameters
                .iter()
                .map(|e| e.standard_error)
                .collect();
            let c = crate::apps::two_stage::mesh_check::check_estimate(
                record,
                options,
                &polish.theta,
                &se,
                say,
            )?;
            say(&format!(
                "  {} iterations in {} rounds, {} FE runs, {:.1} s",
                c.iterations, c.rounds, c.fit_mesh_runs, c.wall_s
            ));
            Some(c)
        }
        None => None,
    };
    let profiles = if options.profile {
        say("profile-likelihood intervals of the polished parameters");
        crate::apps::two_stage::profile::profiles(&full, &polish, options)
    } else {
        Vec::new()
    };
    let one_stage = if options.one_stage {
        say("one-stage comparison: every parameter from the default start");
        let start: Vec<f64> = space.params.iter().map(|p| p.initial).collect();
        let (s, _) = run_stage(
            &whole("one-stage", Vec::new()),
            &viscous,
            start,
            rounds,
            options,
            say,
        )?;
        done(&s);
        Some(s)
    } else {
        None
    };
    Ok(TwoStageResult {
        record: record.name.clone(),
        // the model the estimates are of: the correcting mesh's (the
        // record's punch) when the fits were corrected
        model: viscous
            .fine
            .as_ref()
            .map_or_else(|| visco.name(), |f| f.name()),
        names,
        stages,
        profiles,
        one_stage,
        mesh_check,
        fit_mesh_mm: options.h_fine,
        correcting_mesh_mm: options.correct_h,
        fit_edge_radius_mm: options.fit_edge_radius,
        staged_fe_runs,
        staged_wall_s,
    })
}

#[cfg(test)]
mod tests;
