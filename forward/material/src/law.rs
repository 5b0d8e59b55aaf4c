//! The catalogue of hyperelastic laws: naming, parameters, checks and dispatch.

use std::fmt;
use std::str::FromStr;

use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

use crate::invariants::invariants;
use crate::{
    arruda_boyce, gent, humphrey, invariant_kinematics, kinematics, mooney_rivlin, neo_hookean,
    ogden, reduced_polynomial, veronda_westmann, InvariantDerivs, MaterialError, PrincipalDerivs,
    StressTangent, Volumetric,
};

/// Highest order of the reduced polynomial law.
pub const MAX_POLYNOMIAL_ORDER: usize = 6;
/// The most Ogden terms accepted: each term has its own start exponent
/// (2, -2, 4, -4, 6, -6), and more terms than data can identify only make a
/// fit fail later on an internal start value or an allocation.
pub const MAX_OGDEN_TERMS: usize = 6;

/// An isotropic hyperelastic law with an isochoric energy `W` (Abaqus conventions, see each module).
///
/// Parameters are a plain slice in the order of [`Law::params`]:
/// * `NeoHookean`: `[C10]`
/// * `MooneyRivlin`: `[C10, C01]`
/// * `ReducedPolynomial(N)`: `[C10, C20, .., CN0]` (Yeoh is `N = 3`)
/// * `ArrudaBoyce`: `[mu, lambda_m]`
/// * `Ogden(N)`: `[mu1, alpha1, .., muN, alphaN]`
/// * `Gent`: `[mu, Jm]`
/// * `VerondaWestmann`: `[C1, C2]`
/// * `Humphrey`: `[C1, C2]`
///
/// The evaluation functions ([`Law::isochoric_energy`], [`Law::stress_tangent`], ...) assume the
/// parameters passed [`Law::check`]; they never panic, a wrong count gives NaN.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Law {
    /// `W = C10 (I1b - 3)`.
    NeoHookean,
    /// `W = C10 (I1b - 3) + C01 (I2b - 3)`.
    MooneyRivlin,
    /// `W = sum_{i=1..N} Ci0 (I1b - 3)^i`, `N = 1..=6`.
    ReducedPolynomial(usize),
    /// 5-term Arruda-Boyce series.
    ArrudaBoyce,
    /// `W = sum_{i=1..N} 2 mu_i / alpha_i^2 (l1^a_i + l2^a_i + l3^a_i - 3)`, `N = 1..=6` ([`MAX_OGDEN_TERMS`]).
    Ogden(usize),
    /// `W = -(mu Jm / 2) ln(1 - (I1b - 3) / Jm)` (Gent 1996; [`crate::gent`]).
    Gent,
    /// `W = C1 (exp(C2 (I1b - 3)) - 1) - (C1 C2 / 2) (I2b - 3)` (Veronda & Westmann 1970;
    /// [`crate::veronda_westmann`]).
    VerondaWestmann,
    /// `W = C1 (exp(C2 (I1b - 3)) - 1)` (Humphrey & Yin 1987; [`crate::humphrey`]).
    Humphrey,
}

/// One material parameter with its unit, search bounds and a starting value for soft silicone/tissue.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialParam {
    /// Name in the commercial convention (`C10`, `C01`, `C20`, `mu`, `lambda_m`, `mu1`, `alpha1`, ...).
    pub name: String,
    /// `"MPa"` or `"1"`.
    pub unit: &'static str,
    /// Lower bound (may be `-inf`).
    pub lower: f64,
    /// Upper bound (may be `+inf`).
    pub upper: f64,
    /// Starting value inside the bounds.
    pub initial: f64,
    /// Whether the strain energy is linear in this parameter (a modulus: C_ij, mu, mu_i; every
    /// parameter in MPa), as opposed to a shape parameter (`lambda_m`, `alpha_i`).
    pub modulus: bool,
}

impl MaterialParam {
    fn new(
        name: impl Into<String>,
        unit: &'static str,
        lower: f64,
        upper: f64,
        initial: f64,
    ) -> Self {
        MaterialParam {
            name: name.into(),
            unit,
            lower,
            upper,
            initial,
            modulus: unit == "MPa",
        }
    }
}

/// Bound on every Ogden exponent: `alpha_i` in `(-OGDEN_ALPHA_BOUND, OGDEN_ALPHA_BOUND)`.
///
/// A box for the estimators, not a material limit. 50 leaves the one-term fits of brain tissue
/// (optima at alpha -17.5 to -25.9, Budday et al. 2017 data, `docs/validation/real-data.md`)
/// interior; where an exponent is not identifiable (Treloar uniaxial Ogden-3, a term with
/// mu -> 0) the fit ends on this bound and the report says so.
pub const OGDEN_ALPHA_BOUND: f64 = 50.0;

/// Bound on the exponent `C2` of the Veronda-Westmann and Humphrey laws: `C2` in `(0, 50)`.
///
/// A box for the estimators, not a material limit: the silicone phantoms of Dawood et al. 2026
/// have `C2` of 0.1 to 0.4. Beyond `C2 (I1 - 3) ~ 709` the exponential overflows, which
/// [`Law::check_stretches`] names.
pub const EXPONENT_BOUND: f64 = 50.0;

/// Upper bound of Gent's `Jm` for the estimators (`Jm -> inf` is neo-Hookean).
pub const GENT_JM_BOUND: f64 = 1e4;

/// Starting exponents of the Ogden terms: alternating signs of growing magnitude, so that the terms differ.
const OGDEN_INITIAL_ALPHA: [f64; 6] = [2.0, -2.0, 4.0, -4.0, 6.0, -6.0];

fn par(p: &[f64], i: usize) -> f64 {
    p.get(i).copied().unwrap_or(f64::NAN)
}

fn positive(name: &str, value: f64, requirement: &str) -> Result<(), MaterialError> {
    if value > 0.0 {
        Ok(())
    } else {
        Err(MaterialError::OutOfRange {
            name: name.into(),
            value,
            requirement: requirement.into(),
        })
    }
}

impl Law {
    /// The parameters, in the order the evaluation functions expect them.
    ///
    /// Moduli that must be positive have lower bound 0; higher-order polynomial coefficients and
    /// Mooney-Rivlin's `C10` and `C01` may be negative (their sum may not: [`Law::check`]); `lambda_m` in (1, 100); Ogden `alpha_i` in (-[`OGDEN_ALPHA_BOUND`], [`OGDEN_ALPHA_BOUND`]) = (-50, 50), `mu_i` of either sign.
    pub fn params(&self) -> Vec<MaterialParam> {
        let inf = f64::INFINITY;
        match *self {
            Law::NeoHookean => vec![MaterialParam::new("C10", "MPa", 0.0, inf, 1e-3)],
            // Each of C10 and C01 may be negative: the law's own condition
            // is C10 + C01 > 0 (Law::check), which the estimators keep by
            // rejecting a step outside it, not a box bound on C10.
            Law::MooneyRivlin => vec![
                MaterialParam::new("C10", "MPa", -inf, inf, 1e-3),
                MaterialParam::new("C01", "MPa", -inf, inf, 1e-4),
            ],
            Law::ReducedPolynomial(n) => (1..=n)
                .map(|i| {
                    if i == 1 {
                        MaterialParam::new("C10", "MPa", 0.0, inf, 1e-3)
                    } else {
                        MaterialParam::new(format!("C{i}0"), "MPa", -inf, inf, 0.0)
                    }
                })
                .collect(),
            Law::ArrudaBoyce => vec![
                MaterialParam::new("mu", "MPa", 0.0, inf, 2e-3),
                MaterialParam::new("lambda_m", "1", 1.0, 100.0, 3.0),
            ],
            Law::Ogden(n) => (1..=n)
                .flat_map(|i| {
                    let alpha = OGDEN_INITIAL_ALPHA
                        .get(i - 1)
                        .copied()
                        .unwrap_or(2.0 + i as f64);
                    [
                        MaterialParam::new(format!("mu{i}"), "MPa", -inf, inf, 2e-3 / n as f64),
                        MaterialParam::new(
                            format!("alpha{i}"),
                            "1",
                            -OGDEN_ALPHA_BOUND,
                            OGDEN_ALPHA_BOUND,
                            alpha,
                        ),
                    ]
                })
                .collect(),
            Law::Gent => vec![
                MaterialParam::new("mu", "MPa", 0.0, inf, 2e-3),
                MaterialParam::new("Jm", "1", 0.0, GENT_JM_BOUND, 100.0),
            ],
            Law::VerondaWestmann => vec![
                MaterialParam::new("C1", "MPa", 0.0, inf, 1e-2),
                MaterialParam::new("C2", "1", 0.0, EXPONENT_BOUND, 0.2),
            ],
            Law::Humphrey => vec![
                MaterialParam::new("C1", "MPa", 0.0, inf, 5e-3),
                MaterialParam::new("C2", "1", 0.0, EXPONENT_BOUND, 0.2),
            ],
        }
    }

    /// Number of parameters.
    pub fn param_count(&self) -> usize {
        match *self {
            Law::NeoHookean => 1,
            Law::MooneyRivlin => 2,
            Law::ReducedPolynomial(n) => n,
            Law::ArrudaBoyce => 2,
            Law::Ogden(n) => 2 * n,
            Law::Gent | Law::VerondaWestmann | Law::Humphrey => 2,
        }
    }

    /// Checks the law's order, the parameter count, finiteness and the sign rules, naming the culprit.
    ///
    /// Rules: neo-Hookean `C10 > 0`; Mooney-Rivlin `C10 + C01 > 0` (initial shear modulus);
    /// reduced polynomial `C10 > 0` (higher terms any sign); Arruda-Boyce `mu > 0`, `lambda_m > 1`;
    /// Ogden `alpha_i != 0` and `mu0 = sum mu_i > 0`; Gent `mu > 0`, `Jm > 0`; Veronda-Westmann
    /// and Humphrey `C1 > 0`, `C2 > 0`.
    ///
    /// Ogden note: the classical rule `mu_i alpha_i > 0` belongs to Ogden's own convention
    /// `W = sum mu_i / alpha_i (...)`. In the Abaqus convention used here (`2 mu_i / alpha_i^2`) each
    /// term is non-negative exactly when `mu_i > 0` (AM-GM: `sum l_a^alpha >= 3` when `l1 l2 l3 = 1`),
    /// so Ogden's 1972 Treloar fit becomes `mu_3 > 0, alpha_3 = -2`, which `mu_i alpha_i > 0` would
    /// wrongly reject. Single negative `mu_i` are allowed (common in fits); use
    /// [`crate::stability::drucker`] to see where such a fit stays stable.
    pub fn check(&self, p: &[f64]) -> Result<(), MaterialError> {
        match *self {
            Law::ReducedPolynomial(n) if !(1..=MAX_POLYNOMIAL_ORDER).contains(&n) => {
                return Err(MaterialError::BadOrder {
                    law: "reduced-polynomial".into(),
                    order: n,
                    allowed: format!("1..={MAX_POLYNOMIAL_ORDER}"),
                })
            }
            Law::Ogden(n) if !(1..=MAX_OGDEN_TERMS).contains(&n) => {
                return Err(MaterialError::BadOrder {
                    law: "ogden".into(),
                    order: n,
                    allowed: format!("1..={MAX_OGDEN_TERMS}"),
                })
            }
            _ => {}
        }
        if p.len() != self.param_count() {
            return Err(MaterialError::WrongCount {
                law: self.to_string(),
                expected: self.param_count(),
                got: p.len(),
            });
        }
        for (spec, &value) in self.params().iter().zip(p) {
            if !value.is_finite() {
                return Err(MaterialError::NotFinite {
                    name: spec.name.clone(),
                    value,
                });
            }
        }
        match *self {
            Law::NeoHookean | Law::ReducedPolynomial(_) => positive("C10", p[0], "must be > 0"),
            Law::MooneyRivlin => positive(
                "C10 + C01",
                p[0] + p[1],
                "must be > 0 (initial shear modulus 2 (C10 + C01))",
            ),
            Law::ArrudaBoyce => {
                positive("mu", p[0], "must be > 0")?;
                positive("lambda_m", p[1] - 1.0, "must be > 1").map_err(|_| {
                    MaterialError::OutOfRange {
                        name: "lambda_m".into(),
                        value: p[1],
                        requirement: "must be > 1".into(),
                    }
                })
            }
            Law::Ogden(n) => {
                for i in 0..n {
                    if p[2 * i + 1] == 0.0 {
                        return Err(MaterialError::OutOfRange {
                            name: format!("alpha{}", i + 1),
                            value: 0.0,
                            requirement: "must be != 0".into(),
                        });
                    }
                }
                let mu0: f64 = p.iter().step_by(2).sum();
                positive(
                    &(1..=n)
                        .map(|i| format!("mu{i}"))
                        .collect::<Vec<_>>()
                        .join(" + "),
                    mu0,
                    "must be > 0 (initial shear modulus)",
                )
            }
            Law::Gent => {
                positive("mu", p[0], "must be > 0 (initial shear modulus)")?;
                positive(
                    "Jm",
                    p[1],
                    "must be > 0 (the limit of I1 - 3 the chains can reach; large Jm is neo-Hookean)",
                )
            }
            Law::VerondaWestmann | Law::Humphrey => {
                positive("C1", p[0], "must be > 0 (MPa)")?;
                positive(
                    "C2",
                    p[1],
                    "must be > 0 (the exponent's rate; the initial shear modulus is proportional to C1 C2)",
                )
            }
        }
    }

    /// Checks that the law is defined and finite at the principal stretches `lam` (used as given:
    /// the isochoric stretches of a compressible state), for parameters that passed
    /// [`Law::check`]. Gent's energy is infinite at `I1 - 3 = Jm` and undefined beyond; an
    /// exponential law (Veronda-Westmann, Humphrey) overflows where `C2 (I1 - 3) > ~709`. Where
    /// this fails the evaluation functions give NaN (or infinity), never a wrong finite stress.
    pub fn check_stretches(&self, p: &[f64], lam: [f64; 3]) -> Result<(), MaterialError> {
        let outside = |reason: String| MaterialError::OutsideDomain {
            law: self.to_string(),
            stretches: lam,
            reason,
        };
        if !lam.iter().all(|l| *l > 0.0 && l.is_finite()) {
            return Err(outside("stretches must be positive finite numbers".into()));
        }
        let (i1, _) = invariants(lam);
        if *self == Law::Gent && p.len() == 2 && i1 - 3.0 >= p[1] {
            return Err(outside(format!(
                "I1 - 3 = {} reaches the limit Jm = {} (chains fully extended: the energy is \
                 infinite there and undefined beyond); the stretch must stay where I1 - 3 < Jm, \
                 or Jm must be larger",
                i1 - 3.0,
                p[1]
            )));
        }
        let d = self.isochoric_principal(p, lam);
        if !(d.w.is_finite() && d.dw.iter().all(|v| v.is_finite())) {
            let detail = match self {
                Law::VerondaWestmann | Law::Humphrey if p.len() == 2 => format!(
                    "exp(C2 (I1 - 3)) overflows (C2 (I1 - 3) = {}, the largest is about 709)",
                    p[1] * (i1 - 3.0)
                ),
                _ => "the energy or stress is not finite".into(),
            };
            return Err(outside(detail));
        }
        Ok(())
    }

    /// Initial shear modulus `mu0` (NH: `2 C10`; MR: `2 (C10 + C01)`; RP: `2 C10`; Ogden: `sum mu_i`;
    /// Gent: `mu`; Veronda-Westmann: `C1 C2`; Humphrey: `2 C1 C2`;
    /// AB: `mu (1 + 3/(5 lm^2) + 99/(175 lm^4) + 513/(875 lm^6) + 42039/(67375 lm^8))`, which is the
    /// exact `2 dW/dI1` at rest of the 5-term series and tends to `mu` for large `lambda_m`).
    pub fn shear_modulus(&self, p: &[f64]) -> f64 {
        match *self {
            Law::NeoHookean | Law::ReducedPolynomial(_) => 2.0 * par(p, 0),
            Law::MooneyRivlin => 2.0 * (par(p, 0) + par(p, 1)),
            Law::ArrudaBoyce => arruda_boyce::initial_shear_modulus(par(p, 0), par(p, 1)),
            Law::Ogden(n) => {
                if p.len() == 2 * n {
                    p.iter().step_by(2).sum()
                } else {
                    f64::NAN
                }
            }
            Law::Gent => par(p, 0),
            Law::VerondaWestmann => par(p, 0) * par(p, 1),
            Law::Humphrey => 2.0 * par(p, 0) * par(p, 1),
        }
    }

    /// `W(l1, l2, l3)`, the isochoric energy at principal stretches `lam` (used as given, no projection).
    pub fn isochoric_energy(&self, p: &[f64], lam: [f64; 3]) -> f64 {
        self.isochoric_principal(p, lam).w
    }

    /// `W`, `dW/dl_a` and `d2W/dl_a dl_b` with the stretches `lam` treated as independent.
    pub fn isochoric_principal(&self, p: &[f64], lam: [f64; 3]) -> PrincipalDerivs {
        if p.len() != self.param_count() {
            return PrincipalDerivs::nan();
        }
        let (i1, i2) = invariants(lam);
        match self.invariant_derivs(p, i1, i2) {
            Some(inv) => inv.to_principal(lam),
            None => ogden::principal_derivs(p, lam),
        }
    }

    /// `W(I1, I2)` and its invariant derivatives for the laws written in invariants; `None` for
    /// Ogden (principal stretches only). NaN when the parameter count is wrong.
    pub fn invariant_derivs(&self, p: &[f64], i1: f64, i2: f64) -> Option<InvariantDerivs> {
        if p.len() != self.param_count() {
            return Some(InvariantDerivs {
                w: f64::NAN,
                w1: f64::NAN,
                w2: f64::NAN,
                w11: f64::NAN,
                w12: f64::NAN,
                w22: f64::NAN,
            });
        }
        match *self {
            Law::NeoHookean => Some(neo_hookean::invariant_derivs(p[0], i1)),
            Law::MooneyRivlin => Some(mooney_rivlin::invariant_derivs(p[0], p[1], i1, i2)),
            Law::ReducedPolynomial(_) => Some(reduced_polynomial::invariant_derivs(p, i1)),
            Law::ArrudaBoyce => Some(arruda_boyce::invariant_derivs(p[0], p[1], i1)),
            Law::Ogden(_) => None,
            Law::Gent => Some(gent::invariant_derivs(p[0], p[1], i1)),
            Law::VerondaWestmann => Some(veronda_westmann::invariant_derivs(p[0], p[1], i1, i2)),
            Law::Humphrey => Some(humphrey::invariant_derivs(p[0], p[1], i1)),
        }
    }

    /// Energy `Psi(F) = W(J^{-1/3} F) + U(J)`, first Piola stress `P = dPsi/dF` and tangent
    /// `A = dP/dF` (9x9, index `i*3 + j` for `F_ij`). Laws written in invariants use the
    /// eigen-free [`invariant_kinematics::stress_tangent`]; Ogden uses the principal-stretch
    /// [`kinematics::stress_tangent`]. NaN when `det F <= 0`.
    pub fn stress_tangent(&self, p: &[f64], vol: Volumetric, f: &Matrix3<f64>) -> StressTangent {
        match self {
            Law::Ogden(_) => self.stress_tangent_principal(p, vol, f),
            _ => invariant_kinematics::stress_tangent(
                |i1, i2| self.invariant_derivs(p, i1, i2).unwrap_or_default(),
                vol,
                f,
            ),
        }
    }

    /// The same as [`Law::stress_tangent`], always through the principal stretches
    /// ([`kinematics::stress_tangent`]); kept public as an independent cross-check.
    pub fn stress_tangent_principal(
        &self,
        p: &[f64],
        vol: Volumetric,
        f: &Matrix3<f64>,
    ) -> StressTangent {
        kinematics::stress_tangent(|lam| self.isochoric_principal(p, lam), vol, f)
    }
}

impl fmt::Display for Law {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Law::NeoHookean => write!(f, "neo-hookean"),
            Law::MooneyRivlin => write!(f, "mooney-rivlin"),
            Law::ReducedPolynomial(n) => write!(f, "reduced-polynomial:{n}"),
            Law::ArrudaBoyce => write!(f, "arruda-boyce"),
            Law::Ogden(n) => write!(f, "ogden:{n}"),
            Law::Gent => write!(f, "gent"),
            Law::VerondaWestmann => write!(f, "veronda-westmann"),
            Law::Humphrey => write!(f, "humphrey"),
        }
    }
}

impl FromStr for Law {
    type Err = MaterialError;

    /// Parses `neo-hookean`, `mooney-rivlin`, `reduced-polynomial:N` (N = 1..=6), `yeoh`
    /// (= `reduced-polynomial:3`), `arruda-boyce`, `ogden:N` (N = 1..=6), `gent`,
    /// `veronda-westmann`, `humphrey`; case and surrounding blanks ignored.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let text = s.trim().to_ascii_lowercase();
        let unknown = || MaterialError::UnknownLaw {
            text: s.to_string(),
        };
        let (head, order) = match text.split_once(':') {
            Some((head, n)) => (
                head.trim(),
                Some(n.trim().parse::<usize>().map_err(|_| unknown())?),
            ),
            None => (text.as_str(), None),
        };
        let law = match (head, order) {
            ("neo-hookean", None) => Law::NeoHookean,
            ("mooney-rivlin", None) => Law::MooneyRivlin,
            ("yeoh", None) => Law::ReducedPolynomial(3),
            ("arruda-boyce", None) => Law::ArrudaBoyce,
            ("gent", None) => Law::Gent,
            ("veronda-westmann", None) => Law::VerondaWestmann,
            ("humphrey", None) => Law::Humphrey,
            ("reduced-polynomial", Some(n)) => {
                if !(1..=MAX_POLYNOMIAL_ORDER).contains(&n) {
                    return Err(MaterialError::BadOrder {
                        law: "reduced-polynomial".into(),
                        order: n,
                        allowed: format!("1..={MAX_POLYNOMIAL_ORDER}"),
                    });
                }
                Law::ReducedPolynomial(n)
            }
            ("ogden", Some(n)) => {
                if !(1..=MAX_OGDEN_TERMS).contains(&n) {
                    return Err(MaterialError::BadOrder {
                        law: "ogden".into(),
                        order: n,
                        allowed: format!("1..={MAX_OGDEN_TERMS}"),
                    });
                }
                Law::Ogden(n)
            }
            _ => return Err(unknown()),
        };
        Ok(law)
    }
}
