//! Least squares over one or several data sets sharing one parameter vector.

use crate::{DataSet, InverseError, ResidualKind};
use palpate_core::{Evaluator, ParamSpace};
use std::ops::Range;

/// One evaluator per data set, owned by one thread (STYLE.md 2).
pub type Evaluators<'a> = Vec<Box<dyn Evaluator + 'a>>;

/// The least-squares objective `SSE(theta) = sum_sets sum_i r_i(theta)^2`
/// (residuals as defined by [`ResidualKind`]).
///
/// Parameters are the models' common [`ParamSpace`]; some may be held fixed.
/// Estimators move the free ones in the unbounded space of the space's
/// transforms (`x = lower + exp(z)` etc.), so bounds hold without clamping.
#[derive(Debug, Clone)]
pub struct Objective {
    sets: Vec<DataSet>,
    residual: ResidualKind,
    space: ParamSpace,
    fixed: Vec<Option<f64>>,
    free: Vec<usize>,
    factors: Vec<Vec<(usize, f64)>>,
    offsets: Vec<usize>,
}

impl Objective {
    /// Checks the sets (lengths, weights, common parameter names) and the
    /// fixed parameters (known names, values inside the bounds).
    pub fn new(
        sets: Vec<DataSet>,
        residual: ResidualKind,
        fixed: &[(String, f64)],
    ) -> Result<Self, InverseError> {
        let first = sets.first().ok_or(InverseError::NoDataSets)?;
        let space = first.model.space().clone();
        let names = space.names();
        for set in &sets {
            set.validate()?;
            let found = set.model.space().names();
            if found != names {
                return Err(InverseError::ParameterMismatch {
                    set: set.name.clone(),
                    first: first.name.clone(),
                    expected: names.clone(),
                    found,
                });
            }
        }
        let mut fixed_values = vec![None; space.len()];
        for (name, value) in fixed {
            let k = space
                .index_of(name)
                .ok_or_else(|| InverseError::UnknownParameter {
                    name: name.clone(),
                    known: names.clone(),
                })?;
            let p = &space.params[k];
            if !p.contains(*value) {
                return Err(InverseError::OutOfBounds {
                    name: name.clone(),
                    value: *value,
                    lower: p.lower,
                    upper: p.upper,
                });
            }
            fixed_values[k] = Some(*value);
        }
        let free: Vec<usize> = (0..space.len())
            .filter(|&k| fixed_values[k].is_none())
            .collect();
        if free.is_empty() {
            return Err(InverseError::NothingToFit);
        }
        let mut factors = Vec::with_capacity(sets.len());
        let mut offsets = vec![0];
        for set in &sets {
            let f = residual.factors(&set.observed, set.weight).ok_or_else(|| {
                InverseError::ZeroObservations {
                    set: set.name.clone(),
                }
            })?;
            if f.is_empty() {
                return Err(InverseError::EmptySet {
                    set: set.name.clone(),
                });
            }
            offsets.push(offsets.last().copied().unwrap_or(0) + f.len());
            factors.push(f);
        }
        Ok(Objective {
            sets,
            residual,
            space,
            fixed: fixed_values,
            free,
            factors,
            offsets,
        })
    }

    /// The data sets.
    pub fn sets(&self) -> &[DataSet] {
        &self.sets
    }

    /// The residual kind.
    pub fn residual_kind(&self) -> ResidualKind {
        self.residual
    }

    /// The full parameter space (free and fixed).
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// Indices (in the full space) of the free parameters.
    pub fn free_indices(&self) -> &[usize] {
        &self.free
    }

    /// Names of the free parameters.
    pub fn free_names(&self) -> Vec<String> {
        self.free
            .iter()
            .map(|&k| self.space.params[k].name.clone())
            .collect()
    }

    /// The value a parameter is held at, if fixed.
    pub fn fixed_value(&self, k: usize) -> Option<f64> {
        self.fixed[k]
    }

    /// Number of free parameters.
    pub fn n_free(&self) -> usize {
        self.free.len()
    }

    /// Total number of residuals.
    pub fn n_residuals(&self) -> usize {
        self.offsets.last().copied().unwrap_or(0)
    }

    /// Where set `s`'s residuals lie in the residual vector.
    pub fn residual_range(&self, s: usize) -> Range<usize> {
        self.offsets[s]..self.offsets[s + 1]
    }

    /// Kept sample indices of set `s` and their residual factors `w * s_i`.
    pub fn factors(&self, s: usize) -> &[(usize, f64)] {
        &self.factors[s]
    }

    /// The full physical vector from free physical values.
    pub fn theta_from_free(&self, x_free: &[f64]) -> Vec<f64> {
        let mut theta: Vec<f64> = self.fixed.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
        for (&k, &x) in self.free.iter().zip(x_free) {
            theta[k] = x;
        }
        theta
    }

    /// The full physical vector from free unbounded values `z`.
    pub fn theta_from_unbounded(&self, z: &[f64]) -> Vec<f64> {
        let x: Vec<f64> = self
            .free
            .iter()
            .zip(z)
            .map(|(&k, &zk)| self.space.params[k].from_unbounded(zk))
            .collect();
        self.theta_from_free(&x)
    }

    /// `dx/dz` of each free parameter at `z`.
    pub fn dx_dz(&self, z: &[f64]) -> Vec<f64> {
        self.free
            .iter()
            .zip(z)
            .map(|(&k, &zk)| self.space.params[k].dx_dz(zk))
            .collect()
    }

    /// Free unbounded values of a full physical vector whose free entries lie
    /// strictly inside their bounds (fixed entries are ignored).
    pub fn unbounded_from_theta(&self, theta: &[f64]) -> Result<Vec<f64>, InverseError> {
        if theta.len() != self.space.len() {
            return Err(InverseError::WrongStartLength {
                expected: self.space.len(),
                got: theta.len(),
            });
        }
        self.free
            .iter()
            .map(|&k| {
                let p = &self.space.params[k];
                let x = theta[k];
                let z = p.to_unbounded(x);
                if p.contains(x) && z.is_finite() {
                    Ok(z)
                } else {
                    Err(InverseError::OutOfBounds {
                        name: p.name.clone(),
                        value: x,
                        lower: p.lower,
                        upper: p.upper,
                    })
                }
            })
            .collect()
    }

    /// The starting vector: the space's initial values with fixed values in place.
    pub fn initial_theta(&self) -> Vec<f64> {
        self.space
            .params
            .iter()
            .zip(&self.fixed)
            .map(|(p, f)| f.unwrap_or(p.initial))
            .collect()
    }

    /// One evaluator per set, for one thread.
    pub fn evaluators(&self) -> Evaluators<'_> {
        self.sets.iter().map(|s| s.model.evaluator()).collect()
    }

    /// Predictions of every set at the full physical vector `theta`.
    pub fn predict(
        &self,
        evaluators: &mut Evaluators<'_>,
        theta: &[f64],
        stage: &'static str,
    ) -> Result<Vec<Vec<f64>>, InverseError> {
        self.sets
            .iter()
            .zip(evaluators.iter_mut())
            .map(|(set, ev)| {
                let mut out = vec![0.0; set.loading.len()];
                ev.predict_into(theta, &set.loading, &mut out)
                    .map_err(|source| InverseError::Forward {
                        set: set.name.clone(),
                        theta: theta.to_vec(),
                        stage,
                        source: Box::new(source),
                    })?;
                Ok(out)
            })
            .collect()
    }

    /// Residuals from the sets' predictions, into `out` (length [`Objective::n_residuals`]).
    pub fn residuals_from_predictions(&self, predictions: &[Vec<f64>], out: &mut [f64]) {
        for (s, set) in self.sets.iter().enumerate() {
            let range = self.residual_range(s);
            for (r, &(i, f)) in out[range].iter_mut().zip(&self.factors[s]) {
                *r = f * (predictions[s][i] - set.observed[i]);
            }
        }
    }

    /// Residuals at free unbounded values `z`.
    pub fn residuals(
        &self,
        evaluators: &mut Evaluators<'_>,
        z: &[f64],
        stage: &'static str,
    ) -> Result<Vec<f64>, InverseError> {
        let theta = self.theta_from_unbounded(z);
        let predictions = self.predict(evaluators, &theta, stage)?;
        let mut r = vec![0.0; self.n_residuals()];
        self.residuals_from_predictions(&predictions, &mut r);
        Ok(r)
    }

    /// Whether every set has exact sensitivities.
    pub fn has_exact_sensitivities(&self) -> bool {
        self.sets.iter().all(|s| s.sensitivities.is_some())
    }
}

/// Sum of squares.
pub fn sum_of_squares(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// The map from free unbounded values to the full physical vector, detached
/// from the data (for observers, which must be `'static`).
#[derive(Debug, Clone)]
pub struct ParamMap {
    space: ParamSpace,
    free: Vec<usize>,
    fixed: Vec<Option<f64>>,
}

impl ParamMap {
    /// The full physical vector from free unbounded values `z`.
    pub fn theta_from_unbounded(&self, z: &[f64]) -> Vec<f64> {
        let mut theta: Vec<f64> = self.fixed.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
        for (&k, &zk) in self.free.iter().zip(z) {
            theta[k] = self.space.params[k].from_unbounded(zk);
        }
        theta
    }
}

impl Objective {
    /// A detached copy of the parameter map.
    pub fn clone_param_map(&self) -> ParamMap {
        ParamMap {
            space: self.space.clone(),
            free: self.free.clone(),
            fixed: self.fixed.clone(),
        }
    }
}
