//! Standardised coordinates for the samplers.

use super::density::{DensityWorker, LogDensity};

/// The density in standardised coordinates y with z = center + L y (L
/// lower-triangular: the start's Cholesky factor or diag(scale)), so that
/// finite-difference steps, initial step sizes and mass matrices see unit,
/// uncorrelated scales whatever the parametrisation (a C20 of 1e-3 MPa next
/// to a log C10 of -7). A fixed linear map adds only a constant to the
/// log-density. The samplers run on it and map the draws back.
pub(crate) struct Standardized<'a> {
    pub inner: &'a dyn LogDensity,
    pub center: Vec<f64>,
    /// Lower-triangular L, row-major.
    pub l: Vec<Vec<f64>>,
}

fn apply(center: &[f64], l: &[Vec<f64>], y: &[f64], z: &mut [f64]) {
    for i in 0..center.len() {
        let mut v = center[i];
        for j in 0..=i {
            v += l[i][j] * y[j];
        }
        z[i] = v;
    }
}

impl<'a> Standardized<'a> {
    /// From a start: its Cholesky factor, or diag(scale) (non-positive scales read as 1).
    pub fn new(inner: &'a dyn LogDensity, start: &super::Start) -> Self {
        let d = start.center.len();
        let l = start.cholesky.clone().unwrap_or_else(|| {
            (0..d)
                .map(|i| {
                    (0..d)
                        .map(|j| {
                            let s = start.scale[i];
                            if i != j {
                                0.0
                            } else if s > 0.0 && s.is_finite() {
                                s
                            } else {
                                1.0
                            }
                        })
                        .collect()
                })
                .collect()
        });
        Standardized {
            inner,
            center: start.center.clone(),
            l,
        }
    }

    pub fn to_original(&self, y: &[f64]) -> Vec<f64> {
        let mut z = vec![0.0; y.len()];
        apply(&self.center, &self.l, y, &mut z);
        z
    }
}

struct StandardizedWorker<'a> {
    inner: Box<dyn DensityWorker + 'a>,
    center: &'a [f64],
    l: &'a [Vec<f64>],
    z: Vec<f64>,
}

impl DensityWorker for StandardizedWorker<'_> {
    fn log_density(&mut self, y: &[f64]) -> f64 {
        apply(self.center, self.l, y, &mut self.z);
        self.inner.log_density(&self.z)
    }
    /// Chain rule through the linear map: grad_y = L^T grad_z, so an exact
    /// gradient of the inner density stays exact.
    fn value_and_gradient(&mut self, y: &[f64], grad: &mut [f64]) -> (f64, u64) {
        apply(self.center, self.l, y, &mut self.z);
        let mut gz = vec![0.0; y.len()];
        let (v, n) = self.inner.value_and_gradient(&self.z, &mut gz);
        for j in 0..y.len() {
            grad[j] = (j..y.len()).map(|i| self.l[i][j] * gz[i]).sum();
        }
        (v, n)
    }
}

impl LogDensity for Standardized<'_> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn worker(&self) -> Box<dyn DensityWorker + '_> {
        Box::new(StandardizedWorker {
            inner: self.inner.worker(),
            center: &self.center,
            l: &self.l,
            z: vec![0.0; self.center.len()],
        })
    }
}
