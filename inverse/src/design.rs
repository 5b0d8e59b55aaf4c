//! Experiment design from the Fisher information: before an experiment is
//! run, how well would it determine the parameters?
//!
//! For one candidate experiment (a model and its loading) at a prior guess
//! `theta` of the parameters, with independent Gaussian noise of standard
//! deviation `sigma` on every sample, the Fisher information of the free
//! parameters is
//!
//! `I = J^T J / sigma^2`,  `J_ij = d f_i / d theta_j`
//!
//! (physical units), and `I^{-1}` bounds the covariance of any unbiased
//! estimate (Cramer-Rao); least squares attains it asymptotically, so its
//! diagonal is the standard error a fit to such a record would report
//! (Bates & Watts 1988, §2.3; Fedorov 1972, "Theory of optimal
//! experiments"). `J` comes from the model's exact sensitivities
//! ([`palpate_core::ForwardModel::as_sensitivities`]: one run) or, for a
//! model without them, from central finite differences of whole runs
//! ([`palpate_core::fd`]: two runs per free parameter).
//!
//! The inverse is taken as in a fit's covariance ([`crate::covariance`]: SVD
//! of the column-scaled Jacobian, pseudo-inverse over its numerical rank),
//! so a parameter no output depends on (a zero column) or a combination
//! the outputs cannot separate is reported as not identifiable, with no
//! standard error, rather than inverting a singular matrix.
//!
//! Candidates are ranked by a stated [`Criterion`]: by default the largest
//! relative standard error among the free parameters (the worst-determined
//! parameter decides), or D-optimality (the smallest volume of the
//! confidence ellipsoid, `-ln det I`), or one parameter's standard error.
//! A candidate that leaves a parameter unidentifiable ranks after every
//! identifiable one.
//!
//! A fit to a record of the same candidate with noise `sigma` reports
//! standard errors that scatter about these; `studies/examples/
//! bench_plan_n1.rs` checks them against the spread of 50 such fits.

use crate::{covariance_with_noise, Identifiability, InverseError};
use nalgebra::DMatrix;
use palpate_core::fd::{fd_jacobian, FdRule};
use palpate_core::{ForwardModel, Loading};
use serde::Serialize;
use std::fmt;
use std::str::FromStr;

/// The noise of a record, per sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "value")]
pub enum Noise {
    /// A standard deviation in the model's unit (N for a force).
    Sd(f64),
    /// A fraction of the candidate's largest |prediction| at the guess
    /// (`0.01`: 1 % of the peak force), so each candidate has its own SD.
    FractionOfPeak(f64),
}

impl Noise {
    /// The standard deviation for predictions `f`; an error when it is not
    /// positive and finite.
    pub fn sd(&self, f: &[f64]) -> Result<f64, InverseError> {
        let sd = match *self {
            Noise::Sd(s) => s,
            Noise::FractionOfPeak(r) => r * f.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        };
        if sd.is_finite() && sd > 0.0 {
            Ok(sd)
        } else {
            Err(InverseError::InvalidOption {
                option: "noise",
                reason: format!(
                    "{self}: the noise standard deviation is {sd}; it must be positive and finite"
                ),
            })
        }
    }
}

impl fmt::Display for Noise {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Noise::Sd(s) => write!(f, "{s}"),
            Noise::FractionOfPeak(r) => write!(f, "{}%", 100.0 * r),
        }
    }
}

/// How candidates are ranked (smaller is better).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "parameter")]
pub enum Criterion {
    /// The largest relative standard error `SE_j / |theta_j|` over the free
    /// parameters (every guess must be non-zero).
    WorstRelative,
    /// `-ln det I` (D-optimality): the smallest joint confidence region;
    /// independent of the parameters' units.
    DOptimal,
    /// The standard error of one parameter, by name.
    Parameter(String),
}

impl FromStr for Criterion {
    type Err = String;
    /// `worst-relative`, `d-optimal` or a parameter's name.
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "" => Err(
                "empty criterion: expected worst-relative, d-optimal or a parameter's name".into(),
            ),
            "worst-relative" => Ok(Criterion::WorstRelative),
            "d-optimal" => Ok(Criterion::DOptimal),
            name => Ok(Criterion::Parameter(name.to_string())),
        }
    }
}

impl fmt::Display for Criterion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Criterion::WorstRelative => f.write_str("worst-relative"),
            Criterion::DOptimal => f.write_str("d-optimal"),
            Criterion::Parameter(p) => f.write_str(p),
        }
    }
}

/// Where the Jacobian came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JacobianSource {
    /// The model's exact sensitivities (one run).
    Exact,
    /// Central finite differences of whole runs.
    FiniteDifferences,
}

/// What one candidate would tell about the free parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Information {
    /// Free parameters, in the model's order.
    pub names: Vec<String>,
    pub units: Vec<String>,
    /// The prior guess of each free parameter.
    pub guess: Vec<f64>,
    /// The noise SD used (the model's unit) and the samples.
    pub noise_sd: f64,
    pub samples: usize,
    /// The largest |prediction| at the guess.
    pub peak: f64,
    /// `J^T J / sigma^2` (free x free).
    pub fisher: Vec<Vec<f64>>,
    /// Expected standard errors (`None`: not identifiable).
    pub standard_errors: Vec<Option<f64>>,
    /// `SE / |guess|` (`None`: not identifiable, or a zero guess).
    pub relative_standard_errors: Vec<Option<f64>>,
    /// Correlation matrix (NaN, JSON null, where undefined).
    pub correlation: Vec<Vec<f64>>,
    /// Per free parameter: has a standard error and is not involved in a
    /// rank deficiency or a |correlation| above [`crate::MAX_CORRELATION`].
    pub identifiable: Vec<bool>,
    /// The verdict on the whole set, as a fit reports it.
    pub identifiability: Identifiability,
    /// `ln det I` over the free parameters (`-inf` when singular).
    pub log_det_fisher: f64,
    pub jacobian: JacobianSource,
    /// Forward runs spent.
    pub runs: usize,
}

impl Information {
    /// The names of the free parameters that are not identifiable.
    pub fn not_identifiable(&self) -> Vec<String> {
        self.names
            .iter()
            .zip(&self.identifiable)
            .filter(|(_, ok)| !**ok)
            .map(|(n, _)| n.clone())
            .collect()
    }

    /// The candidate's value of `criterion` (smaller is better; `+inf`
    /// when a parameter it needs is not identifiable). An error names an
    /// unknown parameter, or a zero guess under the relative criterion.
    pub fn score(&self, criterion: &Criterion) -> Result<f64, InverseError> {
        match criterion {
            Criterion::WorstRelative => {
                let mut worst: f64 = 0.0;
                for (j, name) in self.names.iter().enumerate() {
                    if self.guess[j] == 0.0 {
                        return Err(InverseError::InvalidOption {
                            option: "criterion",
                            reason: format!(
                                "worst-relative needs a non-zero guess of every free parameter, and `{name}` is 0; rank by d-optimal or by one parameter's name"
                            ),
                        });
                    }
                    match (self.identifiable[j], self.relative_standard_errors[j]) {
                        (true, Some(r)) => worst = worst.max(r),
                        _ => return Ok(f64::INFINITY),
                    }
                }
                Ok(worst)
            }
            Criterion::DOptimal => Ok(if self.identifiable.iter().all(|&b| b) {
                -self.log_det_fisher
            } else {
                f64::INFINITY
            }),
            Criterion::Parameter(name) => {
                let j = self.names.iter().position(|n| n == name).ok_or_else(|| {
                    InverseError::InvalidOption {
                        option: "criterion",
                        reason: format!(
                            "`{name}` is not a free parameter; free: {}; or worst-relative, d-optimal",
                            self.names.join(", ")
                        ),
                    }
                })?;
                Ok(match (self.identifiable[j], self.standard_errors[j]) {
                    (true, Some(se)) => se,
                    _ => f64::INFINITY,
                })
            }
        }
    }
}

/// The information of one candidate: `model` under `loading` at the full
/// physical parameter vector `theta`, free parameters `free` (indices into
/// the model's space), `noise` per sample; `fd` for a model without exact
/// sensitivities. Errors: no free parameter, a bad index or guess, a failed
/// run (the model's error), a bad noise level.
pub fn information(
    model: &dyn ForwardModel,
    theta: &[f64],
    loading: &Loading,
    free: &[usize],
    noise: Noise,
    fd: &FdRule,
) -> Result<Information, InverseError> {
    let space = model.space();
    if free.is_empty() {
        return Err(InverseError::NothingToFit);
    }
    if let Some(&k) = free.iter().find(|&&k| k >= space.len()) {
        return Err(InverseError::InvalidOption {
            option: "free",
            reason: format!("index {k} for a model of {} parameters", space.len()),
        });
    }
    let forward = |source| InverseError::Forward {
        set: model.name(),
        theta: theta.to_vec(),
        stage: "experiment design",
        source: Box::new(source),
    };
    space.check(theta).map_err(forward)?;
    let (f, columns, jacobian, runs) = match model.as_sensitivities() {
        Some(s) => {
            let (f, cols) = s.predict_with_jacobian(theta, loading).map_err(forward)?;
            (f, cols, JacobianSource::Exact, 1)
        }
        None => {
            let f = model.predict(theta, loading).map_err(forward)?;
            let mut ev = model.evaluator();
            let steps: Vec<_> = space
                .params
                .iter()
                .zip(theta)
                .map(|(spec, &x)| fd.param_step(spec, x))
                .collect();
            // only the free columns: difference a function of the free values
            let free_steps: Vec<_> = free.iter().map(|&k| steps[k]).collect();
            let x0: Vec<f64> = free.iter().map(|&k| theta[k]).collect();
            let mut g = |x: &[f64], out: &mut [f64]| {
                let mut t = theta.to_vec();
                for (&k, &v) in free.iter().zip(x) {
                    t[k] = v;
                }
                ev.predict_into(&t, loading, out)
            };
            let (cols, n) =
                fd_jacobian(&mut g, &x0, &free_steps, None, loading.len()).map_err(forward)?;
            let mut all = vec![Vec::new(); space.len()];
            for (&k, c) in free.iter().zip(cols) {
                all[k] = c;
            }
            (f, all, JacobianSource::FiniteDifferences, 1 + n)
        }
    };
    let m = f.len();
    let q = free.len();
    let mut jx = DMatrix::zeros(m, q);
    for (j, &k) in free.iter().enumerate() {
        for i in 0..m {
            jx[(i, j)] = columns[k][i];
        }
    }
    let noise_sd = noise.sd(&f)?;
    let names: Vec<String> = free.iter().map(|&k| space.params[k].name.clone()).collect();
    let cov = covariance_with_noise(&jx, Some(noise_sd * noise_sd), &names, &vec![false; q]);
    let guess: Vec<f64> = free.iter().map(|&k| theta[k]).collect();
    let fisher_m = jx.transpose() * &jx / (noise_sd * noise_sd);
    let fisher: Vec<Vec<f64>> = (0..q)
        .map(|a| (0..q).map(|b| fisher_m[(a, b)]).collect())
        .collect();
    let identifiable: Vec<bool> = names
        .iter()
        .zip(&cov.standard_errors)
        .map(|(n, se)| se.is_some() && !cov.identifiability.involved.contains(n))
        .collect();
    let relative_standard_errors = cov
        .standard_errors
        .iter()
        .zip(&guess)
        .map(|(se, &g)| se.filter(|_| g != 0.0).map(|s| s / g.abs()))
        .collect();
    Ok(Information {
        names,
        units: free.iter().map(|&k| space.params[k].unit.clone()).collect(),
        guess,
        noise_sd,
        samples: m,
        peak: f.iter().fold(0.0f64, |a, v| a.max(v.abs())),
        fisher,
        standard_errors: cov.standard_errors,
        relative_standard_errors,
        correlation: cov.correlation,
        identifiable,
        identifiability: cov.identifiability,
        log_det_fisher: log_det(&fisher_m),
        jacobian,
        runs,
    })
}

/// `ln det` of a symmetric matrix by its eigenvalues (`-inf` when one is
/// not positive: a singular information).
fn log_det(a: &DMatrix<f64>) -> f64 {
    let eig = a.clone().symmetric_eigen();
    let max = eig.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tol = crate::covariance::RANK_TOLERANCE * max;
    if max == 0.0 || eig.eigenvalues.iter().any(|&v| v.is_nan() || v <= tol) {
        return f64::NEG_INFINITY;
    }
    eig.eigenvalues.iter().map(|v| v.ln()).sum()
}

/// The order of candidates by `criterion` (best first; ties keep the
/// given order), with each candidate's score.
pub fn rank(
    candidates: &[Information],
    criterion: &Criterion,
) -> Result<Vec<(usize, f64)>, InverseError> {
    let mut scored: Vec<(usize, f64)> = candidates
        .iter()
        .enumerate()
        .map(|(i, c)| c.score(criterion).map(|s| (i, s)))
        .collect::<Result<_, _>>()?;
    scored.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    Ok(scored)
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_core::{
        Drive, Evaluator, ForwardError, Observable, ParamSpace, ParamSpec, Sensitivities,
    };

    /// `a x + b x^2 + 0 c` (c: a parameter nothing depends on), with or
    /// without exact sensitivities.
    struct Quad {
        space: ParamSpace,
        exact: bool,
    }
    struct Eval;
    impl Evaluator for Eval {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            o: &mut [f64],
        ) -> Result<(), ForwardError> {
            for (o, x) in o.iter_mut().zip(&l.drive) {
                *o = t[0] * x + t[1] * x * x;
            }
            Ok(())
        }
    }
    impl Sensitivities for Quad {
        fn predict_with_jacobian(
            &self,
            t: &[f64],
            l: &Loading,
        ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
            let f = l.drive.iter().map(|x| t[0] * x + t[1] * x * x).collect();
            let cols = vec![
                l.drive.clone(),
                l.drive.iter().map(|x| x * x).collect(),
                vec![0.0; l.len()],
            ];
            Ok((f, cols))
        }
    }
    impl ForwardModel for Quad {
        fn name(&self) -> String {
            "quad".into()
        }
        fn space(&self) -> &ParamSpace {
            &self.space
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(Eval)
        }
        fn as_sensitivities(&self) -> Option<&dyn Sensitivities> {
            self.exact.then_some(self as &dyn Sensitivities)
        }
    }

    fn quad(exact: bool) -> Quad {
        let p = |n: &str| ParamSpec::new(n, "N/mm", -10.0, 10.0, 1.0);
        Quad {
            space: ParamSpace::new(vec![p("a"), p("b"), p("c")]),
            exact,
        }
    }

    fn loading(n: usize, end: f64) -> Loading {
        Loading::quasi_static(
            Drive::DisplacementMm,
            (1..=n).map(|i| end * i as f64 / n as f64).collect(),
        )
    }

    /// Linear least squares: the standard errors are those of the normal
    /// equations, exactly, from exact sensitivities and from differences.
    #[test]
    fn standard_errors_are_those_of_linear_least_squares() {
        let l = loading(10, 2.0);
        let sd = 0.05;
        // closed form: (X^T X)^{-1} sigma^2 with columns x, x^2
        let (mut s11, mut s12, mut s22) = (0.0, 0.0, 0.0);
        for x in &l.drive {
            s11 += x * x;
            s12 += x * x * x;
            s22 += x * x * x * x;
        }
        let det = s11 * s22 - s12 * s12;
        let se_a = (sd * sd * s22 / det).sqrt();
        let se_b = (sd * sd * s11 / det).sqrt();
        let rho = -s12 / (s11 * s22).sqrt();
        for exact in [true, false] {
            let info = information(
                &quad(exact),
                &[0.5, 0.2, 1.0],
                &l,
                &[0, 1],
                Noise::Sd(sd),
                &FdRule::default(),
            )
            .unwrap();
            let se = &info.standard_errors;
            assert!((se[0].unwrap() / se_a - 1.0).abs() < 1e-6, "{se:?} {se_a}");
            assert!((se[1].unwrap() / se_b - 1.0).abs() < 1e-6, "{se:?} {se_b}");
            assert!((info.correlation[0][1] - rho).abs() < 1e-6);
            assert_eq!(info.identifiable, [true, true]);
            assert!((info.log_det_fisher - (det / sd.powi(4)).ln()).abs() < 1e-6);
            assert_eq!(
                (info.jacobian, info.runs),
                if exact {
                    (JacobianSource::Exact, 1)
                } else {
                    (JacobianSource::FiniteDifferences, 5)
                }
            );
            // twice the noise, twice the standard errors
            let twice = information(
                &quad(exact),
                &[0.5, 0.2, 1.0],
                &l,
                &[0, 1],
                Noise::Sd(2.0 * sd),
                &FdRule::default(),
            )
            .unwrap();
            assert!((twice.standard_errors[0].unwrap() / se[0].unwrap() - 2.0).abs() < 1e-9);
        }
    }

    /// A parameter no output depends on is reported as not identifiable,
    /// with no standard error, and the others keep theirs; nothing panics.
    #[test]
    fn a_parameter_nothing_depends_on_is_not_identifiable() {
        let l = loading(10, 2.0);
        for exact in [true, false] {
            let info = information(
                &quad(exact),
                &[0.5, 0.2, 1.0],
                &l,
                &[0, 1, 2],
                Noise::Sd(0.05),
                &FdRule::default(),
            )
            .unwrap();
            assert_eq!(info.identifiable, [true, true, false], "{info:?}");
            assert_eq!(info.not_identifiable(), ["c"]);
            assert!(info.standard_errors[2].is_none());
            assert!(info.standard_errors[0].is_some());
            assert!(!info.identifiability.identifiable);
            assert_eq!(info.log_det_fisher, f64::NEG_INFINITY);
            for c in [
                Criterion::WorstRelative,
                Criterion::DOptimal,
                Criterion::Parameter("c".into()),
            ] {
                assert_eq!(info.score(&c).unwrap(), f64::INFINITY, "{c}");
            }
            assert!(info.score(&Criterion::Parameter("a".into())).unwrap() < 1.0);
        }
    }

    /// One sample for two parameters: both not identifiable.
    #[test]
    fn fewer_samples_than_parameters_identify_nothing() {
        let info = information(
            &quad(true),
            &[0.5, 0.2, 1.0],
            &loading(1, 2.0),
            &[0, 1],
            Noise::Sd(0.05),
            &FdRule::default(),
        )
        .unwrap();
        assert_eq!(info.identifiable, [false, false]);
    }

    /// A longer ramp separates a from b better, and every criterion says so;
    /// bad criteria and inputs are named.
    #[test]
    fn ranking_prefers_the_more_informative_candidate() {
        let m = quad(true);
        let theta = [0.5, 0.2, 1.0];
        let short = information(
            &m,
            &theta,
            &loading(10, 1.0),
            &[0, 1],
            Noise::Sd(0.05),
            &FdRule::default(),
        )
        .unwrap();
        let long = information(
            &m,
            &theta,
            &loading(10, 4.0),
            &[0, 1],
            Noise::Sd(0.05),
            &FdRule::default(),
        )
        .unwrap();
        let both = [short, long];
        for c in [
            Criterion::WorstRelative,
            Criterion::DOptimal,
            Criterion::Parameter("b".into()),
        ] {
            let r = rank(&both, &c).unwrap();
            assert_eq!(r[0].0, 1, "{c}: {r:?}");
            assert!(r[0].1 < r[1].1);
        }
        let err = rank(&both, &Criterion::Parameter("d".into())).unwrap_err();
        assert!(
            err.to_string().contains("`d` is not a free parameter"),
            "{err}"
        );
        let zero = information(
            &m,
            &[0.0, 0.2, 1.0],
            &loading(10, 1.0),
            &[0, 1],
            Noise::Sd(0.05),
            &FdRule::default(),
        )
        .unwrap();
        let err = zero.score(&Criterion::WorstRelative).unwrap_err();
        assert!(err.to_string().contains("`a` is 0"), "{err}");
        assert_eq!(
            "d-optimal".parse::<Criterion>().unwrap(),
            Criterion::DOptimal
        );
        assert!("".parse::<Criterion>().is_err());
        let err = information(
            &m,
            &theta,
            &loading(10, 1.0),
            &[],
            Noise::Sd(0.05),
            &FdRule::default(),
        )
        .unwrap_err();
        assert!(matches!(err, InverseError::NothingToFit), "{err}");
        let err = information(
            &m,
            &theta,
            &loading(10, 1.0),
            &[0],
            Noise::Sd(0.0),
            &FdRule::default(),
        )
        .unwrap_err();
        assert!(err.to_string().contains("noise"), "{err}");
        // 1 % of the peak: the peak of a x + b x^2 at x = 1 is 0.7
        let rel = information(
            &m,
            &theta,
            &loading(10, 1.0),
            &[0],
            Noise::FractionOfPeak(0.01),
            &FdRule::default(),
        )
        .unwrap();
        assert!((rel.noise_sd - 0.007).abs() < 1e-12, "{}", rel.noise_sd);
    }
}
