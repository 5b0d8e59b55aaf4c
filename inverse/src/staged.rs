//! Staged identification, generic over the forward trait: each stage is a
//! Levenberg-Marquardt fit of a subset of the parameters (the others held
//! by name, or a model of fewer parameters), optionally on a cheap model
//! corrected to an accurate one by output space mapping in rounds, and an
//! estimate checked on a third model (another discretisation).
//!
//! * **Correction rounds** ([`run_stage`]): with an accurate model, the
//!   cheap model is corrected to it sample by sample at an anchor
//!   ([`FidelityCorrection`], theory.md 5.9), LM fits the corrected model,
//!   and the anchor moves to the estimate, until every free estimate moves
//!   by less than [`ROUND_TOLERANCE`] of its standard error (or the rounds
//!   run out: the stage is then not [`StageOutcome::settled`]). The fixed
//!   point is the accurate model's optimum as seen through the cheap
//!   model's sensitivities (Bandler et al. 2004, *IEEE Trans. Microw. Theory
//!   Tech.* 52, 337-361, output space mapping).
//! * **Estimate check** ([`check_estimate`]): the same rounds from an
//!   estimate with the cheap model corrected to a check model instead; the
//!   shift of the estimates, in their standard errors ([`Shift`]), is the
//!   discretisation's share of the error, which the standard errors (noise
//!   only) do not hold.
//!
//! Nothing here prints: each correction is handed to the caller's
//! `on_round` ([`Round`]). The recipe (which stages, which models, what
//! runs between stages) is the caller's: `palpate-studies`'
//! `apps::two_stage` is the one for a Q1 ramp-and-hold record.

use crate::{
    fit, CorrectedModel, DataSet, FdOptions, FidelityCorrection, FitOptions, FitReport,
    InverseError, LmOptions, Method, Objective, ResidualKind,
};
use palpate_core::{ForwardModel, Loading};
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// The correction rounds stop when every free estimate moves by less than
/// this part of its standard error.
pub const ROUND_TOLERANCE: f64 = 0.1;

/// The models a stage fits: the cheap one, and the accurate one it is
/// corrected to (`None`: the cheap one alone). They share one parameter
/// space.
#[derive(Clone)]
pub struct StageModels {
    pub coarse: Arc<dyn ForwardModel>,
    pub fine: Option<Arc<dyn ForwardModel>>,
}

/// What one stage fits.
#[derive(Debug, Clone)]
pub struct Stage {
    /// The stage's name (`elastic`, `polish`, ...).
    pub stage: String,
    /// The data set's name.
    pub set: String,
    pub loading: Loading,
    pub observed: Vec<f64>,
    /// Parameters held, by name (the others are free).
    pub fixed: Vec<(String, f64)>,
}

/// LM settings of every stage.
#[derive(Debug, Clone, Copy)]
pub struct StageOptions {
    pub lm: LmOptions,
    pub fd: FdOptions,
}

/// One correction of the cheap model to the accurate one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshCorrection {
    /// The parameters both models ran at.
    pub anchor: Vec<f64>,
    /// The largest |fine / coarse - 1| over the samples.
    pub max_relative_change: f64,
    /// Wall time of the two runs (s).
    pub wall_s: f64,
}

/// A correction as it is made, for the caller's progress.
#[derive(Debug, Clone, Copy)]
pub struct Round<'a> {
    /// From 0.
    pub round: usize,
    pub anchor: &'a [f64],
    /// Smallest and largest ratio accurate / cheap over the samples.
    pub ratio_range: (f64, f64),
    pub wall_s: f64,
}

/// One stage's result.
#[derive(Clone)]
pub struct StageOutcome {
    /// Free parameters.
    pub free: Vec<String>,
    /// Residuals fitted.
    pub samples: usize,
    /// LM iterations over the rounds.
    pub iterations: u64,
    /// Model runs: objective evaluations (finite-difference ones
    /// included) and one accurate-model run per correction.
    pub runs: usize,
    pub wall_s: f64,
    pub converged: bool,
    pub termination: String,
    /// Every parameter at the end (held ones at their values).
    pub theta: Vec<f64>,
    /// The corrections, one per round (empty without an accurate model).
    pub corrections: Vec<MeshCorrection>,
    /// LM iterations of each round.
    pub round_iterations: Vec<u64>,
    /// Whether LM accepted any step (`false`: every round ended where it
    /// started).
    pub moved: bool,
    /// Whether the last round's estimate stayed within [`ROUND_TOLERANCE`]
    /// SE of its anchor (true for a stage corrected once or not at all).
    pub settled: bool,
    /// The largest move of the last round in standard errors (0 without
    /// correction rounds).
    pub last_round_move_se: f64,
    /// The last round's fit.
    pub fit: FitReport,
    /// The last round's data set (on the corrected model): profiles and
    /// other refits start from it.
    pub set: DataSet,
}

/// LM on `objective` from `start`; the report and the wall time (s).
pub fn lm_fit(
    objective: &Objective,
    start: Vec<f64>,
    lm: LmOptions,
    fd: FdOptions,
) -> Result<(FitReport, f64), InverseError> {
    let t0 = Instant::now();
    let report = fit(
        objective,
        &FitOptions {
            method: Method::LevenbergMarquardt(lm),
            fd,
            start: Some(start),
            ..FitOptions::default()
        },
    )?;
    Ok((report, t0.elapsed().as_secs_f64()))
}

/// Runs one stage: LM from `start` (every parameter of the models' space).
/// With an accurate model, the cheap one is corrected to it at `start`,
/// then (up to `rounds` rounds) at each round's estimate, until the free
/// estimates move by less than [`ROUND_TOLERANCE`] of their standard
/// errors (module docs). `on_round` sees each correction.
pub fn run_stage(
    stage: &Stage,
    models: &StageModels,
    start: Vec<f64>,
    rounds: usize,
    options: &StageOptions,
    on_round: &mut dyn FnMut(&Round<'_>),
) -> Result<StageOutcome, InverseError> {
    let mut theta = start.clone();
    let (mut runs, mut wall_s) = (0, 0.0);
    let (mut corrections, mut round_iterations) = (Vec::new(), Vec::new());
    let mut last = None;
    let (mut settled, mut last_move) = (true, 0.0f64);
    for round in 0..rounds.max(1) {
        let model: Arc<dyn ForwardModel> = match &models.fine {
            None => models.coarse.clone(),
            Some(fine) => {
                let t0 = Instant::now();
                let c = FidelityCorrection::at(
                    fine.as_ref(),
                    models.coarse.as_ref(),
                    &theta,
                    &stage.loading,
                )
                .map_err(|e| InverseError::Forward {
                    set: stage.set.clone(),
                    theta: theta.clone(),
                    stage: "correction to the accurate model",
                    source: Box::new(e),
                })?;
                let w = t0.elapsed().as_secs_f64();
                let ratio_range = c
                    .ratio
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &r| {
                        (l.min(r), h.max(r))
                    });
                on_round(&Round {
                    round,
                    anchor: &theta,
                    ratio_range,
                    wall_s: w,
                });
                corrections.push(MeshCorrection {
                    anchor: theta.clone(),
                    max_relative_change: c.max_relative_change(),
                    wall_s: w,
                });
                runs += 1;
                wall_s += w;
                Arc::new(CorrectedModel::new(
                    models.coarse.clone(),
                    c,
                    stage.loading.clone(),
                    &fine.name(),
                ))
            }
        };
        let set = DataSet::new(
            stage.set.clone(),
            model,
            stage.loading.clone(),
            stage.observed.clone(),
        );
        let objective = Objective::new(vec![set.clone()], ResidualKind::Absolute, &stage.fixed)?;
        let (report, w) = lm_fit(&objective, theta.clone(), options.lm, options.fd)?;
        runs += report.evaluations;
        wall_s += w;
        round_iterations.push(report.iterations);
        // the move of each free estimate from the anchor, in its SE (or, with
        // no SE, in 1e-3 of the value, against the tolerance's scale)
        last_move = report
            .parameters
            .iter()
            .zip(&theta)
            .filter(|(e, _)| !e.fixed)
            .map(|(e, &old)| match e.standard_error {
                Some(se) if se > 0.0 => (e.value - old).abs() / se,
                _ => (e.value - old).abs() / (1e-3 * old.abs()) * ROUND_TOLERANCE,
            })
            .fold(0.0, f64::max);
        settled = models.fine.is_none() || rounds <= 1 || last_move <= ROUND_TOLERANCE;
        theta = report.parameters.iter().map(|p| p.value).collect();
        let stop = models.fine.is_none() || (round > 0 && settled);
        last = Some((objective, report, set));
        if stop {
            break;
        }
    }
    let Some((objective, report, set)) = last else {
        unreachable!("the loop runs at least one round")
    };
    Ok(StageOutcome {
        free: objective.free_names(),
        samples: objective.n_residuals(),
        iterations: round_iterations.iter().sum(),
        runs,
        wall_s,
        converged: report.converged,
        termination: report.termination.to_string(),
        // (the round trip through LM's unbounded coordinates moves a value
        // that stayed by round-off)
        moved: theta
            .iter()
            .zip(&start)
            .any(|(a, b)| (a - b).abs() > 1e-9 * b.abs()),
        settled,
        last_round_move_se: if models.fine.is_some() && rounds > 1 {
            last_move
        } else {
            0.0
        },
        theta,
        corrections,
        round_iterations,
        fit: report,
        set,
    })
}

/// The shift of an estimate from a reference estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct Shift {
    /// The estimate.
    pub theta: Vec<f64>,
    /// Estimate minus reference.
    pub shift: Vec<f64>,
    /// The shift in the reference's standard errors (`None` where it has
    /// none or a zero one).
    pub shift_se: Vec<Option<f64>>,
}

impl Shift {
    /// The shift of `theta` from `reference`, whose standard errors are `se`.
    pub fn new(theta: &[f64], reference: &[f64], se: &[Option<f64>]) -> Shift {
        let shift: Vec<f64> = theta.iter().zip(reference).map(|(c, p)| c - p).collect();
        let shift_se = se
            .iter()
            .zip(&shift)
            .map(|(s, d)| s.filter(|s| *s > 0.0).map(|s| d / s))
            .collect();
        Shift {
            theta: theta.to_vec(),
            shift,
            shift_se,
        }
    }
}

/// The check of an estimate `theta` (standard errors `se`) of `stage` on
/// another model: `models.coarse` (the model the estimate was fitted on)
/// corrected to `models.fine` (the check model), from `theta`, in up to
/// `rounds` rounds ([`run_stage`]). Returns the rounds' outcome and the
/// estimates' shift.
pub fn check_estimate(
    stage: &Stage,
    models: &StageModels,
    theta: &[f64],
    se: &[Option<f64>],
    rounds: usize,
    options: &StageOptions,
    on_round: &mut dyn FnMut(&Round<'_>),
) -> Result<(StageOutcome, Shift), InverseError> {
    if models.fine.is_none() {
        return Err(InverseError::InvalidOption {
            option: "check model",
            reason: "an estimate check needs the model to check on".into(),
        });
    }
    let outcome = run_stage(stage, models, theta.to_vec(), rounds, options, on_round)?;
    let shift = Shift::new(&outcome.theta, theta, se);
    Ok((outcome, shift))
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_core::{Drive, Evaluator, ForwardError, Observable, ParamSpace, ParamSpec};

    /// f = a d + b d^2, times `bias` (1 + `skew` d) for a cheap model.
    struct Quad {
        space: ParamSpace,
        bias: f64,
        skew: f64,
    }
    struct Eval(f64, f64);
    impl Evaluator for Eval {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            o: &mut [f64],
        ) -> Result<(), ForwardError> {
            for (o, d) in o.iter_mut().zip(&l.drive) {
                *o = (t[0] * d + t[1] * d * d) * self.0 * (1.0 + self.1 * d);
            }
            Ok(())
        }
    }
    impl ForwardModel for Quad {
        fn name(&self) -> String {
            format!("quad x {}", self.bias)
        }
        fn space(&self) -> &ParamSpace {
            &self.space
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(Eval(self.bias, self.skew))
        }
    }

    fn quad(bias: f64, skew: f64) -> Arc<dyn ForwardModel> {
        Arc::new(Quad {
            space: ParamSpace::new(vec![
                ParamSpec::new("a", "N/mm", 0.0, 10.0, 1.0),
                ParamSpec::new("b", "N/mm2", 0.0, 10.0, 1.0),
            ]),
            bias,
            skew,
        })
    }

    fn options() -> StageOptions {
        StageOptions {
            lm: LmOptions {
                ftol: 1e-12,
                xtol: 1e-12,
                ..LmOptions::default()
            },
            fd: FdOptions {
                relative_step: 1e-6,
                central: true,
                parallel: false,
            },
        }
    }

    fn stage(fixed: Vec<(String, f64)>) -> Stage {
        let d: Vec<f64> = (1..=20).map(|k| 0.1 * k as f64).collect();
        let loading = Loading::quasi_static(Drive::DisplacementMm, d.clone());
        // data of the accurate model at a = 2, b = 0.5, with a small wiggle
        // (the noise: standard errors > 0)
        let observed = d
            .iter()
            .enumerate()
            .map(|(i, d)| 2.0 * d + 0.5 * d * d + 1e-3 * (i as f64 * 1.7).sin())
            .collect();
        Stage {
            stage: "test".into(),
            set: "quad".into(),
            loading,
            observed,
            fixed,
        }
    }

    /// A held parameter stays; the free one is fitted.
    #[test]
    fn a_stage_fits_its_subset() {
        let models = StageModels {
            coarse: quad(1.0, 0.0),
            fine: None,
        };
        let out = run_stage(
            &stage(vec![("b".into(), 0.5)]),
            &models,
            vec![1.0, 0.5],
            3,
            &options(),
            &mut |_| panic!("no correction without an accurate model"),
        )
        .unwrap();
        assert_eq!(out.free, ["a"]);
        assert_eq!(out.theta[1], 0.5);
        assert!((out.theta[0] - 2.0).abs() < 1e-2, "{:?}", out.theta);
        assert!(out.settled && out.moved && out.corrections.is_empty());
        assert_eq!(out.round_iterations.len(), 1);
    }

    /// With a biased cheap model the rounds reach the accurate model's
    /// optimum (the cheap one's sensitivities have the same shape up to a
    /// skew): the estimate matches a fit of the accurate model itself to
    /// well within a standard error, and the rounds settle.
    #[test]
    fn correction_rounds_reach_the_accurate_models_optimum() {
        let s = stage(Vec::new());
        let fine = quad(1.0, 0.0);
        let direct = run_stage(
            &s,
            &StageModels {
                coarse: fine.clone(),
                fine: None,
            },
            vec![1.0, 1.0],
            1,
            &options(),
            &mut |_| {},
        )
        .unwrap();
        let models = StageModels {
            coarse: quad(1.1, 0.02),
            fine: Some(fine),
        };
        let mut seen = Vec::new();
        let out = run_stage(&s, &models, vec![1.0, 1.0], 8, &options(), &mut |r| {
            seen.push((r.round, r.ratio_range))
        })
        .unwrap();
        assert!(out.settled, "{:?}", out.last_round_move_se);
        assert_eq!(out.corrections.len(), seen.len());
        assert!(seen.len() >= 2 && seen[0].0 == 0, "{seen:?}");
        // the first correction was made at the start, where the cheap model
        // is 10-14 % high
        assert!(
            seen[0].1 .0 < 1.0 / 1.09 && seen[0].1 .1 > 1.0 / 1.15,
            "{seen:?}"
        );
        // one accurate run per correction, and every round's LM runs
        assert!(out.runs > out.corrections.len() + out.fit.evaluations);
        for (k, p) in direct.fit.parameters.iter().enumerate() {
            let se = p.standard_error.unwrap();
            assert!(
                (out.theta[k] - p.value).abs() < 0.1 * se,
                "{k}: {} vs {} (SE {se})",
                out.theta[k],
                p.value
            );
        }
        // checked on the accurate model itself from the direct estimate:
        // no shift to speak of
        let se: Vec<Option<f64>> = direct
            .fit
            .parameters
            .iter()
            .map(|p| p.standard_error)
            .collect();
        let (_, shift) =
            check_estimate(&s, &models, &direct.theta, &se, 8, &options(), &mut |_| {}).unwrap();
        for v in shift.shift_se {
            assert!(v.unwrap().abs() < 0.1, "{v:?}");
        }
    }

    #[test]
    fn shift_is_read_in_standard_errors() {
        let s = Shift::new(
            &[1.0, 2.5, 3.0],
            &[1.5, 2.0, 3.0],
            &[Some(0.25), None, Some(0.0)],
        );
        assert_eq!(s.shift, [-0.5, 0.5, 0.0]);
        assert_eq!(s.shift_se, [Some(-2.0), None, None]);
    }
}
