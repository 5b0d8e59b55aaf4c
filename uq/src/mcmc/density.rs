//! The slice-based log-density that every sampler moves on (STYLE.md 11).
//!
//! A [`LogDensity`] is shared and `Sync` (one per posterior); each chain asks
//! it for a [`DensityWorker`] that owns the per-thread state (forward-model
//! evaluators, scratch) — the `Model -> Math` split of nuts-rs and the
//! `ForwardModel -> Evaluator` split of palpate-core.
//!
//! Any `Fn(&[f64]) -> f64 + Sync` closure is a [`LogDensity`] too, which is
//! what the tests and toy problems use. A value of `-inf` (or NaN, treated as
//! `-inf`) means "outside the support / the model failed": samplers reject
//! such points.

use palpate_core::fd::{fd_column, FdRule};
use std::convert::Infallible;

/// A log-density on R^d, up to an additive constant.
pub trait LogDensity: Sync {
    /// Dimension d.
    fn dim(&self) -> usize;
    /// A per-thread worker.
    fn worker(&self) -> Box<dyn DensityWorker + '_>;
}

/// Per-thread evaluation of a [`LogDensity`].
///
/// The gradient has a finite-difference default ([`fd_value_and_gradient`]:
/// central differences, step `h_k = 1e-5 max(1, |z_k|)`), acceptable for
/// cheap analytic models; a model with exact sensitivities overrides [`DensityWorker::value_and_gradient`]
/// (the layered-capability hook of STYLE.md 3).
pub trait DensityWorker {
    /// log p(z).
    fn log_density(&mut self, z: &[f64]) -> f64;

    /// log p(z) and its gradient, written into `grad`. Returns the number of
    /// log-density evaluations it cost together with the value.
    fn value_and_gradient(&mut self, z: &[f64], grad: &mut [f64]) -> (f64, u64) {
        fd_value_and_gradient(&mut |z| self.log_density(z), z, grad)
    }
}

/// Relative step of the finite-difference gradient: `h_k = 1e-5 max(1, |z_k|)`.
pub const FD_RELATIVE_STEP: f64 = 1e-5;

/// Central finite-difference gradient of `f` by palpate-core's `fd` (step
/// [`FD_RELATIVE_STEP`] `max(1, |z_k|)`): the default of
/// [`DensityWorker::value_and_gradient`], for overrides that fall back to
/// it. Returns the value and the evaluations spent (2 d + 1).
pub fn fd_value_and_gradient(
    f: &mut dyn FnMut(&[f64]) -> f64,
    z: &[f64],
    grad: &mut [f64],
) -> (f64, u64) {
    let f0 = f(z);
    let rule = FdRule::central(FD_RELATIVE_STEP);
    let mut g = |zz: &[f64], out: &mut [f64]| -> Result<(), Infallible> {
        out[0] = f(zz);
        Ok(())
    };
    let mut evals = 1;
    for (k, gk) in grad.iter_mut().enumerate().take(z.len()) {
        let mut col = [0.0];
        let Ok(n) = fd_column(
            &mut g,
            z,
            k,
            rule.unbounded_step(z[k]),
            Some(&[f0]),
            &mut col,
        );
        evals += n as u64;
        *gk = col[0];
    }
    (f0, evals)
}

/// A closure as a log-density of fixed dimension.
pub struct FnDensity<F> {
    dim: usize,
    f: F,
}

impl<F: Fn(&[f64]) -> f64 + Sync> FnDensity<F> {
    /// Wraps `f` on R^`dim`.
    pub fn new(dim: usize, f: F) -> Self {
        FnDensity { dim, f }
    }
}

struct FnWorker<'a, F>(&'a F);

impl<F: Fn(&[f64]) -> f64> DensityWorker for FnWorker<'_, F> {
    fn log_density(&mut self, z: &[f64]) -> f64 {
        (self.0)(z)
    }
}

impl<F: Fn(&[f64]) -> f64 + Sync> LogDensity for FnDensity<F> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn worker(&self) -> Box<dyn DensityWorker + '_> {
        Box::new(FnWorker(&self.f))
    }
}

/// A closure with an exact gradient: `f(z, grad) -> log p`, filling `grad`.
pub struct GradFnDensity<F> {
    dim: usize,
    f: F,
}

impl<F: Fn(&[f64], &mut [f64]) -> f64 + Sync> GradFnDensity<F> {
    /// Wraps `f` on R^`dim`.
    pub fn new(dim: usize, f: F) -> Self {
        GradFnDensity { dim, f }
    }
}

struct GradFnWorker<'a, F> {
    f: &'a F,
    scratch: Vec<f64>,
}

impl<F: Fn(&[f64], &mut [f64]) -> f64> DensityWorker for GradFnWorker<'_, F> {
    fn log_density(&mut self, z: &[f64]) -> f64 {
        (self.f)(z, &mut self.scratch)
    }
    fn value_and_gradient(&mut self, z: &[f64], grad: &mut [f64]) -> (f64, u64) {
        ((self.f)(z, grad), 1)
    }
}

impl<F: Fn(&[f64], &mut [f64]) -> f64 + Sync> LogDensity for GradFnDensity<F> {
    fn dim(&self) -> usize {
        self.dim
    }
    fn worker(&self) -> Box<dyn DensityWorker + '_> {
        Box::new(GradFnWorker {
            f: &self.f,
            scratch: vec![0.0; self.dim],
        })
    }
}

/// A worker that counts log-density evaluations and maps NaN to `-inf`.
pub(crate) struct Counted<'a> {
    pub inner: Box<dyn DensityWorker + 'a>,
    pub evaluations: u64,
}

impl<'a> Counted<'a> {
    pub fn new(inner: Box<dyn DensityWorker + 'a>) -> Self {
        Counted {
            inner,
            evaluations: 0,
        }
    }
    pub fn log_density(&mut self, z: &[f64]) -> f64 {
        self.evaluations += 1;
        let v = self.inner.log_density(z);
        if v.is_nan() {
            f64::NEG_INFINITY
        } else {
            v
        }
    }
    pub fn value_and_gradient(&mut self, z: &[f64], grad: &mut [f64]) -> f64 {
        let (v, n) = self.inner.value_and_gradient(z, grad);
        self.evaluations += n;
        if v.is_nan() || grad.iter().any(|g| !g.is_finite()) {
            f64::NEG_INFINITY
        } else {
            v
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finite_difference_gradient_matches_exact() {
        let d = FnDensity::new(2, |z: &[f64]| {
            -0.5 * (z[0] * z[0] + 3.0 * z[1] * z[1]) + z[0] * z[1].sin()
        });
        let mut w = d.worker();
        let z = [0.7, -1.3];
        let mut g = [0.0; 2];
        let (v, n) = w.value_and_gradient(&z, &mut g);
        assert_eq!(n, 5);
        assert!((v - w.log_density(&z)).abs() < 1e-15);
        let exact = [-z[0] + z[1].sin(), -3.0 * z[1] + z[0] * z[1].cos()];
        for k in 0..2 {
            assert!(
                (g[k] - exact[k]).abs() < 1e-8,
                "{k}: {} vs {}",
                g[k],
                exact[k]
            );
        }
    }
}
