//! The volumetric (bulk) part of the strain energy.

use serde::{Deserialize, Serialize};

use crate::MaterialError;

/// Volumetric energy `U(J)` added to the isochoric energy.
///
/// Abaqus convention (Abaqus Theory Manual, "Hyperelastic material behavior"):
/// `U = (J - 1)^2 / D1`, so that the initial bulk modulus is `K = 2 / D1`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Volumetric {
    /// `U = 0`: isochoric part only, for mixed u-p or exact-constraint formulations.
    Incompressible,
    /// `U = (J - 1)^2 / D1` with `D1` in 1/MPa; `K = 2 / D1`.
    D1(f64),
}

impl Volumetric {
    /// Checks that `D1` is finite and positive.
    pub fn check(&self) -> Result<(), MaterialError> {
        match *self {
            Volumetric::Incompressible => Ok(()),
            Volumetric::D1(d1) if !d1.is_finite() => Err(MaterialError::NotFinite {
                name: "D1".into(),
                value: d1,
            }),
            Volumetric::D1(d1) if d1 <= 0.0 => Err(MaterialError::OutOfRange {
                name: "D1".into(),
                value: d1,
                requirement: "must be > 0 (use Volumetric::Incompressible for the limit D1 -> 0)"
                    .into(),
            }),
            Volumetric::D1(_) => Ok(()),
        }
    }

    /// The volumetric energy `U(J) = (J - 1)^2 / D1` (0 when incompressible).
    pub fn u(&self, j: f64) -> f64 {
        match *self {
            Volumetric::Incompressible => 0.0,
            Volumetric::D1(d1) => (j - 1.0) * (j - 1.0) / d1,
        }
    }

    /// `dU/dJ = 2 (J - 1) / D1` (0 when incompressible).
    pub fn du(&self, j: f64) -> f64 {
        match *self {
            Volumetric::Incompressible => 0.0,
            Volumetric::D1(d1) => 2.0 * (j - 1.0) / d1,
        }
    }

    /// `d2U/dJ2 = 2 / D1` (0 when incompressible).
    pub fn d2u(&self, _j: f64) -> f64 {
        match *self {
            Volumetric::Incompressible => 0.0,
            Volumetric::D1(d1) => 2.0 / d1,
        }
    }

    /// Initial bulk modulus `K = 2 / D1` (infinite when incompressible).
    pub fn bulk_modulus(&self) -> f64 {
        match *self {
            Volumetric::Incompressible => f64::INFINITY,
            Volumetric::D1(d1) => 2.0 / d1,
        }
    }

    /// The `D1` giving bulk modulus `k` (`D1 = 2 / K`), e.g. `K = 1000 mu0` for "incompressible" FE models.
    pub fn from_bulk_modulus(k: f64) -> Volumetric {
        Volumetric::D1(2.0 / k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        let v = Volumetric::D1(0.05);
        for j in [0.7, 1.0, 1.3] {
            let h = 1e-6;
            let du = (v.u(j + h) - v.u(j - h)) / (2.0 * h);
            let d2u = (v.du(j + h) - v.du(j - h)) / (2.0 * h);
            assert!((du - v.du(j)).abs() < 1e-7, "{du} vs {}", v.du(j));
            assert!((d2u - v.d2u(j)).abs() < 1e-6);
        }
        assert_eq!(v.bulk_modulus(), 40.0);
        assert_eq!(Volumetric::from_bulk_modulus(40.0), v);
        assert_eq!(Volumetric::Incompressible.bulk_modulus(), f64::INFINITY);
    }

    #[test]
    fn bad_d1_is_named() {
        for d1 in [0.0, -1.0, f64::NAN] {
            let err = Volumetric::D1(d1).check().unwrap_err();
            assert!(err.to_string().contains("D1"), "{err}");
        }
        assert!(Volumetric::Incompressible.check().is_ok());
    }
}
