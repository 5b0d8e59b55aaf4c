//! Sampling until converged: extend the draws until every R-hat is below a
//! threshold and every bulk ESS above one, or a cap is reached.
//!
//! Criteria (defaults): rank-normalised split R-hat < 1.01 and bulk ESS >=
//! 400 for every parameter, the thresholds of Vehtari, Gelman, Simpson,
//! Carpenter & Bürkner (2021), "Rank-normalization, folding, and
//! localization: an improved R-hat", *Bayesian Analysis* 16(2), sec. 4
//! ("R-hat < 1.01 ... ESS > 400").
//!
//! Extension doubles the stored draws per chain (up to the cap) and runs the
//! sampler again from the same seed. Every sampler's warm-up and random
//! streams do not depend on the number of draws, so the longer run repeats
//! the shorter one's draws exactly and continues them (tested): the result
//! is the run a user would have got by asking for the final length at once,
//! at a cost of at most twice that run (the repeated prefixes sum to less
//! than the final length).

use super::{McmcError, SampleRun, Sampler};
use crate::mcmc::diagnostics::{ess_bulk, rhat};
use crate::mcmc::{Chains, LogDensity, Start};

/// When a run counts as converged, and how far it may be extended.
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    /// Every R-hat must be below this.
    pub rhat_below: f64,
    /// Every bulk ESS must be at least this.
    pub ess_bulk_at_least: f64,
    /// Largest number of stored draws per chain.
    pub max_draws: usize,
}

impl Default for Convergence {
    fn default() -> Self {
        Convergence {
            rhat_below: 1.01,
            ess_bulk_at_least: 400.0,
            max_draws: 64_000,
        }
    }
}

/// The worst diagnostics of a run and which parameters they belong to.
#[derive(Debug, Clone, PartialEq)]
pub struct Worst {
    /// Stored draws per chain.
    pub draws: usize,
    pub rhat_max: f64,
    pub rhat_param: usize,
    pub ess_bulk_min: f64,
    pub ess_param: usize,
}

impl Worst {
    /// Max R-hat and min bulk ESS over the parameters of `x`.
    pub fn of(x: &Chains) -> Worst {
        let mut w = Worst {
            draws: x.n_draws,
            rhat_max: f64::NEG_INFINITY,
            rhat_param: 0,
            ess_bulk_min: f64::INFINITY,
            ess_param: 0,
        };
        for k in 0..x.dim {
            let p = x.param(k);
            let r = rhat(&p);
            let e = ess_bulk(&p);
            // NaN (a constant parameter) counts as not converged.
            let r = if r.is_nan() { f64::INFINITY } else { r };
            let e = if e.is_nan() { 0.0 } else { e };
            if r > w.rhat_max {
                w.rhat_max = r;
                w.rhat_param = k;
            }
            if e < w.ess_bulk_min {
                w.ess_bulk_min = e;
                w.ess_param = k;
            }
        }
        w
    }

    /// Whether it meets `c`.
    pub fn meets(&self, c: &Convergence) -> bool {
        self.rhat_max < c.rhat_below && self.ess_bulk_min >= c.ess_bulk_at_least
    }
}

/// A run extended until converged (or capped).
#[derive(Debug, Clone)]
pub struct ConvergedRun {
    /// The final run.
    pub run: SampleRun,
    /// Its worst diagnostics.
    pub worst: Worst,
    /// Whether it meets the criteria (false: the cap was reached).
    pub converged: bool,
    /// The diagnostics of every run tried, shortest first.
    pub history: Vec<Worst>,
    /// Log-density evaluations of all runs together.
    pub evaluations: u64,
    /// Wall time of all runs together, s.
    pub wall_time_s: f64,
}

fn with_draws(s: &Sampler, draws: usize) -> Sampler {
    let mut s = s.clone();
    match &mut s {
        Sampler::Ensemble(x) => x.draws = draws,
        Sampler::Demc(x) => x.draws = draws,
        Sampler::Nuts(x) => x.draws = draws,
    }
    s
}

/// The stored draws per chain of a sampler's settings.
pub fn draws_of(s: &Sampler) -> usize {
    match s {
        Sampler::Ensemble(x) => x.draws,
        Sampler::Demc(x) => x.draws,
        Sampler::Nuts(x) => x.draws,
    }
}

/// Runs `sampler`, then doubles its draws (capped at `c.max_draws`) while
/// the diagnostics of the draws mapped by `to_physical` miss `c`.
/// `on_run(worst, next)` is called after each run that is extended, with
/// the next length; `progress` is passed to each run, and `on_start(total)`
/// announces each run's total iterations (for a progress bar).
#[allow(clippy::too_many_arguments)]
pub fn sample_until_converged(
    sampler: &Sampler,
    density: &dyn LogDensity,
    start: &Start,
    seed: u64,
    c: &Convergence,
    to_physical: &dyn Fn(&[f64]) -> Vec<f64>,
    progress: Option<&(dyn Fn(u64) + Sync)>,
    on_start: &mut dyn FnMut(u64),
    on_run: &mut dyn FnMut(&Worst, usize),
) -> Result<ConvergedRun, McmcError> {
    let mut s = sampler.clone();
    if c.max_draws < draws_of(&s) {
        return Err(McmcError::InvalidSettings {
            field: "max_draws".into(),
            reason: format!(
                "the cap {} is below the {} draws of the first run",
                c.max_draws,
                draws_of(&s)
            ),
        });
    }
    let mut history = Vec::new();
    let mut evaluations = 0;
    let mut wall = 0.0;
    loop {
        on_start(s.total_iterations());
        let run = s.run(density, start, seed, progress)?;
        evaluations += run.evaluations;
        wall += run.wall_time_s;
        let worst = Worst::of(&run.chains.map(to_physical));
        history.push(worst.clone());
        let draws = draws_of(&s);
        let converged = worst.meets(c);
        if converged || draws >= c.max_draws {
            return Ok(ConvergedRun {
                run,
                worst,
                converged,
                history,
                evaluations,
                wall_time_s: wall,
            });
        }
        let next = (2 * draws).min(c.max_draws);
        on_run(&worst, next);
        s = with_draws(&s, next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcmc::{DemcSettings, EnsembleSettings, FnDensity, NutsSettings};

    fn gaussian() -> FnDensity<impl Fn(&[f64]) -> f64 + Sync> {
        // A correlated 2-D Gaussian.
        FnDensity::new(2, |x: &[f64]| {
            let (a, b) = (x[0], x[1] - 0.9 * x[0]);
            -0.5 * (a * a + b * b / 0.19)
        })
    }

    /// A longer run from the same seed repeats the shorter one's draws: the
    /// basis of extension by re-running.
    #[test]
    fn a_longer_run_continues_the_shorter_one() {
        let d = gaussian();
        let start = Start::ball(vec![0.0, 0.0], 1.0);
        for s in [
            Sampler::Ensemble(EnsembleSettings {
                tune: 50,
                draws: 40,
                ..Default::default()
            }),
            Sampler::Demc(DemcSettings {
                tune: 50,
                draws: 40,
                ..Default::default()
            }),
            Sampler::Nuts(NutsSettings {
                tune: 50,
                draws: 40,
                chains: 2,
                ..Default::default()
            }),
        ] {
            let short = s.run(&d, &start, 7, None).unwrap();
            let long = with_draws(&s, 80).run(&d, &start, 7, None).unwrap();
            for c in 0..short.chains.n_chains {
                for t in 0..40 {
                    assert_eq!(short.chains.point(c, t), long.chains.point(c, t), "{s:?}");
                }
            }
        }
    }

    /// Too few draws to converge: extended, reported, converged.
    #[test]
    fn extends_until_converged_and_stops_at_the_cap() {
        let d = gaussian();
        let start = Start::ball(vec![0.0, 0.0], 1.0);
        let s = Sampler::Demc(DemcSettings {
            tune: 100,
            draws: 20,
            ..Default::default()
        });
        let id = |z: &[f64]| z.to_vec();
        let mut lines = Vec::new();
        let r = sample_until_converged(
            &s,
            &d,
            &start,
            1,
            &Convergence::default(),
            &id,
            None,
            &mut |_| {},
            &mut |w, next| lines.push((w.draws, next)),
        )
        .unwrap();
        assert!(r.converged && r.worst.meets(&Convergence::default()));
        assert!(!lines.is_empty() && lines[0] == (20, 40), "{lines:?}");
        assert_eq!(r.history.len(), lines.len() + 1);
        assert!(!r.history[0].meets(&Convergence::default()));
        // A cap below convergence: stops there, not converged.
        let capped = Convergence {
            max_draws: 40,
            ..Default::default()
        };
        let r = sample_until_converged(
            &s,
            &d,
            &start,
            1,
            &capped,
            &id,
            None,
            &mut |_| {},
            &mut |_, _| {},
        )
        .unwrap();
        assert!(!r.converged && r.run.chains.n_draws == 40);
        let bad = Convergence {
            max_draws: 10,
            ..Default::default()
        };
        let e = sample_until_converged(
            &s,
            &d,
            &start,
            1,
            &bad,
            &id,
            None,
            &mut |_| {},
            &mut |_, _| {},
        );
        assert!(e.unwrap_err().to_string().contains("cap 10"));
    }
}
