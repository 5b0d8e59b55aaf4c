//! Fitting a model to the whole record or to the record with a window left out, through
//! palpate-inverse (Levenberg-Marquardt in the unbounded parameter space),
//! from several starting points.

use super::GapError;
use palpate_core::{
    Evaluator, ForwardError, ForwardModel, Loading, Observable, Output, ParamSpace, ParamSpec,
};
use palpate_inverse::{
    fit, DataSet, FdOptions, FitOptions, FitReport, LmOptions, Method, Objective, ResidualKind,
};
use std::sync::Arc;

/// A fitted model.
#[derive(Debug, Clone)]
pub(crate) struct Fitted {
    /// Physical parameters at the optimum.
    pub theta: Vec<f64>,
    /// Sum of squared residuals over the fitted samples.
    pub sse: f64,
    /// Predictions over the whole loading history (fitted and held-out samples).
    pub predicted: Vec<f64>,
    /// The inverse crate's report (standard errors, correlations, identifiability).
    pub report: FitReport,
}

/// A model seen through a subset of the samples of one fixed history: it
/// always simulates the whole `full` history (so history-dependent models
/// such as QLV stay exact) and returns only the samples `keep`. This lets the
/// calibration fit a record with a window left out (blocked
/// cross-validation); the loading handed to its evaluator only sets the
/// output length.
struct Masked {
    inner: Arc<dyn ForwardModel>,
    full: Loading,
    keep: Vec<usize>,
}

struct MaskedEvaluator<'a> {
    model: &'a Masked,
    inner: Box<dyn Evaluator + 'a>,
    buffer: Vec<f64>,
}

impl Evaluator for MaskedEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        _loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        self.buffer.resize(m.full.len(), 0.0);
        self.inner.predict_into(theta, &m.full, &mut self.buffer)?;
        for (o, &k) in out.iter_mut().zip(&m.keep) {
            *o = self.buffer[k];
        }
        Ok(())
    }
}

impl ForwardModel for Masked {
    fn name(&self) -> String {
        self.inner.name()
    }
    fn space(&self) -> &ParamSpace {
        self.inner.space()
    }
    fn observable(&self) -> Observable {
        self.inner.observable()
    }
    /// The first of the inner model's outputs: the diagnosis fits that one.
    fn outputs(&self) -> Vec<Output> {
        self.inner.outputs().into_iter().take(1).collect()
    }
    fn expensive(&self) -> bool {
        self.inner.expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(MaskedEvaluator {
            model: self,
            inner: self.inner.evaluator(),
            buffer: Vec::new(),
        })
    }
}

/// Levenberg-Marquardt settings of the diagnosis: tolerances far below what
/// the statistics resolve (a likelihood ratio of 1 is a relative SSE change
/// of about 1/n), and a budget that stops the fits of degenerate
/// enrichments (e.g. a Prony term drifting to tau -> 0 in noise) early.
/// For an expensive model (finite elements, seconds per prediction) the
/// budget is smaller and the tolerances looser: the statistics resolve a
/// likelihood-ratio change of about 1, i.e. a change of SSE of sigma^2,
/// a relative change of ~1/n (SSE ~ n sigma^2). ftol = 1e-4 stops when the
/// predicted and actual reductions are below 1e-4 SSE, 0.004 sigma^2 at
/// n = 40: a hundredth of what any test resolves. (1e-6 before: on a
/// friction fit whose response saturates, the last ten iterations, twenty
/// FE solves, moved the SSE by less than 0.01 sigma^2.)
///
/// For a cheap model ftol = 1e-8 (4e-6 sigma^2 at n = 400) and at most 400
/// evaluations or 50 iterations per run. The budget bounds what one run
/// costs: the calibration's polish of a parameter near its bound (an
/// effect fitted to "off", C20 or D1 at 0) refits from the optimum until a
/// refit gains under 1e-9 of the SSE, up to twenty times, and a run that
/// creeps along a flat valley (a Prony term whose weight goes to 0 leaves
/// its time constant free) spent the whole budget in each. Measured on the
/// two-effect C1 records (`bench_gap_sets`): 1e-10 and 1500 evaluations
/// took 12 s of CPU per diagnosis, up to 55 s, every verdict the same.
/// The wall slide that continues a run blocked by parameters the model
/// refuses (palpate-inverse) is held to the same budget.
fn gap_lm_options(expensive: bool) -> LmOptions {
    if expensive {
        LmOptions {
            ftol: 1e-4,
            xtol: 1e-5,
            gtol: 1e-8,
            max_evaluations: 120,
            max_iterations: 20,
            ..LmOptions::default()
        }
    } else {
        LmOptions {
            ftol: 1e-8,
            xtol: 1e-7,
            gtol: 1e-10,
            max_evaluations: 400,
            max_iterations: 50,
            ..LmOptions::default()
        }
    }
}

/// The least-squares factor a = <f, y> / <f, f> of predictions `f` against
/// data `y`, and `theta` with every parameter in MPa multiplied by it: the
/// best refit of the moduli alone (exact for a strain energy linear in its
/// moduli under prescribed displacement, e.g. neo-Hookean, whose force is
/// then linear in C10). `None` when a is not a positive finite number.
pub(crate) fn scale_moduli(
    specs: &[ParamSpec],
    theta: &[f64],
    f: &[f64],
    y: &[f64],
) -> Option<(f64, Vec<f64>)> {
    let ff: f64 = f.iter().map(|v| v * v).sum();
    let fy: f64 = f.iter().zip(y).map(|(a, b)| a * b).sum();
    let a = fy / ff;
    (a.is_finite() && a > 0.0).then(|| {
        let scaled = specs
            .iter()
            .zip(theta)
            .map(|(s, v)| if s.is_modulus() { v * a } else { *v })
            .collect();
        (a, scaled)
    })
}

/// `x` moved strictly inside the bounds of `spec` (the unbounded transforms
/// send a bound to infinity): a value on or beyond a bound moves a tenth of
/// the way towards the starting value, or by a small relative step.
pub(crate) fn interior(spec: &ParamSpec, x: f64) -> f64 {
    let mut v = if x.is_finite() { x } else { spec.initial };
    if spec.lower.is_finite() && v <= spec.lower {
        let gap = (spec.initial - spec.lower).abs();
        v = spec.lower
            + if gap > 0.0 {
                0.1 * gap
            } else {
                1e-6 * spec.lower.abs().max(1.0)
            };
    }
    if spec.upper.is_finite() && v >= spec.upper {
        let gap = (spec.upper - spec.initial).abs();
        v = spec.upper
            - if gap > 0.0 {
                0.1 * gap
            } else {
                1e-6 * spec.upper.abs().max(1.0)
            };
    }
    v
}

/// Fits `model` to the samples `keep` of the record (all when `None`) from
/// each start (moved inside the bounds; parameters in `fixed` held at their
/// values) and keeps the lowest SSE; `expensive` selects the smaller budget
/// of [`gap_lm_options`]. Starts whose fit fails are skipped; the
/// error of the first is returned when all fail. Predictions cover the whole
/// record.
pub(crate) fn fit_from_starts(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    keep: Option<&[usize]>,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
    expensive: bool,
) -> Result<Fitted, GapError> {
    fit_with_budget(
        model, loading, observed, keep, starts, fixed, expensive, None,
    )
}

/// [`fit_from_starts`] with at most `iterations` Levenberg-Marquardt
/// iterations per start when given; `Some(0)`: no iteration, only the
/// statistics at the start (standard errors, correlations,
/// identifiability), for a start that is already an optimum (of a
/// projected line search).
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_with_budget(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    keep: Option<&[usize]>,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
    expensive: bool,
    iterations: Option<u64>,
) -> Result<Fitted, GapError> {
    // An exact refit of a cheap model with samples left out (the `refit`
    // cross-validation, and contiguous blocks) keeps the tight settings it
    // was defined with: it is the reference the linearised folds are
    // measured against.
    let lm = if keep.is_some() && !expensive {
        LmOptions {
            ftol: 1e-10,
            xtol: 1e-9,
            gtol: 1e-10,
            max_evaluations: 1500,
            max_iterations: 200,
            ..LmOptions::default()
        }
    } else {
        gap_lm_options(expensive)
    };
    fit_with(
        model, loading, observed, keep, starts, fixed, expensive, iterations, lm,
    )
}

/// The refit of a cheap model to the samples `keep` with the settings of a
/// whole-record fit ([`gap_lm_options`]): for a fold of the linearised
/// cross-validation whose chord iterations did not settle. From the
/// whole-record optimum, a refit resolves the held-out predictions to far
/// below the noise with these settings; the tight ones of
/// [`fit_with_budget`] cost up to 2,000 evaluations per fold on a
/// compressible law with relaxation for no change of a verdict.
pub(crate) fn refit_kept(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    keep: &[usize],
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
) -> Result<Fitted, GapError> {
    fit_with(
        model,
        loading,
        observed,
        Some(keep),
        starts,
        fixed,
        false,
        None,
        gap_lm_options(false),
    )
}

/// [`fit_with_budget`] with the Levenberg-Marquardt settings `lm`.
#[allow(clippy::too_many_arguments)]
fn fit_with(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    keep: Option<&[usize]>,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
    expensive: bool,
    iterations: Option<u64>,
    lm: LmOptions,
) -> Result<Fitted, GapError> {
    let set = match keep {
        None => DataSet::new("data", model.clone(), loading.clone(), observed.to_vec()),
        Some(keep) => {
            let masked: Arc<dyn ForwardModel> = Arc::new(Masked {
                inner: model.clone(),
                full: loading.clone(),
                keep: keep.to_vec(),
            });
            let drive = keep.iter().map(|&k| loading.drive[k]).collect();
            let y = keep.iter().map(|&k| observed[k]).collect();
            DataSet::new(
                "data (window left out)",
                masked,
                Loading::quasi_static(loading.drive_kind, drive),
                y,
            )
        }
    };
    let objective = Objective::new(vec![set], ResidualKind::Absolute, fixed).map_err(|source| {
        GapError::Fit {
            model: model.name(),
            source,
        }
    })?;
    let mut best: Option<FitReport> = None;
    let mut first_error = None;
    for start in starts {
        let start: Vec<f64> = model
            .space()
            .params
            .iter()
            .zip(start)
            .map(
                |(p, &x)| match fixed.iter().find(|(name, _)| *name == p.name) {
                    Some((_, v)) => *v,
                    None => interior(p, x),
                },
            )
            .collect();
        let mut lm = lm;
        if let Some(k) = iterations {
            lm.max_iterations = lm.max_iterations.min(k);
        }
        let mut options = FitOptions {
            start: Some(start),
            method: Method::LevenbergMarquardt(lm),
            ..FitOptions::default()
        };
        if expensive {
            // Forward differences (one prediction per column instead of
            // two) with a step above the nonlinear solver's tolerance.
            options.fd = FdOptions {
                relative_step: 1e-5,
                central: false,
                parallel: true,
            };
        }
        let outcome = if iterations == Some(0) {
            // statistics at the start, no iteration (the start is already
            // an optimum, e.g. of a projected line search)
            objective
                .unbounded_from_theta(options.start.as_deref().unwrap_or(&[]))
                .and_then(|z| palpate_inverse::fit::statistics(&objective, &z, &options.fd))
                .map(|mut r| {
                    r.converged = true;
                    r
                })
        } else {
            fit(&objective, &options)
        };
        match outcome {
            Ok(report) => {
                if report.sse.is_finite() && best.as_ref().is_none_or(|b| report.sse < b.sse) {
                    best = Some(report);
                }
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    let report = match (best, first_error) {
        (Some(r), _) => r,
        (None, Some(source)) => {
            return Err(GapError::Fit {
                model: model.name(),
                source,
            })
        }
        (None, None) => {
            return Err(GapError::InvalidOption {
                option: "starts",
                reason: "no starting point".into(),
            })
        }
    };
    let theta = report.theta();
    // On the whole record the fit's own predictions at the optimum are the
    // record's (one model evaluation saved per fit); with samples left out
    // the left-out ones need a prediction.
    let predicted = match (keep, report.sets.first()) {
        (None, Some(set)) if set.predicted.len() == observed.len() => set.predicted.clone(),
        _ => model.predict(&theta, loading)?,
    };
    let sse = match keep {
        None => predicted
            .iter()
            .zip(observed)
            .map(|(p, y)| (y - p).powi(2))
            .sum(),
        Some(keep) => keep
            .iter()
            .map(|&k| (observed[k] - predicted[k]).powi(2))
            .sum(),
    };
    Ok(Fitted {
        theta,
        sse,
        predicted,
        report,
    })
}
