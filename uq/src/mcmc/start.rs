//! Where chains start: a centre and a per-coordinate scale in the unbounded
//! space (typically the Laplace mode and standard deviations).

use super::density::Counted;
use super::error::McmcError;
use super::rng::{std_normal, ChainRng};
use serde::{Deserialize, Serialize};

/// Start points are drawn as `center + scale * N(0, 1)` (retrying, then
/// shrinking the scale, until the log-density is finite).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Start {
    pub center: Vec<f64>,
    pub scale: Vec<f64>,
    /// Optional lower-triangular Cholesky factor L of a covariance (e.g. the
    /// Laplace covariance, row-major). When present the samplers move in
    /// y with z = center + L y, which decorrelates the posterior for NUTS and
    /// DE-MCz (a fixed linear map: no Jacobian term); otherwise L = diag(scale).
    #[serde(default)]
    pub cholesky: Option<Vec<Vec<f64>>>,
}

impl Start {
    /// A start with the same scale in every coordinate.
    pub fn ball(center: Vec<f64>, scale: f64) -> Start {
        let scale = vec![scale; center.len()];
        Start {
            center,
            scale,
            cholesky: None,
        }
    }

    pub(crate) fn check(&self, dim: usize) -> Result<(), McmcError> {
        let rows = self.cholesky.as_ref().map_or(dim, |l| {
            if l.iter().all(|r| r.len() == dim) {
                l.len()
            } else {
                0
            }
        });
        for got in [self.center.len(), self.scale.len(), rows] {
            if got != dim {
                return Err(McmcError::DimensionMismatch { expected: dim, got });
            }
        }
        Ok(())
    }

    /// A jittered start point with a finite log-density, and that density.
    pub(crate) fn draw(
        &self,
        rng: &mut ChainRng,
        w: &mut Counted,
        chain: usize,
    ) -> Result<(Vec<f64>, f64), McmcError> {
        const TRIES: usize = 100;
        let mut shrink = 1.0;
        for i in 0..TRIES {
            if i % 10 == 9 {
                shrink *= 0.3;
            }
            let z: Vec<f64> = self
                .center
                .iter()
                .zip(&self.scale)
                .map(|(c, s)| c + shrink * s * std_normal(rng))
                .collect();
            let lp = w.log_density(&z);
            if lp.is_finite() {
                return Ok((z, lp));
            }
        }
        Err(McmcError::NoFiniteStart {
            chain,
            tries: TRIES,
        })
    }
}
