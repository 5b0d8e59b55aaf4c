//! What a fit reports.

use crate::{Identifiability, ResidualKind, Termination};
use serde::Serialize;

/// Which bound a parameter sits on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundSide {
    Lower,
    Upper,
}

/// One parameter of the fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterEstimate {
    pub name: String,
    pub unit: String,
    /// Estimate in physical units.
    pub value: f64,
    /// Standard error in physical units (delta method through `dx/dz` at the
    /// optimum), `None` when fixed, on a bound, or not identifiable.
    pub standard_error: Option<f64>,
    /// Held fixed at `value`.
    pub fixed: bool,
    /// Set when the estimate sits on a bound (within 1e-6 of the initial
    /// value's distance to it); its standard error is then not given.
    pub at_bound: Option<BoundSide>,
    pub lower: f64,
    pub upper: f64,
}

/// One data set at the optimum.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SetReport {
    pub name: String,
    pub model: String,
    pub weight: f64,
    pub samples: usize,
    /// Sum of squared objective residuals of the set (weighted, per the residual kind).
    pub sse: f64,
    /// Raw (absolute, unweighted) sum of squares `sum (f_i - y_i)^2`.
    pub sse_absolute: f64,
    /// Raw RMS error `sqrt(sse_absolute / n)` in the observable's unit.
    pub rms_absolute: f64,
    /// `1 - SS_res / SS_tot` in raw units, `SS_tot = sum (y_i - mean y)^2`.
    pub r_squared: f64,
    pub observed: Vec<f64>,
    pub predicted: Vec<f64>,
    /// Objective residuals of the kept samples, in order (see `kept`).
    pub residuals: Vec<f64>,
    /// Sample indices that have a residual (all but zero observations for
    /// relative residuals).
    pub kept: Vec<usize>,
}

/// The result of a fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitReport {
    pub method: String,
    pub residual: ResidualKind,
    /// Every parameter of the space, free and fixed, in order.
    pub parameters: Vec<ParameterEstimate>,
    /// Names of the free parameters (rows/columns of `correlation`).
    pub free: Vec<String>,
    /// Correlation matrix of the free parameters (NaN, i.e. JSON null, where undefined).
    pub correlation: Vec<Vec<f64>>,
    /// `sigma^2 = SSE / (n - p)`.
    pub sigma2: Option<f64>,
    /// Objective value `sum r_i^2`.
    pub sse: f64,
    /// `sqrt(SSE / n)` over the objective residuals.
    pub rms: f64,
    /// Pooled `1 - sum_sets SS_res / sum_sets SS_tot` in raw units (each set
    /// about its own mean); meaningful when the sets share a unit.
    pub r_squared: f64,
    pub n_residuals: usize,
    pub iterations: u64,
    /// Objective evaluations (one prediction per set each), finite-difference
    /// ones and those of every start included.
    pub evaluations: usize,
    pub jacobians: usize,
    pub termination: Termination,
    pub converged: bool,
    /// Starts tried, the index of the best, and starts whose run failed.
    pub starts: usize,
    pub best_start: usize,
    pub failed_starts: usize,
    pub sets: Vec<SetReport>,
    pub identifiability: Identifiability,
    /// The optimum lies against an admissibility limit of the model that is
    /// not a box bound (Mooney-Rivlin's `C10 + C01 > 0`): the Gauss-Newton
    /// step from it reaches parameters the model refuses, so the fit stopped
    /// on that limit rather than at a minimum. Standard errors, correlations
    /// and `identifiability` assume an interior minimum and do not describe
    /// such a fit. Serialised only when set.
    #[serde(skip_serializing_if = "is_false")]
    pub on_limit: bool,
}

fn is_false(b: &bool) -> bool {
    !*b
}

impl FitReport {
    /// A parameter by name.
    pub fn parameter(&self, name: &str) -> Option<&ParameterEstimate> {
        self.parameters.iter().find(|p| p.name == name)
    }

    /// A parameter's value by name.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.parameter(name).map(|p| p.value)
    }

    /// A parameter's standard error by name.
    pub fn standard_error(&self, name: &str) -> Option<f64> {
        self.parameter(name).and_then(|p| p.standard_error)
    }

    /// The full physical parameter vector.
    pub fn theta(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// What holds the optimum other than the data, one phrase each: the
    /// model's admissibility limit ([`FitReport::on_limit`]) and every
    /// parameter on a bound of its range. Empty for an interior optimum.
    pub fn constraints(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.on_limit {
            out.push("stopped on an admissibility limit of the model".to_string());
        }
        for p in &self.parameters {
            match p.at_bound {
                Some(BoundSide::Lower) => out.push(format!("{} on its lower bound", p.name)),
                Some(BoundSide::Upper) => out.push(format!("{} on its upper bound", p.name)),
                None => {}
            }
        }
        out
    }

    /// Whether the data alone determine the optimum: identifiable
    /// parameters at an interior minimum (no [`FitReport::constraints`]).
    pub fn determined(&self) -> bool {
        self.identifiability.identifiable && self.constraints().is_empty()
    }
}
