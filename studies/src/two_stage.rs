//! The two-stage identification of a quasi-linear viscoelastic material by
//! inverse finite elements on a Q1 ramp-and-hold record (BENCHMARKS.md Q1;
//! issue 13, the third source study): Levenberg-Marquardt on the FE model
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

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::Q1Punch;
use palpate_inverse::{
    fit, CorrectedModel, DataSet, FdOptions, FidelityCorrection, FitOptions, FitReport, LmOptions,
    Method, Objective, ResidualKind,
};
use palpate_material::Law;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

pub use crate::two_stage_report::report;
pub use crate::two_stage_step::TwoStageStep;

/// The chi-square(1) 95 % quantile: the profile-likelihood threshold
/// (Venzon & Moolgavkar 1988), as `palpate_uq::gap`'s profiles.
pub const CHI2_1_95: f64 = 3.841_458_820_694_124;

/// The correction rounds stop when every estimate moves by less than this
/// part of its standard error.
pub const ROUND_TOLERANCE: f64 = 0.1;

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
    /// Rounds of the polish and the one-stage fit with the correction: the
    /// anchor moves to each round's estimate until the estimates move by
    /// less than [`ROUND_TOLERANCE`] of their standard errors.
    pub correction_rounds: usize,
    /// Time step of the viscoelastic runs (s), fixed for every parameter.
    pub max_time_step: f64,
    /// Radius of the punch's rounded edge (mm; `Q1Punch::edge_radius`).
    pub edge_radius: f64,
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
            correction_rounds: 3,
            max_time_step: 1.0,
            edge_radius: palpate_fe::q1::DEFAULT_EDGE_RADIUS,
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

    /// The elastic FE model of the fits.
    pub fn elastic_model(&self) -> Q1Punch {
        self.elastic_model_at(self.h_fine)
    }

    /// The viscoelastic FE model of the fits (law, then `g_i, tau_i_s`).
    pub fn viscoelastic_model(&self) -> Q1Punch {
        self.viscoelastic_model_at(self.h_fine)
    }

    /// The elastic FE model with elements of `h` mm under the punch.
    pub fn elastic_model_at(&self, h: f64) -> Q1Punch {
        let mut m = Q1Punch::new(self.law);
        m.edge_radius = self.edge_radius;
        m.grading = Some(Grading {
            h_fine: h,
            fine_length: 3.0,
            growth: 1.0 + h,
        });
        m
    }

    /// The viscoelastic FE model with elements of `h` mm under the punch.
    pub fn viscoelastic_model_at(&self, h: f64) -> Q1Punch {
        let mut m = self.elastic_model_at(h).with_prony_parameters(self.terms);
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
        let d = crate::calibration::TestData::read("Q1", crate::calibration::TestKind::N1, path)?;
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
    pub fit: FitReport,
}

/// One correction of the fit mesh's model to the correcting mesh.
#[derive(Debug, Clone, Serialize)]
pub struct MeshCorrection {
    /// The parameters both meshes ran at.
    pub anchor: Vec<f64>,
    /// The largest |fine / coarse - 1| over the samples.
    pub max_relative_change: f64,
    /// Wall time of the two runs (s).
    pub wall_s: f64,
}

/// A 95 % profile-likelihood interval: `min over the others SSE(x) / sigma^2`
/// within [`CHI2_1_95`] of its minimum. Each side is evaluated at
/// `estimate -/+ 2 SE` (the other parameters refitted by LM from the
/// optimum) and the crossing interpolated linearly in the signed root
/// `sqrt(delta chi2)` from the optimum (exact for a quadratic profile); a
/// side whose first point stays below the threshold is tried at 4 SE, and
/// is `None` (not bounded) if it still does, or if the point leaves the
/// parameter's bounds or fails.
#[derive(Debug, Clone, Serialize)]
pub struct Profile {
    pub param: String,
    pub estimate: f64,
    pub standard_error: Option<f64>,
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    /// (value, delta chi2) evaluated.
    pub points: Vec<(f64, f64)>,
    pub fe_runs: usize,
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
    /// The correcting mesh's element size under the punch (mm), if any.
    pub correcting_mesh_mm: Option<f64>,
    /// Totals of the staged route (stages, polish, without profiles).
    pub staged_fe_runs: usize,
    pub staged_wall_s: f64,
}

/// Progress of the stages (the CLI prints it).
pub type Say<'a> = &'a (dyn Fn(&str) + Sync);

fn lm_fit(
    objective: &Objective,
    start: Vec<f64>,
    options: &TwoStageOptions,
    lm: LmOptions,
) -> anyhow::Result<(FitReport, f64)> {
    let t0 = Instant::now();
    let report = fit(
        objective,
        &FitOptions {
            method: Method::LevenbergMarquardt(lm),
            fd: options.fd,
            start: Some(start),
            ..FitOptions::default()
        },
    )?;
    Ok((report, t0.elapsed().as_secs_f64()))
}

/// The models a stage fits: the fit mesh's, and the correcting mesh's when
/// asked.
struct StageModels {
    coarse: Arc<dyn ForwardModel>,
    fine: Option<Arc<dyn ForwardModel>>,
}

/// What one stage fits.
struct StageData<'a> {
    stage: &'a str,
    name: String,
    loading: Loading,
    observed: Vec<f64>,
    /// Parameters held, by name.
    fixed: Vec<(String, f64)>,
}

/// Runs one stage: LM from `start` (every parameter of the models' space).
/// With a correcting mesh, the fit mesh's model is corrected to it at the
/// start, then (up to `rounds` rounds) at each round's estimate, until the
/// estimates move by less than [`ROUND_TOLERANCE`] of their standard
/// errors. Returns the result and the data set of the last round (the
/// profiles refit it).
fn run_stage(
    data: &StageData<'_>,
    models: &StageModels,
    start: Vec<f64>,
    rounds: usize,
    options: &TwoStageOptions,
    say: Say<'_>,
) -> anyhow::Result<(StageResult, DataSet)> {
    let mut theta = start.clone();
    let (mut fe_runs, mut wall_s) = (0, 0.0);
    let (mut corrections, mut round_iterations) = (Vec::new(), Vec::new());
    let mut last = None;
    for round in 0..rounds.max(1) {
        let model: Arc<dyn ForwardModel> = match &models.fine {
            None => models.coarse.clone(),
            Some(fine) => {
                let t0 = Instant::now();
                let c = FidelityCorrection::at(
                    fine.as_ref(),
                    models.coarse.as_ref(),
                    &theta,
                    &data.loading,
                )
                .map_err(|e| {
                    anyhow::anyhow!(
                        "{}: the correcting mesh's run at {theta:?}: {e}",
                        data.stage
                    )
                })?;
                let w = t0.elapsed().as_secs_f64();
                let (lo, hi) = c
                    .ratio
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &r| {
                        (l.min(r), h.max(r))
                    });
                say(&format!(
                    "  round {}: the fit mesh's force corrected by x {lo:.4} .. {hi:.4} at [{}] ({w:.0} s)",
                    round + 1,
                    theta
                        .iter()
                        .map(|v| format!("{v:.4e}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
                corrections.push(MeshCorrection {
                    anchor: theta.clone(),
                    max_relative_change: c.max_relative_change(),
                    wall_s: w,
                });
                fe_runs += 1;
                wall_s += w;
                Arc::new(CorrectedModel::new(
                    models.coarse.clone(),
                    c,
                    data.loading.clone(),
                    &fine.name(),
                ))
            }
        };
        let set = DataSet::new(
            data.name.clone(),
            model,
            data.loading.clone(),
            data.observed.clone(),
        );
        let objective = Objective::new(vec![set.clone()], ResidualKind::Absolute, &data.fixed)?;
        let (report, w) = lm_fit(&objective, theta.clone(), options, options.lm)?;
        fe_runs += report.evaluations;
        wall_s += w;
        round_iterations.push(report.iterations);
        let settled = round > 0
            && report
                .parameters
                .iter()
                .zip(&theta)
                .filter(|(e, _)| !e.fixed)
                .all(|(e, &old)| match e.standard_error {
                    Some(se) if se > 0.0 => (e.value - old).abs() <= ROUND_TOLERANCE * se,
                    _ => (e.value - old).abs() <= 1e-3 * old.abs(),
                });
        theta = report.parameters.iter().map(|p| p.value).collect();
        let stop = models.fine.is_none() || settled;
        last = Some((objective, report, set));
        if stop {
            break;
        }
    }
    let (objective, report, set) = last.expect("at least one round");
    let result = StageResult {
        stage: data.stage.into(),
        free: objective.free_names(),
        samples: objective.n_residuals(),
        iterations: round_iterations.iter().sum(),
        fe_runs,
        wall_s,
        converged: report.converged,
        termination: report.termination.to_string(),
        // (the round trip through LM's unbounded coordinates moves a value
        // that stayed by round-off)
        moved: theta
            .iter()
            .zip(&start)
            .any(|(a, b)| (a - b).abs() > 1e-9 * b.abs()),
        theta,
        correction: None,
        mesh_corrections: corrections,
        round_iterations,
        fit: report,
    };
    Ok((result, set))
}

/// The elastic force curve of stage 1 scaled by the parameter `s`, at the
/// samples of the record: `s F_e(k)` (the ramp's elastic FE predictions,
/// then the end-of-ramp value through the hold). The base of the
/// force-level QLV of [`ramp_correction`].
struct ScaledCurve {
    fe: Vec<f64>,
    space: palpate_core::ParamSpace,
}

impl ForwardModel for ScaledCurve {
    fn name(&self) -> String {
        "scaled elastic force curve of stage 1".into()
    }
    fn space(&self) -> &palpate_core::ParamSpace {
        &self.space
    }
    fn observable(&self) -> palpate_core::Observable {
        palpate_core::Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn palpate_core::Evaluator + '_> {
        Box::new(ScaledEvaluator(self))
    }
}

struct ScaledEvaluator<'a>(&'a ScaledCurve);

impl palpate_core::Evaluator for ScaledEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), palpate_core::ForwardError> {
        if out.len() != self.0.fe.len() || loading.len() != out.len() {
            return Err(palpate_core::ForwardError::InvalidLoading(
                "the scaled curve answers only for its record".into(),
            ));
        }
        for (o, f) in out.iter_mut().zip(&self.0.fe) {
            *o = theta[0] * f;
        }
        Ok(())
    }
}

/// The relaxation during the ramp lowers the ramp force, so stage 1's
/// elastic fit underestimates the instantaneous moduli. Force-level QLV
/// (`palpate_enrich::Viscoelastic`, Fung's QLV on the force: exact for the
/// punch in the linear range by the correspondence principle) of the stage-1
/// elastic curve `s F_e(t)` is fitted to the whole record by LM in
/// `s, g_i, tau_i` from `s = 1` and the default Prony start; it costs no FE
/// run (the curve is stage 1's). Returns `s` (the factor on the moduli:
/// the force is proportional to them for a law with one modulus, e.g.
/// neo-Hookean, under exact incompressibility) and the Prony terms,
/// increasing in tau, as the start of stage 2. `None` when the record is
/// not a ramp then a hold at constant depth, or the fit fails.
pub fn ramp_correction(
    record: &Q1Record,
    fe_ramp: &[f64],
    terms: usize,
) -> Option<(f64, Vec<f64>)> {
    let k = record.ramp_end();
    if fe_ramp.len() != k + 1 || record.depth[k..].iter().any(|&d| d != record.depth[k]) {
        return None;
    }
    let mut fe = fe_ramp.to_vec();
    fe.resize(record.depth.len(), fe_ramp[k]);
    let base = ScaledCurve {
        fe,
        space: palpate_core::ParamSpace::new(vec![palpate_core::ParamSpec::new(
            "scale",
            "1",
            0.0,
            f64::INFINITY,
            1.0,
        )]),
    };
    let qlv = palpate_enrich::Viscoelastic::new(Box::new(base), terms);
    let set = DataSet::new(
        "ramp correction",
        Arc::new(qlv),
        record.loading(),
        record.force.clone(),
    );
    let objective = Objective::new(vec![set], ResidualKind::Absolute, &[]).ok()?;
    let report = fit(&objective, &FitOptions::default()).ok()?;
    let theta: Vec<f64> = report.parameters.iter().map(|p| p.value).collect();
    let mut pairs: Vec<(f64, f64)> = (0..terms)
        .map(|i| (theta[1 + 2 * i], theta[2 + 2 * i]))
        .collect();
    pairs.sort_by(|a, b| a.1.total_cmp(&b.1));
    let sum: f64 = pairs.iter().map(|p| p.0).sum();
    (report.converged && sum < 1.0 && theta[0] > 0.0).then(|| {
        (
            theta[0],
            pairs.into_iter().flat_map(|(g, t)| [g, t]).collect(),
        )
    })
}

/// Past this depth (mm) a fit mesh coarser than [`DEEP_FIT_MESH`] is stiff
/// under the punch's rounded edge (18 % at 5 mm for 0.3 mm cells, 7 % for
/// 0.15 mm; docs/guide.md).
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
    let whole = |stage, fixed| StageData {
        stage,
        name: record.name.clone(),
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
                let data = StageData {
                    stage,
                    name: format!("{} (ramp)", record.name),
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
    let profiles = if options.profile {
        say("profile-likelihood intervals of the polished parameters");
        profiles(&full, &polish, options)
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
        model: visco.name(),
        names,
        stages,
        profiles,
        one_stage,
        correcting_mesh_mm: options.correct_h,
        staged_fe_runs,
        staged_wall_s,
    })
}

/// The profile of each free parameter of the polish ([`Profile`]).
fn profiles(set: &DataSet, polish: &StageResult, options: &TwoStageOptions) -> Vec<Profile> {
    let report = &polish.fit;
    let n = report.n_residuals as f64;
    let p = report.free.len() as f64;
    let sigma2 = report.sse / (n - p).max(1.0);
    let mut lm = options.lm;
    lm.max_iterations = 5;
    report
        .parameters
        .iter()
        .filter(|e| !e.fixed)
        .map(|e| {
            let mut prof = Profile {
                param: e.name.clone(),
                estimate: e.value,
                standard_error: e.standard_error,
                lower: None,
                upper: None,
                points: Vec::new(),
                fe_runs: 0,
            };
            let Some(se) = e.standard_error.filter(|s| *s > 0.0) else {
                return prof;
            };
            for side in [-1.0, 1.0] {
                let mut end = None;
                for m in [2.0, 4.0] {
                    let x = e.value + side * m * se;
                    if !(x > e.lower && x < e.upper) {
                        break;
                    }
                    let Ok(objective) = Objective::new(
                        vec![set.clone()],
                        ResidualKind::Absolute,
                        &[(e.name.clone(), x)],
                    ) else {
                        break;
                    };
                    let mut start = polish.theta.clone();
                    let k = report
                        .parameters
                        .iter()
                        .position(|q| q.name == e.name)
                        .expect("a parameter of the fit");
                    start[k] = x;
                    let Ok((r, _)) = lm_fit(&objective, start, options, lm) else {
                        break;
                    };
                    prof.fe_runs += r.evaluations;
                    let d = ((r.sse - report.sse) / sigma2).max(0.0);
                    prof.points.push((x, d));
                    if d >= CHI2_1_95 {
                        // linear in sqrt(delta chi2) from 0 at the estimate
                        end = Some(e.value + side * m * se * (CHI2_1_95 / d).sqrt());
                        break;
                    }
                }
                if side < 0.0 {
                    prof.lower = end;
                } else {
                    prof.upper = end;
                }
            }
            prof
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The setters both option builders (CLI, manifest step) share refuse
    /// what they should and keep the old value when they do.
    #[test]
    fn the_setters_check_their_ranges() {
        let mut o = TwoStageOptions::new(Law::NeoHookean);
        o.set_terms(3).unwrap();
        assert_eq!(o.terms, 3);
        assert!(o.set_terms(0).unwrap_err().contains("1 to 4"));
        assert!(o.set_terms(5).is_err());
        assert_eq!(o.terms, 3);
        o.set_fit_mesh(0.15).unwrap();
        for bad in [0.01, 1.5, f64::NAN] {
            assert!(o.set_fit_mesh(bad).unwrap_err().contains("0.02..1 mm"));
        }
        assert_eq!(o.h_fine, 0.15);
        o.set_time_step(0.5).unwrap();
        for bad in [0.0, -1.0, f64::INFINITY] {
            assert!(o.set_time_step(bad).unwrap_err().contains("positive"));
        }
        assert_eq!(o.max_time_step, 0.5);
        // the correcting mesh: in range and finer than the fit mesh (0.15)
        for bad in [0.01, 0.15, 0.2] {
            assert!(o.set_correct_mesh(bad).is_err(), "{bad}");
        }
        assert!(o.set_correct_mesh(0.2).unwrap_err().contains("finer"));
        assert_eq!(o.correct_h, None);
        o.set_correct_mesh(0.1).unwrap();
        assert_eq!(o.correct_h, Some(0.1));
    }

    /// A deep record on the default fit mesh gets the note; a shallow one,
    /// a corrected fit or a fine fit mesh do not.
    #[test]
    fn a_deep_record_is_told_of_the_correcting_mesh() {
        let rec = |depth: f64| {
            Q1Record::new(
                "r",
                vec![0.0, 0.5, 10.0],
                vec![0.0, depth, depth],
                vec![0.0, 0.1, 0.05],
            )
            .unwrap()
        };
        let mut o = TwoStageOptions::new(Law::NeoHookean);
        let note = deep_record_note(&rec(5.0), &o).expect("a note at 5 mm");
        assert!(
            note.contains("5 mm") && note.contains("--correct-mesh"),
            "{note}"
        );
        assert!(deep_record_note(&rec(1.0), &o).is_none());
        o.set_correct_mesh(0.1).unwrap();
        assert!(deep_record_note(&rec(5.0), &o).is_none());
        let mut fine = TwoStageOptions::new(Law::NeoHookean);
        fine.set_fit_mesh(0.1).unwrap();
        assert!(deep_record_note(&rec(5.0), &fine).is_none());
    }

    #[test]
    fn the_edge_radius_reaches_both_fit_models() {
        let mut o = TwoStageOptions::new(Law::NeoHookean);
        assert_eq!(
            o.elastic_model().edge_radius,
            palpate_fe::q1::DEFAULT_EDGE_RADIUS
        );
        o.set_edge_radius(1.0).unwrap();
        assert_eq!(o.elastic_model().edge_radius, 1.0);
        assert_eq!(o.viscoelastic_model().edge_radius, 1.0);
        for bad in [0.0, -1.0, 2.0, f64::NAN] {
            assert!(o.set_edge_radius(bad).is_err(), "{bad}");
            assert_eq!(o.edge_radius, 1.0);
        }
    }
}
