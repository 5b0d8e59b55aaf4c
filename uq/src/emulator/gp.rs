//! A Gaussian-process emulator of a whole force curve.
//!
//! Training: n model runs at a Halton design in a parameter box
//! [lower, upper] (inputs scaled to [0, 1]^d). Every output sample j (one
//! point of the curve) is standardised, y_j = (f_j - m_j) / s_j, and all share
//! one squared-exponential kernel
//!
//!   k(u, u') = exp(-1/2 sum_i (u_i - u'_i)^2 / l_i^2) + delta [u = u'],
//!
//! with per-output signal variances profiled out. The length scales
//! maximise the summed log marginal likelihood
//!
//!   sum_j [ -n/2 ln(y_j^T K^-1 y_j / n) ] - m/2 ln det K
//!
//! over a log grid (Rasmussen & Williams 2006, *Gaussian Processes for
//! Machine Learning*, eqs. 2.25-2.30 and 5.8). The prediction is the GP mean
//! f_j(u) = m_j + s_j k(u)^T K^-1 y_j: one kernel vector and a product with
//! the precomputed n x m weight matrix, so an evaluation costs O(n m), not a
//! finite-element solve. Sharing the kernel across the curve keeps one
//! Cholesky factorisation for all outputs (the outputs of a force curve vary
//! smoothly together, which a PCA-per-component emulator would exploit the
//! same way at more code).
//!
//! The emulator is itself a [`ForwardModel`] whose parameter bounds are the
//! training box, so a [`crate::likelihood::Posterior`] samples it directly and
//! never extrapolates. [`CurveEmulator::validate`] compares it with direct
//! model runs at fresh design points.

use nalgebra::{DMatrix, DVector};
use palpate_core::{
    Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace, ParamSpec,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Why an emulator could not be trained.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum EmulatorError {
    #[error("parameter box: {reason}")]
    InvalidBox { reason: String },
    #[error("design point {index} ({theta:?}): the model failed: {source}")]
    ModelFailed {
        index: usize,
        theta: Vec<f64>,
        #[source]
        source: ForwardError,
    },
    #[error("the kernel matrix is not positive definite for any length scale")]
    Singular,
}

/// Points `index..index + n` of the Halton sequence (bases 2, 3, 5, ...)
/// scaled into the box.
pub fn halton_design(lower: &[f64], upper: &[f64], start: usize, n: usize) -> Vec<Vec<f64>> {
    const PRIMES: [u64; 10] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29];
    (start..start + n)
        .map(|i| {
            lower
                .iter()
                .zip(upper)
                .enumerate()
                .map(|(k, (lo, hi))| {
                    let b = PRIMES[k % PRIMES.len()];
                    let (mut f, mut x, mut j) = (1.0, 0.0, i as u64 + 1);
                    while j > 0 {
                        f /= b as f64;
                        x += f * (j % b) as f64;
                        j /= b;
                    }
                    lo + (hi - lo) * x
                })
                .collect()
        })
        .collect()
}

/// Emulator accuracy against direct model runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Validation {
    pub points: usize,
    /// max over points and samples of |emulator - model| / max |model curve|.
    pub max_relative_error: f64,
    /// RMS of the same relative errors.
    pub rms_relative_error: f64,
}

/// A trained curve emulator.
#[derive(Debug, Clone)]
pub struct CurveEmulator {
    name: String,
    observable: Observable,
    space: ParamSpace,
    lower: Vec<f64>,
    upper: Vec<f64>,
    inputs: Vec<Vec<f64>>,
    length_scales: Vec<f64>,
    mean: Vec<f64>,
    scale: Vec<f64>,
    /// K^-1 Y, n x m.
    weights: DMatrix<f64>,
    /// The loading the curve was trained on (predictions are for it only).
    loading: Loading,
    /// Model runs spent on training.
    pub runs: usize,
}

const NUGGET: f64 = 1e-10;

fn kernel(a: &[f64], b: &[f64], l: &[f64]) -> f64 {
    let s: f64 = a
        .iter()
        .zip(b)
        .zip(l)
        .map(|((x, y), l)| (x - y) * (x - y) / (l * l))
        .sum();
    (-0.5 * s).exp()
}

fn gram(u: &[Vec<f64>], l: &[f64]) -> DMatrix<f64> {
    let n = u.len();
    DMatrix::from_fn(n, n, |i, j| {
        kernel(&u[i], &u[j], l) + if i == j { NUGGET } else { 0.0 }
    })
}

impl CurveEmulator {
    /// Runs `model` at `n_runs` Halton points of the box (in parallel, one
    /// evaluator per thread) and fits the GP.
    pub fn train(
        model: &dyn ForwardModel,
        loading: &Loading,
        lower: &[f64],
        upper: &[f64],
        n_runs: usize,
    ) -> Result<CurveEmulator, EmulatorError> {
        let d = model.space().len();
        if lower.len() != d
            || upper.len() != d
            || lower
                .iter()
                .zip(upper)
                .any(|(l, u)| l.is_nan() || u.is_nan() || l >= u)
        {
            return Err(EmulatorError::InvalidBox {
                reason: format!("need {d} lower < upper pairs"),
            });
        }
        let design = halton_design(lower, upper, 0, n_runs);
        let curves: Vec<Vec<f64>> = design
            .par_iter()
            .enumerate()
            .map_init(
                || model.evaluator(),
                |ev, (i, theta)| {
                    let mut out = vec![0.0; loading.len()];
                    ev.predict_into(theta, loading, &mut out)
                        .map(|_| out)
                        .map_err(|source| EmulatorError::ModelFailed {
                            index: i,
                            theta: theta.clone(),
                            source,
                        })
                },
            )
            .collect::<Result<_, _>>()?;
        Self::fit(model, loading, lower, upper, design, curves)
    }

    /// Fits the GP to given runs (`curves[i]` at physical `design[i]`).
    pub fn fit(
        model: &dyn ForwardModel,
        loading: &Loading,
        lower: &[f64],
        upper: &[f64],
        design: Vec<Vec<f64>>,
        curves: Vec<Vec<f64>>,
    ) -> Result<CurveEmulator, EmulatorError> {
        let n = design.len();
        let m = loading.len();
        let d = lower.len();
        let inputs: Vec<Vec<f64>> = design
            .iter()
            .map(|t| {
                t.iter()
                    .zip(lower)
                    .zip(upper)
                    .map(|((x, l), u)| (x - l) / (u - l))
                    .collect()
            })
            .collect();
        let mut mean = vec![0.0; m];
        let mut scale = vec![0.0; m];
        for j in 0..m {
            let col: Vec<f64> = curves.iter().map(|c| c[j]).collect();
            let mu = col.iter().sum::<f64>() / n as f64;
            let var = col.iter().map(|v| (v - mu) * (v - mu)).sum::<f64>() / n as f64;
            mean[j] = mu;
            scale[j] = if var > 0.0 { var.sqrt() } else { 1.0 };
        }
        let y = DMatrix::from_fn(n, m, |i, j| (curves[i][j] - mean[j]) / scale[j]);
        // Log grid of length scales per dimension (0.05 .. 5 in unit-box units).
        let grid: Vec<f64> = (0..13).map(|k| 0.05 * 10f64.powf(k as f64 / 6.0)).collect();
        let mut best: Option<(f64, Vec<f64>)> = None;
        let combos = grid.len().pow(d as u32);
        for c in 0..combos {
            let mut idx = c;
            let l: Vec<f64> = (0..d)
                .map(|_| {
                    let v = grid[idx % grid.len()];
                    idx /= grid.len();
                    v
                })
                .collect();
            let Some(ch) = gram(&inputs, &l).cholesky() else {
                continue;
            };
            let alpha = ch.solve(&y);
            let log_det: f64 = 2.0 * (0..n).map(|i| ch.l()[(i, i)].ln()).sum::<f64>();
            let mut lml = -0.5 * m as f64 * log_det;
            for j in 0..m {
                let q = y.column(j).dot(&alpha.column(j)) / n as f64;
                if q > 0.0 {
                    lml -= 0.5 * n as f64 * q.ln();
                }
            }
            if lml.is_finite() && best.as_ref().is_none_or(|(b, _)| lml > *b) {
                best = Some((lml, l));
            }
        }
        let (_, length_scales) = best.ok_or(EmulatorError::Singular)?;
        let ch = gram(&inputs, &length_scales)
            .cholesky()
            .ok_or(EmulatorError::Singular)?;
        let weights = ch.solve(&y);
        let space = ParamSpace::new(
            model
                .space()
                .params
                .iter()
                .zip(lower.iter().zip(upper))
                .map(|(p, (l, u))| {
                    ParamSpec::new(p.name.clone(), p.unit.clone(), *l, *u, 0.5 * (l + u))
                })
                .collect(),
        );
        Ok(CurveEmulator {
            name: format!("GP emulator of {} ({n} runs)", model.name()),
            observable: model.observable(),
            space,
            lower: lower.to_vec(),
            upper: upper.to_vec(),
            inputs,
            length_scales,
            mean,
            scale,
            weights,
            loading: loading.clone(),
            runs: n,
        })
    }

    /// The chosen length scales (unit-box units).
    pub fn length_scales(&self) -> &[f64] {
        &self.length_scales
    }

    /// The emulated curve at physical `theta` (inside the box).
    pub fn curve(&self, theta: &[f64], out: &mut [f64]) {
        let u: Vec<f64> = theta
            .iter()
            .zip(&self.lower)
            .zip(&self.upper)
            .map(|((x, l), h)| (x - l) / (h - l))
            .collect();
        let k = DVector::from_iterator(
            self.inputs.len(),
            self.inputs
                .iter()
                .map(|p| kernel(&u, p, &self.length_scales)),
        );
        for (j, o) in out.iter_mut().enumerate() {
            *o = self.mean[j] + self.scale[j] * k.dot(&self.weights.column(j));
        }
    }

    /// Compares with `model` at `n` fresh Halton points (after the training ones).
    pub fn validate(
        &self,
        model: &dyn ForwardModel,
        n: usize,
    ) -> Result<Validation, EmulatorError> {
        let pts = halton_design(&self.lower, &self.upper, self.runs, n);
        let errs: Vec<(f64, f64, usize)> = pts
            .par_iter()
            .enumerate()
            .map(|(i, theta)| {
                let direct = model.predict(theta, &self.loading).map_err(|source| {
                    EmulatorError::ModelFailed {
                        index: i,
                        theta: theta.clone(),
                        source,
                    }
                })?;
                let mut em = vec![0.0; direct.len()];
                self.curve(theta, &mut em);
                let peak = direct
                    .iter()
                    .fold(0.0f64, |a, v| a.max(v.abs()))
                    .max(1e-300);
                let mut max = 0.0f64;
                let mut ss = 0.0;
                for (a, b) in em.iter().zip(&direct) {
                    let r = (a - b).abs() / peak;
                    max = max.max(r);
                    ss += r * r;
                }
                Ok((max, ss, direct.len()))
            })
            .collect::<Result<_, EmulatorError>>()?;
        let max = errs.iter().map(|e| e.0).fold(0.0, f64::max);
        let ss: f64 = errs.iter().map(|e| e.1).sum();
        let cnt: usize = errs.iter().map(|e| e.2).sum();
        Ok(Validation {
            points: n,
            max_relative_error: max,
            rms_relative_error: (ss / cnt as f64).sqrt(),
        })
    }
}

struct EmulatorEvaluator<'a>(&'a CurveEmulator);

impl Evaluator for EmulatorEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let e = self.0;
        e.space.check(theta)?;
        if loading.drive != e.loading.drive || out.len() != e.loading.len() {
            return Err(ForwardError::InvalidLoading(
                "the emulator predicts only the loading history it was trained on".into(),
            ));
        }
        e.curve(theta, out);
        Ok(())
    }
}

impl ForwardModel for CurveEmulator {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        self.observable
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(EmulatorEvaluator(self))
    }
}
