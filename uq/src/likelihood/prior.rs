//! Priors on one physical parameter.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

const LN_SQRT_2PI: f64 = 0.918_938_533_204_672_8;

/// A prior density on a physical parameter value x.
///
/// * `Flat`: p(x) ∝ 1 inside the parameter's bounds (improper when a bound is infinite).
/// * `Uniform { lower, upper }`: 1 / (upper - lower) on [lower, upper].
/// * `Normal { mean, sd }`: N(mean, sd^2).
/// * `LogNormal { mu, sigma }`: ln x ~ N(mu, sigma^2), x > 0.
/// * `HalfNormal { sd }`: 2 N(x; 0, sd^2) for x >= 0.
/// * `LogUniform { lower, upper }`: 1 / (x ln(upper / lower)) on
///   [lower, upper], 0 < lower < upper (uniform in ln x: a scale known
///   only to its order of magnitude).
///
/// Spelled in the CLI and manifests as `flat`, `uniform:L,U`, `normal:M,S`,
/// `lognormal:MU,SIGMA`, `halfnormal:S`, `loguniform:L,U`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Prior {
    Flat,
    Uniform { lower: f64, upper: f64 },
    Normal { mean: f64, sd: f64 },
    LogNormal { mu: f64, sigma: f64 },
    HalfNormal { sd: f64 },
    LogUniform { lower: f64, upper: f64 },
}

impl Prior {
    /// log p(x), normalised (0 for `Flat`); `-inf` outside the support.
    pub fn log_density(&self, x: f64) -> f64 {
        match *self {
            Prior::Flat => 0.0,
            Prior::Uniform { lower, upper } => {
                if x >= lower && x <= upper {
                    -(upper - lower).ln()
                } else {
                    f64::NEG_INFINITY
                }
            }
            Prior::Normal { mean, sd } => {
                let u = (x - mean) / sd;
                -0.5 * u * u - sd.ln() - LN_SQRT_2PI
            }
            Prior::LogNormal { mu, sigma } => {
                if x <= 0.0 {
                    return f64::NEG_INFINITY;
                }
                let u = (x.ln() - mu) / sigma;
                -0.5 * u * u - sigma.ln() - LN_SQRT_2PI - x.ln()
            }
            Prior::HalfNormal { sd } => {
                if x < 0.0 {
                    return f64::NEG_INFINITY;
                }
                let u = x / sd;
                -0.5 * u * u - sd.ln() - LN_SQRT_2PI + std::f64::consts::LN_2
            }
            Prior::LogUniform { lower, upper } => {
                if x >= lower && x <= upper {
                    -x.ln() - (upper / lower).ln().ln()
                } else {
                    f64::NEG_INFINITY
                }
            }
        }
    }

    /// d log p / dx inside the support (0 for `Flat` and `Uniform`).
    pub fn d_log_density(&self, x: f64) -> f64 {
        match *self {
            Prior::Flat | Prior::Uniform { .. } => 0.0,
            Prior::Normal { mean, sd } => -(x - mean) / (sd * sd),
            Prior::LogNormal { mu, sigma } => -(x.ln() - mu) / (sigma * sigma * x) - 1.0 / x,
            Prior::HalfNormal { sd } => -x / (sd * sd),
            Prior::LogUniform { .. } => -1.0 / x,
        }
    }

    /// Whether the prior integrates to one (needed for a meaningful evidence).
    pub fn is_proper(&self) -> bool {
        !matches!(self, Prior::Flat)
    }

    /// The support `[lo, hi]` (`Flat` and `Normal`: the real line).
    pub fn support(&self) -> (f64, f64) {
        match *self {
            Prior::Flat | Prior::Normal { .. } => (f64::NEG_INFINITY, f64::INFINITY),
            Prior::Uniform { lower, upper } | Prior::LogUniform { lower, upper } => (lower, upper),
            Prior::LogNormal { .. } | Prior::HalfNormal { .. } => (0.0, f64::INFINITY),
        }
    }

    /// `x` if the density is positive there, else the point a thousandth
    /// of the support's width (or of |x|, at least 1e-12) inside its
    /// nearest end.
    pub fn nearest_inside(&self, x: f64) -> f64 {
        let (lo, hi) = self.support();
        let inside = self.log_density(x).is_finite();
        if inside {
            return x;
        }
        let w = if (hi - lo).is_finite() {
            1e-3 * (hi - lo)
        } else {
            (1e-3 * x.abs()).max(1e-12)
        };
        if x <= lo {
            lo + w
        } else if x >= hi {
            hi - w
        } else {
            x
        }
    }

    /// Checks the prior's own numbers, saying which one is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let finite = |name: &str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(format!(
                    "invalid prior {self}: the {name} must be a finite number"
                ))
            }
        };
        let width = |name: &str, v: f64| {
            finite(name, v)?;
            if v > 0.0 {
                Ok(())
            } else {
                Err(format!("invalid prior {self}: the {name} must be positive"))
            }
        };
        match *self {
            Prior::Flat => Ok(()),
            Prior::Uniform { lower, upper } => {
                finite("lower end", lower)?;
                finite("upper end", upper)?;
                if upper > lower {
                    Ok(())
                } else {
                    Err(format!(
                        "invalid prior {self}: the upper end must exceed the lower end (uniform:L,U with L < U)"
                    ))
                }
            }
            Prior::Normal { mean, sd } => {
                finite("mean", mean)?;
                width("standard deviation", sd)
            }
            Prior::LogNormal { mu, sigma } => {
                finite("log-mean mu", mu)?;
                width("log-standard deviation sigma", sigma)
            }
            Prior::HalfNormal { sd } => width("scale", sd),
            Prior::LogUniform { lower, upper } => {
                width("lower end", lower)?;
                finite("upper end", upper)?;
                if upper > lower {
                    Ok(())
                } else {
                    Err(format!(
                        "invalid prior {self}: the upper end must exceed the lower end (loguniform:L,U with 0 < L < U)"
                    ))
                }
            }
        }
    }
}

impl fmt::Display for Prior {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Prior::Flat => write!(f, "flat"),
            Prior::Uniform { lower, upper } => write!(f, "uniform:{lower},{upper}"),
            Prior::Normal { mean, sd } => write!(f, "normal:{mean},{sd}"),
            Prior::LogNormal { mu, sigma } => write!(f, "lognormal:{mu},{sigma}"),
            Prior::HalfNormal { sd } => write!(f, "halfnormal:{sd}"),
            Prior::LogUniform { lower, upper } => write!(f, "loguniform:{lower},{upper}"),
        }
    }
}

impl FromStr for Prior {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (kind, args) = s.split_once(':').unwrap_or((s, ""));
        let nums: Vec<f64> = if args.is_empty() {
            Vec::new()
        } else {
            args.split(',')
                .map(|a| {
                    a.trim()
                        .parse::<f64>()
                        .map_err(|_| format!("prior `{s}`: `{a}` is not a number"))
                })
                .collect::<Result<_, _>>()?
        };
        let need = |n: usize| {
            if nums.len() == n {
                Ok(())
            } else {
                Err(format!(
                    "prior `{s}`: `{kind}` takes {n} number{}, got {}",
                    if n == 1 { "" } else { "s" },
                    nums.len()
                ))
            }
        };
        let p = match kind.trim().to_ascii_lowercase().as_str() {
            "flat" => {
                need(0)?;
                Prior::Flat
            }
            "uniform" => {
                need(2)?;
                Prior::Uniform { lower: nums[0], upper: nums[1] }
            }
            "normal" => {
                need(2)?;
                Prior::Normal { mean: nums[0], sd: nums[1] }
            }
            "lognormal" | "log-normal" => {
                need(2)?;
                Prior::LogNormal { mu: nums[0], sigma: nums[1] }
            }
            "halfnormal" | "half-normal" => {
                need(1)?;
                Prior::HalfNormal { sd: nums[0] }
            }
            "loguniform" | "log-uniform" => {
                need(2)?;
                Prior::LogUniform { lower: nums[0], upper: nums[1] }
            }
            other => {
                return Err(format!(
                    "unknown prior `{other}`; expected flat, uniform:L,U, normal:M,S, lognormal:MU,SIGMA, halfnormal:S or loguniform:L,U"
                ))
            }
        };
        p.validate()?;
        Ok(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Trapezoidal integral of exp(log p) over [a, b].
    fn integral(p: Prior, a: f64, b: f64) -> f64 {
        let n = 200_000;
        let h = (b - a) / n as f64;
        (0..=n)
            .map(|i| {
                let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                w * p.log_density(a + i as f64 * h).exp()
            })
            .sum::<f64>()
            * h
    }

    #[test]
    fn proper_priors_integrate_to_one() {
        for (p, a, b) in [
            (
                Prior::Uniform {
                    lower: 1.0,
                    upper: 3.0,
                },
                0.0,
                4.0,
            ),
            (Prior::Normal { mean: 1.0, sd: 0.5 }, -5.0, 7.0),
            (
                Prior::LogNormal {
                    mu: 0.2,
                    sigma: 0.4,
                },
                1e-9,
                20.0,
            ),
            (Prior::HalfNormal { sd: 2.0 }, 0.0, 30.0),
            (
                Prior::LogUniform {
                    lower: 0.5,
                    upper: 2.0,
                },
                0.0,
                3.0,
            ),
        ] {
            let i = integral(p, a, b);
            assert!((i - 1.0).abs() < 2e-4, "{p}: {i}");
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for (p, x) in [
            (Prior::Normal { mean: 1.0, sd: 0.5 }, 0.3),
            (
                Prior::LogNormal {
                    mu: 0.2,
                    sigma: 0.4,
                },
                1.7,
            ),
            (Prior::HalfNormal { sd: 2.0 }, 0.9),
            (
                Prior::LogUniform {
                    lower: 1e-4,
                    upper: 0.2,
                },
                0.03,
            ),
            (
                Prior::Uniform {
                    lower: 0.0,
                    upper: 2.0,
                },
                1.0,
            ),
        ] {
            let h = 1e-6;
            let fd = (p.log_density(x + h) - p.log_density(x - h)) / (2.0 * h);
            assert!(
                (fd - p.d_log_density(x)).abs() < 1e-6 * fd.abs().max(1.0),
                "{p}"
            );
        }
    }

    #[test]
    fn parses_and_rejects() {
        for s in [
            "flat",
            "uniform:0,1",
            "normal:1e-3,2e-4",
            "lognormal:-7,0.5",
            "halfnormal:0.1",
            "loguniform:1e-4,0.2",
        ] {
            let p: Prior = s.parse().unwrap();
            assert_eq!(p.to_string().parse::<Prior>().unwrap(), p);
        }
        assert!("normal:1"
            .parse::<Prior>()
            .unwrap_err()
            .contains("2 numbers"));
        assert!("normal:1,-1".parse::<Prior>().is_err());
        assert!("loguniform:0,1"
            .parse::<Prior>()
            .unwrap_err()
            .contains("lower end must be positive"));
        assert!("loguniform:2,1"
            .parse::<Prior>()
            .unwrap_err()
            .contains("0 < L < U"));
        assert!("gamma:1,1"
            .parse::<Prior>()
            .unwrap_err()
            .contains("unknown prior"));
    }
}
