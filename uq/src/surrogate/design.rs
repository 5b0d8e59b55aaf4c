//! The parameter box a surrogate is trained in, and its space-filling design.
//!
//! The design is the Halton sequence (bases 2, 3, 5, ...; Halton 1960,
//! *Numer. Math.* 2, 84-90), scaled into the box: a low-discrepancy set whose
//! first n points cover the box evenly for any n, and whose next points
//! (`start = n`) are fresh, so held-out validation runs continue the same
//! sequence without repeating a training point.

use super::SurrogateError;
use palpate_core::{ParamSpace, ParamSpec};
use serde::{Deserialize, Serialize};

/// Named lower and upper bounds of every parameter (physical units): the
/// region a surrogate is trained in and answers for. Outside it a surrogate
/// refuses ([`ParamBox::check`]) instead of extrapolating.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamBox {
    pub names: Vec<String>,
    pub units: Vec<String>,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
}

impl ParamBox {
    /// The box `[lower, upper]` of the parameters of `space` (in its order).
    /// Every bound must be finite with lower < upper, and inside the model's
    /// own bounds; the error names the parameter.
    pub fn new(space: &ParamSpace, lower: &[f64], upper: &[f64]) -> Result<Self, SurrogateError> {
        let d = space.len();
        if lower.len() != d || upper.len() != d {
            return Err(SurrogateError::InvalidBox {
                name: space.names().join(", "),
                reason: format!(
                    "{d} parameters but {} lower and {} upper bounds",
                    lower.len(),
                    upper.len()
                ),
            });
        }
        for (p, (&l, &u)) in space.params.iter().zip(lower.iter().zip(upper)) {
            let bad = |reason: String| SurrogateError::InvalidBox {
                name: p.name.clone(),
                reason,
            };
            if !(l.is_finite() && u.is_finite() && l < u) {
                return Err(bad(format!(
                    "[{l}, {u}] {}: need finite bounds with lower < upper",
                    p.unit
                )));
            }
            if l < p.lower || u > p.upper {
                return Err(bad(format!(
                    "[{l}, {u}] {} leaves the model's bounds [{}, {}]",
                    p.unit, p.lower, p.upper
                )));
            }
        }
        Ok(ParamBox {
            names: space.names(),
            units: space.params.iter().map(|p| p.unit.clone()).collect(),
            lower: lower.to_vec(),
            upper: upper.to_vec(),
        })
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.lower.len()
    }

    /// True for a box of no parameters.
    pub fn is_empty(&self) -> bool {
        self.lower.is_empty()
    }

    /// The box as a parameter space (bounds = the box, start = its centre):
    /// what a sampler on the surrogate moves in.
    pub fn space(&self) -> ParamSpace {
        ParamSpace::new(
            (0..self.len())
                .map(|k| {
                    ParamSpec::new(
                        self.names[k].clone(),
                        self.units[k].clone(),
                        self.lower[k],
                        self.upper[k],
                        0.5 * (self.lower[k] + self.upper[k]),
                    )
                })
                .collect(),
        )
    }

    /// Ok when `theta` has one value per parameter, each inside the box;
    /// otherwise [`SurrogateError::OutsideBox`] naming the first parameter
    /// that leaves it.
    pub fn check(&self, theta: &[f64]) -> Result<(), SurrogateError> {
        if theta.len() != self.len() {
            return Err(SurrogateError::OutsideBox {
                name: format!("({} values for {} parameters)", theta.len(), self.len()),
                value: f64::NAN,
                lower: f64::NAN,
                upper: f64::NAN,
            });
        }
        for (k, &v) in theta.iter().enumerate() {
            if !(v >= self.lower[k] && v <= self.upper[k]) {
                return Err(SurrogateError::OutsideBox {
                    name: self.names[k].clone(),
                    value: v,
                    lower: self.lower[k],
                    upper: self.upper[k],
                });
            }
        }
        Ok(())
    }

    /// Physical -> unit cube [0, 1]^d.
    pub fn to_unit(&self, theta: &[f64]) -> Vec<f64> {
        theta
            .iter()
            .zip(self.lower.iter().zip(&self.upper))
            .map(|(x, (l, u))| (x - l) / (u - l))
            .collect()
    }

    /// Points `start..start + n` of the Halton sequence in the box.
    pub fn halton(&self, start: usize, n: usize) -> Vec<Vec<f64>> {
        halton_design(&self.lower, &self.upper, start, n)
    }
}

/// Points `start..start + n` of the Halton sequence (bases 2, 3, 5, ...)
/// scaled into the box `[lower, upper]`.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn space() -> ParamSpace {
        ParamSpace::new(vec![
            ParamSpec::new("C10", "MPa", 0.0, f64::INFINITY, 1e-3),
            ParamSpec::new("g1", "1", 0.0, 1.0, 0.3),
        ])
    }

    #[test]
    fn the_box_names_what_is_wrong_and_what_leaves_it() {
        let b = ParamBox::new(&space(), &[1e-3, 0.1], &[2e-3, 0.5]).unwrap();
        assert!(b.check(&[1.5e-3, 0.1]).is_ok());
        let e = b.check(&[2.5e-3, 0.2]).unwrap_err().to_string();
        assert!(
            e.contains("C10") && e.contains("0.0025") && e.contains("0.002"),
            "{e}"
        );
        let e = ParamBox::new(&space(), &[1e-3, 0.1], &[2e-3, 1.5])
            .unwrap_err()
            .to_string();
        assert!(e.contains("g1") && e.contains("model's bounds"), "{e}");
        let e = ParamBox::new(&space(), &[2e-3, 0.1], &[1e-3, 0.5])
            .unwrap_err()
            .to_string();
        assert!(e.contains("C10") && e.contains("lower < upper"), "{e}");
    }

    /// The first 16 points of base 2 in 1D are the dyadic fractions: every
    /// interval [k/16, (k+1)/16) holds exactly one.
    #[test]
    fn halton_fills_the_box_evenly() {
        let p = halton_design(&[0.0], &[1.0], 0, 15);
        let mut cells = [0; 16];
        for x in &p {
            cells[(x[0] * 16.0) as usize] += 1;
        }
        assert_eq!(cells.iter().filter(|&&c| c == 1).count(), 15);
        let more = halton_design(&[0.0], &[1.0], 15, 1);
        assert!(p.iter().all(|x| x[0] != more[0][0]));
    }
}
