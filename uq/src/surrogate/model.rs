//! The surrogate: parameters -> every output of a forward model on one
//! loading history, by a reduced basis of the output curves and one Gaussian
//! process per basis coefficient.
//!
//! Training: n model runs at the Halton points of the box (in parallel, one
//! evaluator per rayon thread). Each run's outputs, samples x outputs
//! row-major, form a row y_i of the snapshot matrix Y (n x m). With the mean
//! row ybar, the thin SVD Y - 1 ybar = U S V^T gives the proper orthogonal
//! decomposition (principal components) of the curves; the first K right
//! singular vectors v_k, K the smallest with
//!
//!   sum_{k > K} s_k^2 <= tol^2 sum_k s_k^2,
//!
//! span them to the relative tolerance tol (Holmes, Lumley & Berkooz 1996,
//! *Turbulence, Coherent Structures, Dynamical Systems and Symmetry*, ch. 3).
//! The coefficients c_ik = (U S)_ik are each fitted by a GP on the unit cube
//! ([`super::gp::Gp`]), so the prediction is
//!
//!   y(theta) = ybar + sum_k c_k(u(theta)) v_k,
//!
//! O(K (n d + m)) per evaluation instead of a finite-element solve. A basis
//! per curve rather than one GP per sample lets each coefficient have its
//! own length scales (the peak force depends on the stiffness, the curve's
//! shape on the nonlinearity).
//!
//! Error: held-out runs at the next Halton points, never used in training,
//! give the error e_ij = y_surrogate - y_model at every sample and output;
//! reported as max and RMS of |e| relative to each run's peak |output|
//! ([`Validation`]), and as the per-sample second moment
//! `error_variance[j] = mean_i e_ij^2`, which the likelihood adds to the
//! noise variance ([`crate::likelihood::Posterior::with_model_error`]).

use super::design::ParamBox;
use super::gp::Gp;
use super::SurrogateError;
use nalgebra::{DMatrix, DVector};
use palpate_core::{
    Evaluator, ForwardError, ForwardModel, Loading, Observable, Output, ParamSpace,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::time::Instant;

/// Version of the stored form; a change makes old cache files miss.
pub const SURROGATE_FORMAT: u32 = 1;

/// How a surrogate is trained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurrogateOptions {
    /// Model runs in the training design (Halton points 0..n).
    pub training_runs: usize,
    /// Held-out model runs for the error (the next Halton points).
    pub validation_runs: usize,
    /// Relative tolerance of the reduced basis (energy of the curves left out).
    pub basis_tolerance: f64,
}

impl Default for SurrogateOptions {
    fn default() -> Self {
        SurrogateOptions {
            training_runs: 40,
            validation_runs: 10,
            basis_tolerance: 1e-5,
        }
    }
}

impl SurrogateOptions {
    /// The defaults scaled to `d` parameters: max(30, 15 d) training runs,
    /// max(8, 3 d) held-out runs.
    pub fn for_dimension(d: usize) -> Self {
        SurrogateOptions {
            training_runs: (15 * d).max(30),
            validation_runs: (3 * d).max(8),
            ..Default::default()
        }
    }
}

/// What defines a surrogate: the model, the loading, the box, the options,
/// and `description`, a caller's canonical text of everything else that
/// changes the model's answers (its spec, mesh, code version). Its SHA-256
/// ([`SurrogateRequest::key`]) names the cache entry.
pub struct SurrogateRequest<'a> {
    pub model: &'a dyn ForwardModel,
    pub loading: &'a Loading,
    pub bounds: ParamBox,
    pub options: SurrogateOptions,
    pub description: String,
}

impl SurrogateRequest<'_> {
    /// SHA-256 (hex) of the format version, `description`, the model's name
    /// and outputs, the loading, the box and the options.
    pub fn key(&self) -> String {
        let text = serde_json::json!({
            "format": SURROGATE_FORMAT,
            "description": self.description,
            "model": self.model.name(),
            "outputs": self.model.outputs(),
            "loading": self.loading,
            "bounds": self.bounds,
            "options": self.options,
        })
        .to_string();
        Sha256::digest(text.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }
}

/// The surrogate's error on held-out model runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Validation {
    /// Held-out runs that converged and were compared.
    pub points: usize,
    /// Max over runs, samples and outputs of |surrogate - model| / (the
    /// run's peak |output|).
    pub max_relative_error: f64,
    /// RMS of the same relative errors.
    pub rms_relative_error: f64,
    /// Max |surrogate - model| in the output's unit (per output).
    pub max_abs_error: Vec<f64>,
    /// Mean squared error per sample and output (samples x outputs,
    /// row-major), in the output's unit squared: the variance the likelihood
    /// adds.
    pub error_variance: Vec<f64>,
}

/// A model run of the design that failed (left out of training or
/// validation), with the model's reason.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedRun {
    pub theta: Vec<f64>,
    pub reason: String,
}

/// A trained surrogate. Serialisable: the cache stores it as JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Surrogate {
    format: u32,
    key: String,
    model_name: String,
    observable: Observable,
    outputs: Vec<Output>,
    bounds: ParamBox,
    space: ParamSpace,
    loading: Loading,
    options: SurrogateOptions,
    mean: Vec<f64>,
    basis: Vec<Vec<f64>>,
    gps: Vec<Gp>,
    /// Per output, the coefficients of a quadratic trend in the unit-cube
    /// parameters ([`quadratic_terms`]) added to `mean` (the per-output
    /// form, [`fit_per_output`]); empty otherwise.
    #[serde(default)]
    trends: Vec<Vec<f64>>,
    validation: Validation,
    /// Model runs that converged: training + validation.
    pub fe_runs: usize,
    /// Runs that failed (not used).
    pub failed: Vec<FailedRun>,
    /// Wall time of the build in s.
    pub build_time_s: f64,
    /// CPU time (user + sys) of the build in s, when the platform tells.
    pub build_cpu_s: Option<f64>,
}

fn run_all(
    model: &dyn ForwardModel,
    loading: &Loading,
    points: &[Vec<f64>],
    width: usize,
    done: &std::sync::atomic::AtomicUsize,
    total: usize,
    progress: Option<&(dyn Fn(usize, usize) + Sync)>,
) -> Vec<Result<Vec<f64>, String>> {
    points
        .par_iter()
        .map_init(
            || model.evaluator(),
            |ev, theta| {
                let mut out = vec![0.0; loading.len() * width];
                let r = ev
                    .predict_outputs_into(theta, loading, &mut out)
                    .map(|_| out)
                    .map_err(|e| e.to_string());
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if let Some(p) = progress {
                    p(n, total);
                }
                r
            },
        )
        .collect()
}

/// user + sys CPU time of this process (Linux /proc), for build reports.
pub fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

impl Surrogate {
    /// Runs the model at the training and held-out points (in parallel,
    /// `progress(done, total)` after each run), fits the basis and the GPs,
    /// and measures the error on the held-out runs.
    pub fn build(
        req: &SurrogateRequest<'_>,
        progress: Option<&(dyn Fn(usize, usize) + Sync)>,
    ) -> Result<Surrogate, SurrogateError> {
        let t0 = Instant::now();
        let c0 = cpu_seconds();
        let all_pts = Self::design(req)?;
        let width = req.model.outputs().len();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let results = run_all(
            req.model,
            req.loading,
            &all_pts,
            width,
            &done,
            all_pts.len(),
            progress,
        );
        Self::assemble(req, results, t0, c0)
    }

    /// The model runs a surrogate of `req` needs, checked: the training
    /// points, then the held-out ones (Halton points of the box). Each is
    /// independent of the others ([`Surrogate::run_point`]), so they may be
    /// computed anywhere and handed to [`Surrogate::from_runs`] in this order.
    pub fn design(req: &SurrogateRequest<'_>) -> Result<Vec<Vec<f64>>, SurrogateError> {
        let model = req.model;
        let d = model.space().len();
        if req.bounds.len() != d || req.bounds.names != model.space().names() {
            return Err(SurrogateError::InvalidBox {
                name: req.bounds.names.join(", "),
                reason: format!(
                    "the box is over ({}), the model's parameters are ({})",
                    req.bounds.names.join(", "),
                    model.space().names().join(", ")
                ),
            });
        }
        let o = &req.options;
        if o.training_runs < d + 2 || o.validation_runs < 1 {
            return Err(SurrogateError::InvalidOptions(format!(
                "{} training runs for {d} parameters (need at least {}) and {} held-out runs (need 1)",
                o.training_runs,
                d + 2,
                o.validation_runs
            )));
        }
        if !(o.basis_tolerance > 0.0 && o.basis_tolerance < 1.0) {
            return Err(SurrogateError::InvalidOptions(format!(
                "basis tolerance {}: must lie in (0, 1)",
                o.basis_tolerance
            )));
        }
        req.loading
            .validate()
            .map_err(|e| SurrogateError::InvalidOptions(format!("loading: {e}")))?;
        let mut all_pts = req.bounds.halton(0, o.training_runs);
        all_pts.extend(req.bounds.halton(o.training_runs, o.validation_runs));
        Ok(all_pts)
    }

    /// One model run of a design: the model's outputs at `theta` along
    /// `loading` (samples x outputs), or why it failed (a failed run is
    /// left out of the surrogate, as in [`Surrogate::build`]).
    pub fn run_point(
        model: &dyn ForwardModel,
        loading: &Loading,
        theta: &[f64],
    ) -> Result<Vec<f64>, String> {
        let mut out = vec![0.0; loading.len() * model.outputs().len()];
        model
            .evaluator()
            .predict_outputs_into(theta, loading, &mut out)
            .map(|_| out)
            .map_err(|e| e.to_string())
    }

    /// The surrogate of `req` from the runs at [`Surrogate::design`]'s
    /// points, in that order (computed by [`Surrogate::run_point`]): the
    /// same surrogate as [`Surrogate::build`] but for its build times,
    /// which count this assembly only.
    pub fn from_runs(
        req: &SurrogateRequest<'_>,
        results: Vec<Result<Vec<f64>, String>>,
    ) -> Result<Surrogate, SurrogateError> {
        let t0 = Instant::now();
        let c0 = cpu_seconds();
        let expected = Self::design(req)?.len();
        if results.len() != expected {
            return Err(SurrogateError::InvalidOptions(format!(
                "{} model runs given for a design of {expected}",
                results.len()
            )));
        }
        Self::assemble(req, results, t0, c0)
    }

    fn assemble(
        req: &SurrogateRequest<'_>,
        results: Vec<Result<Vec<f64>, String>>,
        t0: Instant,
        c0: Option<f64>,
    ) -> Result<Surrogate, SurrogateError> {
        let model = req.model;
        let d = model.space().len();
        let o = &req.options;
        let outputs = model.outputs();
        let all_pts = Self::design(req)?;
        let total = all_pts.len();
        let mut failed = Vec::new();
        let mut design = Vec::new();
        let mut curves = Vec::new();
        let mut held = Vec::new();
        for (i, (theta, r)) in all_pts.iter().zip(results).enumerate() {
            match r {
                Ok(c) if i < o.training_runs => {
                    design.push(theta.clone());
                    curves.push(c);
                }
                Ok(c) => held.push((theta.clone(), c)),
                Err(reason) => failed.push(FailedRun {
                    theta: theta.clone(),
                    reason,
                }),
            }
        }
        let need = (d + 2).max((o.training_runs * 4).div_ceil(5));
        if design.len() < need || held.is_empty() {
            let first = failed.first().cloned().unwrap_or(FailedRun {
                theta: Vec::new(),
                reason: "none".into(),
            });
            return Err(SurrogateError::TooManyFailures {
                failed: failed.len(),
                total,
                theta: first.theta,
                reason: first.reason,
            });
        }
        // a run may leave outputs undefined (NaN): one GP per output then
        let missing = curves.iter().any(|c| c.iter().any(|v| !v.is_finite()));
        let (mean, basis, gps, trends) = if missing {
            fit_per_output(&req.bounds, &design, &curves)?
        } else {
            let (m, b, g) = fit(&req.bounds, &design, &curves, o.basis_tolerance)?;
            (m, b, g, Vec::new())
        };
        let mut s = Surrogate {
            format: SURROGATE_FORMAT,
            key: req.key(),
            model_name: model.name(),
            observable: model.observable(),
            outputs,
            space: req.bounds.space(),
            bounds: req.bounds.clone(),
            loading: req.loading.clone(),
            options: o.clone(),
            mean,
            basis,
            gps,
            trends,
            validation: Validation {
                points: 0,
                max_relative_error: 0.0,
                rms_relative_error: 0.0,
                max_abs_error: Vec::new(),
                error_variance: Vec::new(),
            },
            fe_runs: design.len() + held.len(),
            failed,
            build_time_s: 0.0,
            build_cpu_s: None,
        };
        s.validation = s.compare(&held);
        s.build_time_s = t0.elapsed().as_secs_f64();
        s.build_cpu_s = cpu_seconds().zip(c0).map(|(a, b)| a - b);
        Ok(s)
    }

    /// The error of this surrogate against given model runs (`theta`, the
    /// model's outputs samples x outputs).
    pub fn compare(&self, runs: &[(Vec<f64>, Vec<f64>)]) -> Validation {
        let m = self.mean.len();
        let k = self.outputs.len();
        let mut max_rel = 0.0f64;
        let mut ss_rel = 0.0;
        let mut max_abs = vec![0.0f64; k];
        let mut var = vec![0.0; m];
        // runs that define each entry (a run may leave some undefined, NaN)
        let mut defined = vec![0usize; m];
        let mut pred = vec![0.0; m];
        for (theta, y) in runs {
            self.evaluate(theta, &mut pred);
            for j in 0..k {
                let peak = (0..m / k)
                    .map(|i| y[i * k + j].abs())
                    .filter(|v| v.is_finite())
                    .fold(0.0f64, f64::max)
                    .max(1e-300);
                for i in 0..m / k {
                    if !y[i * k + j].is_finite() {
                        continue;
                    }
                    let e = pred[i * k + j] - y[i * k + j];
                    max_abs[j] = max_abs[j].max(e.abs());
                    max_rel = max_rel.max(e.abs() / peak);
                    ss_rel += (e / peak).powi(2);
                    var[i * k + j] += e * e;
                    defined[i * k + j] += 1;
                }
            }
        }
        let total: usize = defined.iter().sum();
        Validation {
            points: runs.len(),
            max_relative_error: max_rel,
            rms_relative_error: (ss_rel / total.max(1) as f64).sqrt(),
            max_abs_error: max_abs,
            error_variance: var
                .into_iter()
                .zip(&defined)
                .map(|(v, &c)| v / c.max(1) as f64)
                .collect(),
        }
    }

    /// The outputs at `theta` (samples x outputs, row-major, `out.len()` =
    /// samples x outputs); refuses a `theta` outside the trained box.
    pub fn predict_outputs(&self, theta: &[f64], out: &mut [f64]) -> Result<(), SurrogateError> {
        self.bounds.check(theta)?;
        if out.len() != self.mean.len() {
            return Err(SurrogateError::InvalidOptions(format!(
                "{} output slots for {} samples x {} outputs",
                out.len(),
                self.loading.len(),
                self.outputs.len()
            )));
        }
        self.evaluate(theta, out);
        Ok(())
    }

    fn evaluate(&self, theta: &[f64], out: &mut [f64]) {
        let u = self.bounds.to_unit(theta);
        out.copy_from_slice(&self.mean);
        if !self.trends.is_empty() {
            let q = quadratic_terms(&u);
            for (o, t) in out.iter_mut().zip(&self.trends) {
                *o += t.iter().zip(&q).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        for (gp, v) in self.gps.iter().zip(&self.basis) {
            let c = gp.mean(&u);
            for (o, b) in out.iter_mut().zip(v) {
                *o += c * b;
            }
        }
    }

    /// The held-out error.
    pub fn validation(&self) -> &Validation {
        &self.validation
    }

    /// The per-sample error variance of output `j` (unit squared), for
    /// [`crate::likelihood::Posterior::with_model_error`].
    pub fn error_variance(&self, j: usize) -> Vec<f64> {
        let k = self.outputs.len();
        self.validation
            .error_variance
            .iter()
            .skip(j)
            .step_by(k)
            .copied()
            .collect()
    }

    /// The trained box.
    pub fn bounds(&self) -> &ParamBox {
        &self.bounds
    }

    /// The loading history it answers for.
    pub fn loading(&self) -> &Loading {
        &self.loading
    }

    /// The cache key it was built under ([`SurrogateRequest::key`]).
    pub fn key(&self) -> &str {
        &self.key
    }

    /// Basis size K.
    pub fn basis_size(&self) -> usize {
        self.basis.len()
    }

    /// The options it was trained with.
    pub fn options(&self) -> &SurrogateOptions {
        &self.options
    }

    /// The stored form (JSON).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Reads the stored form; the error says why it is not a surrogate of
    /// this format.
    pub fn from_json(text: &str) -> Result<Surrogate, String> {
        let s = serde_json::from_str::<Surrogate>(text).map_err(|e| e.to_string())?;
        if s.format != SURROGATE_FORMAT {
            return Err(format!(
                "stored format {}, this build reads {SURROGATE_FORMAT}",
                s.format
            ));
        }
        Ok(s)
    }
}

/// Reduced basis and coefficient GPs of the training curves.
#[allow(clippy::type_complexity)]
fn fit(
    bounds: &ParamBox,
    design: &[Vec<f64>],
    curves: &[Vec<f64>],
    tol: f64,
) -> Result<(Vec<f64>, Vec<Vec<f64>>, Vec<Gp>), SurrogateError> {
    let n = curves.len();
    let m = curves[0].len();
    let mut mean = vec![0.0; m];
    for c in curves {
        for (a, v) in mean.iter_mut().zip(c) {
            *a += v / n as f64;
        }
    }
    let y = DMatrix::from_fn(n, m, |i, j| curves[i][j] - mean[j]);
    let svd = y.svd(true, true);
    let (u, vt) = match (svd.u, svd.v_t) {
        (Some(u), Some(vt)) => (u, vt),
        _ => return Err(SurrogateError::Singular),
    };
    let s = &svd.singular_values;
    let mut order: Vec<usize> = (0..s.len()).collect();
    order.sort_by(|a, b| s[*b].total_cmp(&s[*a]));
    let energy: f64 = s.iter().map(|v| v * v).sum();
    let mut kept = 0;
    let mut left = energy;
    for &k in &order {
        if left <= tol * tol * energy || s[k] == 0.0 {
            break;
        }
        left -= s[k] * s[k];
        kept += 1;
    }
    let inputs: Vec<Vec<f64>> = design.iter().map(|t| bounds.to_unit(t)).collect();
    let mut basis = Vec::with_capacity(kept);
    let mut gps = Vec::with_capacity(kept);
    for &k in order.iter().take(kept) {
        let coef: Vec<f64> = (0..n).map(|i| u[(i, k)] * s[k]).collect();
        gps.push(Gp::fit(&inputs, &coef).ok_or(SurrogateError::Singular)?);
        basis.push(vt.row(k).iter().copied().collect());
    }
    Ok((mean, basis, gps))
}

/// The terms of a full quadratic in `u` without the constant: u_i, then
/// u_i u_j (i <= j).
pub fn quadratic_terms(u: &[f64]) -> Vec<f64> {
    let mut q = u.to_vec();
    for i in 0..u.len() {
        for j in i..u.len() {
            q.push(u[i] * u[j]);
        }
    }
    q
}

/// Per-output trend and GP of [`fit_per_output`]: (mean, basis, GPs,
/// trends).
type PerOutput = (Vec<f64>, Vec<Vec<f64>>, Vec<Gp>, Vec<Vec<f64>>);

/// The surrogate of runs that leave some outputs undefined (NaN; e.g. an R2
/// scan whose wheel positions fall off the rolled path for nodules near the
/// block's end): no common basis (a basis needs every output of every
/// run), but per output a quadratic trend in the parameters (least squares,
/// when the runs defining the output are at least twice its terms) and a GP
/// of the residuals on the runs that define it (universal kriging with the
/// trend fitted first; Rasmussen & Williams 2006, sec. 2.7); as the basis
/// form with the identity basis. An output defined by fewer than 2 runs is
/// their mean (0 when none). Outputs are undefined where the model is never
/// asked for them, so each output is queried where its runs are.
fn fit_per_output(
    bounds: &ParamBox,
    design: &[Vec<f64>],
    curves: &[Vec<f64>],
) -> Result<PerOutput, SurrogateError> {
    let m = curves[0].len();
    let units: Vec<Vec<f64>> = design.iter().map(|t| bounds.to_unit(t)).collect();
    let nq = quadratic_terms(&units[0]).len();
    let mut mean = vec![0.0; m];
    let mut trends = vec![vec![0.0; nq]; m];
    let mut basis = Vec::new();
    let mut gps = Vec::new();
    for j in 0..m {
        let (inputs, y): (Vec<Vec<f64>>, Vec<f64>) = units
            .iter()
            .zip(curves)
            .filter(|(_, c)| c[j].is_finite())
            .map(|(u, c)| (u.clone(), c[j]))
            .unzip();
        if y.is_empty() {
            continue;
        }
        let n = y.len();
        mean[j] = y.iter().sum::<f64>() / n as f64;
        if n < 2 {
            continue;
        }
        let mut r: Vec<f64> = y.iter().map(|v| v - mean[j]).collect();
        if n >= 2 * (nq + 1) {
            // least squares [1, q(u)] c = y by SVD
            let a = DMatrix::from_fn(n, nq + 1, |i, k| {
                if k == 0 {
                    1.0
                } else {
                    quadratic_terms(&inputs[i])[k - 1]
                }
            });
            let c = a
                .clone()
                .svd(true, true)
                .solve(&DVector::from_column_slice(&y), 1e-12)
                .map_err(|_| SurrogateError::Singular)?;
            mean[j] = c[0];
            trends[j] = c.iter().skip(1).copied().collect();
            let fitted = &a * &c;
            r = y.iter().zip(fitted.iter()).map(|(v, f)| v - f).collect();
        }
        gps.push(Gp::fit(&inputs, &r).ok_or(SurrogateError::Singular)?);
        let mut e = vec![0.0; m];
        e[j] = 1.0;
        basis.push(e);
    }
    Ok((mean, basis, gps, trends))
}

/// Same drive kind and samples (and times) to 1e-12 relative: a record
/// read again from its CSV is the same history.
fn same_loading(a: &Loading, b: &Loading) -> bool {
    let close = |x: &[f64], y: &[f64]| {
        x.len() == y.len()
            && x.iter()
                .zip(y)
                .all(|(p, q)| (p - q).abs() <= 1e-12 * p.abs().max(q.abs()).max(1e-300))
    };
    a.drive_kind == b.drive_kind
        && close(&a.drive, &b.drive)
        && match (&a.time, &b.time) {
            (None, None) => true,
            (Some(x), Some(y)) => close(x, y),
            _ => false,
        }
}

struct SurrogateEvaluator<'a>(&'a Surrogate);

impl SurrogateEvaluator<'_> {
    fn check(&self, theta: &[f64], loading: &Loading) -> Result<(), ForwardError> {
        let s = self.0;
        s.bounds.check(theta).map_err(|e| match e {
            SurrogateError::OutsideBox {
                name,
                value,
                lower,
                upper,
            } => ForwardError::InvalidParameter {
                name,
                value,
                reason: format!(
                    "outside the surrogate's trained box [{lower}, {upper}]: it does not extrapolate (train it on a wider box)"
                ),
            },
            other => ForwardError::InvalidLoading(other.to_string()),
        })?;
        if !same_loading(loading, &s.loading) {
            return Err(ForwardError::InvalidLoading(format!(
                "the surrogate answers only for the loading history it was trained on ({} samples, drive {} .. {})",
                s.loading.len(),
                s.loading.drive.first().copied().unwrap_or(0.0),
                s.loading.drive.last().copied().unwrap_or(0.0)
            )));
        }
        Ok(())
    }
}

impl Evaluator for SurrogateEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.check(theta, loading)?;
        let s = self.0;
        let k = s.outputs.len();
        if out.len() != loading.len() {
            return Err(ForwardError::InvalidLoading(format!(
                "{} output slots for {} samples",
                out.len(),
                loading.len()
            )));
        }
        if k == 1 {
            s.evaluate(theta, out);
        } else {
            let mut all = vec![0.0; s.mean.len()];
            s.evaluate(theta, &mut all);
            for (o, row) in out.iter_mut().zip(all.chunks_exact(k)) {
                *o = row[0];
            }
        }
        Ok(())
    }

    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.check(theta, loading)?;
        let s = self.0;
        palpate_core::check_output_slots(out.len(), loading.len(), s.outputs.len())?;
        s.evaluate(theta, out);
        Ok(())
    }
}

/// The surrogate is a forward model whose parameter bounds are its trained
/// box, so a [`crate::likelihood::Posterior`] samples it directly and never
/// extrapolates; it answers only for its training loading.
impl ForwardModel for Surrogate {
    fn name(&self) -> String {
        format!(
            "surrogate of {} ({} runs, {} basis vectors)",
            self.model_name,
            self.fe_runs,
            self.basis.len()
        )
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        self.observable
    }
    fn outputs(&self) -> Vec<Output> {
        self.outputs.clone()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(SurrogateEvaluator(self))
    }
}
