//! A sampler's run as independent units: the parallel units of
//! [`Sampler::run`] (NUTS chains, DE-MCz populations, ensembles of walkers)
//! computed one at a time, anywhere, and assembled.
//!
//! Unit `k` draws from its own stream `chain_rng(seed, k)` and starts from
//! the same standardised start as in [`Sampler::run`], so it is the same
//! whichever process computes it, and [`Sampler::assemble`] of units
//! `0..Sampler::unit_count()` gives exactly the draws of [`Sampler::run`]
//! (tested below). This is what lets a study shard the chains of a sample
//! step (palpate-studies' `sample_step`) and cache each one.

use super::chains::{Chains, GroupOut, SampleRun};
use super::density::LogDensity;
use super::error::McmcError;
use super::standardized::Standardized;
use super::start::Start;
use super::{demc, ensemble, nuts, Sampler};
use serde::{Deserialize, Serialize};

/// What one unit returns: its chains' draws in the density's own space
/// (`[chain][draw][dim]`: one chain for NUTS, a population's or an
/// ensemble's chains otherwise), with what [`SampleRun`] reports of them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitRun {
    pub chains: Vec<Vec<Vec<f64>>>,
    /// Log-density of each stored draw, `[chain][draw]`.
    pub log_density: Vec<Vec<f64>>,
    /// Acceptance rate per chain (NUTS: mean acceptance statistic).
    pub acceptance: Vec<f64>,
    /// Log-density evaluations, warm-up included.
    pub evaluations: u64,
    /// NUTS only: divergent transitions after warm-up, per chain.
    pub divergences: Vec<usize>,
    /// NUTS only: adapted step size per chain.
    pub step_size: Vec<f64>,
}

impl Sampler {
    /// The number of independent units of a run (NUTS chains, DE-MCz
    /// populations, ensembles).
    pub fn unit_count(&self) -> usize {
        match self {
            Sampler::Ensemble(s) => s.ensembles,
            Sampler::Demc(s) => s.populations,
            Sampler::Nuts(s) => s.chains,
        }
    }

    /// Unit `index` of [`Sampler::run`] with the same density, start and
    /// seed, computed alone. Refused as [`Sampler::run`] refuses, and for
    /// an index not below [`Sampler::unit_count`].
    pub fn run_unit(
        &self,
        density: &dyn LogDensity,
        start: &Start,
        seed: u64,
        index: usize,
    ) -> Result<UnitRun, McmcError> {
        let d = density.dim();
        start.check(d)?;
        match self {
            Sampler::Ensemble(s) => ensemble::check_settings(s, d)?,
            Sampler::Demc(s) => demc::check_settings(s)?,
            Sampler::Nuts(s) => nuts::check_settings(s)?,
        }
        if index >= self.unit_count() {
            return Err(McmcError::InvalidSettings {
                field: "unit".into(),
                reason: format!(
                    "unit {index} of a run of {} units (numbered from 0)",
                    self.unit_count()
                ),
            });
        }
        let std = Standardized::new(density, start);
        let unit = Start::ball(vec![0.0; d], 1.0);
        let back = |chains: Vec<Vec<Vec<f64>>>| -> Vec<Vec<Vec<f64>>> {
            chains
                .into_iter()
                .map(|c| c.iter().map(|y| std.to_original(y)).collect())
                .collect()
        };
        let group = |g: GroupOut, iterations: usize| UnitRun {
            acceptance: g
                .accepted
                .iter()
                .map(|&a| a as f64 / iterations as f64)
                .collect(),
            chains: back(g.chains),
            log_density: g.logp,
            evaluations: g.evaluations,
            divergences: Vec::new(),
            step_size: Vec::new(),
        };
        Ok(match self {
            Sampler::Nuts(s) => {
                let o = nuts::run_chain(&std, &unit, s, seed, index, None)?;
                UnitRun {
                    chains: back(vec![o.draws]),
                    log_density: vec![o.logp],
                    acceptance: vec![o.accept],
                    evaluations: o.evaluations,
                    divergences: vec![o.divergences],
                    step_size: vec![o.eps],
                }
            }
            Sampler::Demc(s) => group(
                demc::run_population(&std, &unit, s, seed, index, None)?,
                s.draws * s.thin,
            ),
            Sampler::Ensemble(s) => group(
                ensemble::run_one(&std, &unit, s, seed, index, None)?,
                s.draws * s.thin,
            ),
        })
    }

    /// The run of the units `0..unit_count()` in their order (`wall_time_s`
    /// 0: the units ran wherever they ran).
    pub fn assemble(&self, units: Vec<UnitRun>) -> SampleRun {
        let mut all = Vec::new();
        let mut run = SampleRun {
            sampler: match self {
                Sampler::Ensemble(_) => "ensemble",
                Sampler::Demc(_) => "demc",
                Sampler::Nuts(_) => "nuts",
            }
            .into(),
            chains: Chains::from_nested(&[]),
            log_density: Vec::new(),
            acceptance: Vec::new(),
            evaluations: 0,
            wall_time_s: 0.0,
            divergences: Vec::new(),
            step_size: Vec::new(),
        };
        for u in units {
            all.extend(u.chains);
            run.log_density.extend(u.log_density);
            run.acceptance.extend(u.acceptance);
            run.evaluations += u.evaluations;
            run.divergences.extend(u.divergences);
            run.step_size.extend(u.step_size);
        }
        run.chains = Chains::from_nested(&all);
        run
    }
}

#[cfg(test)]
mod tests {
    use super::super::{DemcSettings, EnsembleSettings, FnDensity, NutsSettings};
    use super::*;

    fn banana(x: &[f64]) -> f64 {
        -0.5 * (x[0] * x[0] + 4.0 * (x[1] - 0.3 * x[0] * x[0]).powi(2))
    }

    #[test]
    fn units_assemble_to_the_run_bit_for_bit() {
        let density = FnDensity::new(2, banana);
        let start = Start::ball(vec![0.1, -0.2], 0.5);
        for sampler in [
            Sampler::Nuts(NutsSettings {
                chains: 3,
                draws: 50,
                tune: 60,
                ..Default::default()
            }),
            Sampler::Demc(DemcSettings {
                populations: 2,
                draws: 40,
                tune: 40,
                ..Default::default()
            }),
            Sampler::Ensemble(EnsembleSettings {
                ensembles: 2,
                draws: 20,
                tune: 20,
                ..Default::default()
            }),
        ] {
            let whole = sampler.run(&density, &start, 7, None).unwrap();
            // Units computed out of order, as shards would.
            let mut units: Vec<(usize, UnitRun)> = (0..sampler.unit_count())
                .rev()
                .map(|k| (k, sampler.run_unit(&density, &start, 7, k).unwrap()))
                .collect();
            units.sort_by_key(|(k, _)| *k);
            let parts = sampler.assemble(units.into_iter().map(|(_, u)| u).collect());
            assert_eq!(parts.chains, whole.chains, "{}", whole.sampler);
            assert_eq!(parts.log_density, whole.log_density);
            assert_eq!(parts.acceptance, whole.acceptance);
            assert_eq!(parts.evaluations, whole.evaluations);
            assert_eq!(parts.divergences, whole.divergences);
            assert_eq!(parts.step_size, whole.step_size);
            assert_eq!(parts.sampler, whole.sampler);
        }
    }

    #[test]
    fn a_unit_past_the_count_is_refused() {
        let density = FnDensity::new(2, banana);
        let start = Start::ball(vec![0.0, 0.0], 0.5);
        let s = Sampler::Nuts(NutsSettings {
            chains: 2,
            ..Default::default()
        });
        let e = s.run_unit(&density, &start, 1, 2).unwrap_err().to_string();
        assert!(e.contains("unit 2 of a run of 2 units"), "{e}");
    }
}
