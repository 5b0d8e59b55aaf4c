//! Named physical parameters with bounds, and the map to the unbounded space
//! that estimators and samplers move in.
//!
//! At every crate boundary parameters are plain `&[f64]` in physical units
//! (MPa, mm, s, dimensionless), in the order of the [`ParamSpace`].

use serde::{Deserialize, Serialize};

/// Map between a bounded physical value `x` and an unbounded value `z`.
///
/// * `Identity`: `x = z` (no bounds).
/// * `LogShift`: `x = lower + exp(z)` (only a lower bound).
/// * `NegLogShift`: `x = upper - exp(z)` (only an upper bound).
/// * `Logit`: `x = lower + (upper - lower) / (1 + exp(-z))` (both bounds).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Transform {
    Identity,
    LogShift,
    NegLogShift,
    Logit,
}

/// What a parameter does in its model, for consumers that treat parameters
/// by kind rather than by name (the gap diagnosis rescales the moduli,
/// starts time constants across the record's duration, orders Prony terms by
/// their time constant). The model that declares the parameter sets it; the
/// default is [`ParamRole::Other`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum ParamRole {
    /// An elastic modulus: the response is proportional to it when it is the
    /// only modulus (e.g. C10 of neo-Hookean under prescribed displacement).
    Modulus,
    /// A dimensionless shape parameter of a law (Ogden alpha, Arruda-Boyce N).
    Shape,
    /// The weight g_i of Prony term `term` (1-based) of a relaxation function.
    RelaxationWeight { term: usize },
    /// The time constant tau_i (s) of Prony term `term` (1-based).
    TimeConstant { term: usize },
    /// A shift of the drive's zero (e.g. the contact point d0).
    Offset,
    /// A compliance that is zero in the stiff limit (1/K, series compliance).
    Compliance,
    /// A friction coefficient.
    Friction,
    /// Anything else.
    #[default]
    Other,
}

/// One named parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamSpec {
    /// Name in the common commercial convention (`C10`, `mu1`, `D1`, `g1`, ...).
    pub name: String,
    /// Unit, e.g. `MPa`, `mm`, `s`, `1`.
    pub unit: String,
    /// Lower bound (may be `-inf`).
    pub lower: f64,
    /// Upper bound (may be `+inf`).
    pub upper: f64,
    /// A sensible starting value inside the bounds.
    pub initial: f64,
    /// What the parameter does in its model.
    #[serde(default, skip_serializing_if = "is_other")]
    pub role: ParamRole,
    /// For the parameter of an effect (`Enrichable`): the range of values it
    /// plausibly takes in practice, narrower than the bounds (e.g. friction
    /// 0 to 0.8 against bounds 0 to 2). The gap diagnosis refits the base
    /// model with the effect held at the ends of this range to show how far
    /// an effect the data cannot see would move the base parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plausible: Option<(f64, f64)>,
}

fn is_other(r: &ParamRole) -> bool {
    *r == ParamRole::Other
}

impl ParamSpec {
    /// A parameter with bounds and a starting value.
    pub fn new(
        name: impl Into<String>,
        unit: impl Into<String>,
        lower: f64,
        upper: f64,
        initial: f64,
    ) -> Self {
        ParamSpec {
            name: name.into(),
            unit: unit.into(),
            lower,
            upper,
            initial,
            role: ParamRole::Other,
            plausible: None,
        }
    }

    /// The same parameter with its role.
    pub fn with_role(mut self, role: ParamRole) -> Self {
        self.role = role;
        self
    }

    /// The same parameter with a plausible range (see [`ParamSpec::plausible`]).
    pub fn with_plausible(mut self, lower: f64, upper: f64) -> Self {
        self.plausible = Some((lower, upper));
        self
    }

    /// Whether the parameter is an elastic modulus.
    pub fn is_modulus(&self) -> bool {
        self.role == ParamRole::Modulus
    }

    /// The transform implied by the bounds.
    pub fn transform(&self) -> Transform {
        match (self.lower.is_finite(), self.upper.is_finite()) {
            (false, false) => Transform::Identity,
            (true, false) => Transform::LogShift,
            (false, true) => Transform::NegLogShift,
            (true, true) => Transform::Logit,
        }
    }

    /// Whether `x` lies inside the closed bounds.
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite() && x >= self.lower && x <= self.upper
    }

    /// Physical -> unbounded. Values on a bound map to +-infinity, so callers
    /// should start strictly inside.
    pub fn to_unbounded(&self, x: f64) -> f64 {
        match self.transform() {
            Transform::Identity => x,
            Transform::LogShift => (x - self.lower).ln(),
            Transform::NegLogShift => (self.upper - x).ln(),
            Transform::Logit => {
                let u = (x - self.lower) / (self.upper - self.lower);
                (u / (1.0 - u)).ln()
            }
        }
    }

    /// Unbounded -> physical.
    pub fn from_unbounded(&self, z: f64) -> f64 {
        match self.transform() {
            Transform::Identity => z,
            Transform::LogShift => self.lower + z.exp(),
            Transform::NegLogShift => self.upper - z.exp(),
            Transform::Logit => self.lower + (self.upper - self.lower) / (1.0 + (-z).exp()),
        }
    }

    /// dx/dz at `z`.
    pub fn dx_dz(&self, z: f64) -> f64 {
        match self.transform() {
            Transform::Identity => 1.0,
            Transform::LogShift => z.exp(),
            Transform::NegLogShift => -z.exp(),
            Transform::Logit => {
                let s = 1.0 / (1.0 + (-z).exp());
                (self.upper - self.lower) * s * (1.0 - s)
            }
        }
    }

    /// log |dx/dz| at `z` (the log-Jacobian a sampler adds to the density).
    pub fn log_abs_dx_dz(&self, z: f64) -> f64 {
        match self.transform() {
            Transform::Identity => 0.0,
            Transform::LogShift | Transform::NegLogShift => z,
            Transform::Logit => {
                // log((u-l) s (1-s)) with s = sigmoid(z), computed stably.
                let softplus = |t: f64| if t > 30.0 { t } else { t.exp().ln_1p() };
                (self.upper - self.lower).ln() - softplus(-z) - softplus(z)
            }
        }
    }
}

/// An ordered list of named parameters.
///
/// ```
/// use palpate_core::{ParamSpace, ParamSpec, Transform};
///
/// let space = ParamSpace::new(vec![
///     ParamSpec::new("C10", "MPa", 0.0, f64::INFINITY, 0.1),
///     ParamSpec::new("g1", "1", 0.0, 1.0, 0.5),
/// ]);
/// assert_eq!(space.names(), ["C10", "g1"]);
/// assert_eq!(space.params[0].transform(), Transform::LogShift);
/// // Estimators move in the unbounded space: C10 = exp(z0), g1 = logistic(z1).
/// let z = space.to_unbounded(&[1.0, 0.5]);
/// assert_eq!(z, [0.0, 0.0]);
/// assert_eq!(space.from_unbounded(&[0.0, 0.0]), [1.0, 0.5]);
/// // Checks name the first offender.
/// let err = space.check(&[0.1, 1.5]).unwrap_err();
/// assert!(err.to_string().contains("g1"), "{err}");
/// assert!(space.check(&[0.1]).is_err());
/// ```
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ParamSpace {
    pub params: Vec<ParamSpec>,
}

impl ParamSpace {
    /// A space from its parameters.
    pub fn new(params: Vec<ParamSpec>) -> Self {
        ParamSpace { params }
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// True when there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// Parameter names in order.
    pub fn names(&self) -> Vec<String> {
        self.params.iter().map(|p| p.name.clone()).collect()
    }

    /// Index of a parameter by name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.params.iter().position(|p| p.name == name)
    }

    /// Starting values.
    pub fn initial(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.initial).collect()
    }

    /// Appends the parameters of another space (used by enrichments).
    pub fn extended(&self, more: &[ParamSpec]) -> ParamSpace {
        let mut params = self.params.clone();
        params.extend_from_slice(more);
        ParamSpace { params }
    }

    /// Physical -> unbounded, element-wise.
    pub fn to_unbounded(&self, x: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(x)
            .map(|(p, &v)| p.to_unbounded(v))
            .collect()
    }

    /// Unbounded -> physical, element-wise.
    pub fn from_unbounded(&self, z: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(z)
            .map(|(p, &v)| p.from_unbounded(v))
            .collect()
    }

    /// Sum of log |dx/dz| (log-Jacobian of the whole map).
    pub fn log_jacobian(&self, z: &[f64]) -> f64 {
        self.params
            .iter()
            .zip(z)
            .map(|(p, &v)| p.log_abs_dx_dz(v))
            .sum()
    }

    /// Checks the length and the bounds; the error names the first offender.
    pub fn check(&self, x: &[f64]) -> Result<(), crate::ForwardError> {
        if x.len() != self.params.len() {
            return Err(crate::ForwardError::WrongParameterCount {
                expected: self.params.len(),
                got: x.len(),
            });
        }
        for (p, &v) in self.params.iter().zip(x) {
            if !p.contains(v) {
                return Err(crate::ForwardError::InvalidParameter {
                    name: p.name.clone(),
                    value: v,
                    reason: format!("outside [{}, {}] {}", p.lower, p.upper, p.unit),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn specs() -> Vec<ParamSpec> {
        vec![
            ParamSpec::new("a", "1", f64::NEG_INFINITY, f64::INFINITY, 0.3),
            ParamSpec::new("b", "MPa", 0.0, f64::INFINITY, 2.0),
            ParamSpec::new("c", "1", f64::NEG_INFINITY, 1.0, 0.5),
            ParamSpec::new("d", "1", 0.0, 1.0, 0.25),
        ]
    }

    #[test]
    fn round_trip_and_jacobian_match_finite_differences() {
        for p in specs() {
            let z = p.to_unbounded(p.initial);
            assert!(
                (p.from_unbounded(z) - p.initial).abs() < 1e-14,
                "{}",
                p.name
            );
            let h = 1e-6;
            let fd = (p.from_unbounded(z + h) - p.from_unbounded(z - h)) / (2.0 * h);
            assert!((fd - p.dx_dz(z)).abs() < 1e-8, "{}", p.name);
            assert!(
                (p.dx_dz(z).abs().ln() - p.log_abs_dx_dz(z)).abs() < 1e-12,
                "{}",
                p.name
            );
        }
    }

    #[test]
    fn check_names_the_offender() {
        let s = ParamSpace::new(specs());
        let err = s.check(&[0.0, -1.0, 0.0, 0.5]).unwrap_err();
        assert!(err.to_string().contains("`b`"), "{err}");
        assert!(s.check(&[0.0, 1.0]).is_err());
        assert!(s.check(&[0.0, 1.0, 0.0, 0.5]).is_ok());
    }
}
