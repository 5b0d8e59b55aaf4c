//! Affine-invariant ensemble sampler with the stretch move.
//!
//! Goodman & Weare (2010), "Ensemble samplers with affine invariance",
//! *Comm. App. Math. Comp. Sci.* 5(1), eq. 7-10; the parallel "red-black"
//! split of Foreman-Mackey et al. (2013), emcee, *PASP* 125, algorithm 3.
//! Walker k of one half moves along the line through a random walker j of
//! the other half: y = x_j + s (x_k - x_j), with s drawn from
//! g(s) ∝ 1/sqrt(s) on [1/a, a], accepted with probability
//! min(1, s^(d-1) p(y) / p(x_k)).
//!
//! Several independent ensembles run in parallel (rayon), each with its own
//! random stream; every walker is reported as a chain, as ArviZ does with
//! emcee output.

use super::chains::{GroupOut, SampleRun};
use super::density::{Counted, LogDensity};
use super::error::McmcError;
use super::rng::{chain_rng, uniform};
use super::standardized::Standardized;
use super::start::Start;
use rand::Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Settings of the ensemble sampler.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnsembleSettings {
    /// Independent ensembles (run in parallel).
    pub ensembles: usize,
    /// Walkers per ensemble (even, >= 2 d + 2); 0 picks max(16, 4 d) rounded up to even.
    pub walkers: usize,
    /// Warm-up iterations discarded.
    pub tune: usize,
    /// Stored draws per walker.
    pub draws: usize,
    /// Keep one iteration in `thin`.
    pub thin: usize,
    /// Stretch scale a (emcee default 2).
    pub a: f64,
}

impl Default for EnsembleSettings {
    fn default() -> Self {
        EnsembleSettings {
            ensembles: 2,
            walkers: 0,
            tune: 1000,
            draws: 2000,
            thin: 1,
            a: 2.0,
        }
    }
}

impl EnsembleSettings {
    fn walkers_for(&self, dim: usize) -> usize {
        let w = if self.walkers == 0 {
            (4 * dim).max(16)
        } else {
            self.walkers
        };
        w + w % 2
    }
}

/// The checks of [`sample_ensemble`]'s settings for dimension `d`.
pub(crate) fn check_settings(settings: &EnsembleSettings, d: usize) -> Result<(), McmcError> {
    let nw = settings.walkers_for(d);
    if nw < 2 * d + 2 {
        return Err(McmcError::InvalidSettings {
            field: "walkers".into(),
            reason: format!("need at least 2 d + 2 = {} walkers, got {nw}", 2 * d + 2),
        });
    }
    if settings.ensembles == 0 || settings.draws < 4 || settings.thin == 0 || settings.a <= 1.0 {
        return Err(McmcError::InvalidSettings {
            field: "ensembles/draws/thin/a".into(),
            reason: "need ensembles >= 1, draws >= 4, thin >= 1, a > 1".into(),
        });
    }
    Ok(())
}

/// Ensemble `e` of a run, alone (its stream is `chain_rng(seed, e)`).
pub(crate) fn run_one(
    density: &dyn LogDensity,
    start: &Start,
    s: &EnsembleSettings,
    seed: u64,
    e: usize,
    progress: Option<&(dyn Fn(u64) + Sync)>,
) -> Result<GroupOut, McmcError> {
    let d = density.dim();
    let nw = s.walkers_for(d);
    let mut rng = chain_rng(seed, e);
    let mut w = Counted::new(density.worker());
    let mut x = Vec::with_capacity(nw);
    let mut lp = Vec::with_capacity(nw);
    for k in 0..nw {
        let (z, l) = start.draw(&mut rng, &mut w, e * nw + k)?;
        x.push(z);
        lp.push(l);
    }
    let half = nw / 2;
    let mut chains = vec![Vec::with_capacity(s.draws); nw];
    let mut logp = vec![Vec::with_capacity(s.draws); nw];
    let mut accepted = vec![0usize; nw];
    let total = s.tune + s.draws * s.thin;
    let mut y = vec![0.0; d];
    for it in 0..total {
        for h in 0..2 {
            let (active, other) = if h == 0 {
                (0..half, half..nw)
            } else {
                (half..nw, 0..half)
            };
            for k in active {
                let j = rng.random_range(other.clone());
                let zs = ((s.a - 1.0) * uniform(&mut rng) + 1.0).powi(2) / s.a;
                for i in 0..d {
                    y[i] = x[j][i] + zs * (x[k][i] - x[j][i]);
                }
                let ly = w.log_density(&y);
                let log_ratio = (d as f64 - 1.0) * zs.ln() + ly - lp[k];
                if uniform(&mut rng).ln() < log_ratio {
                    x[k].copy_from_slice(&y);
                    lp[k] = ly;
                    if it >= s.tune {
                        accepted[k] += 1;
                    }
                }
            }
        }
        if it >= s.tune && (it - s.tune).is_multiple_of(s.thin) {
            for k in 0..nw {
                chains[k].push(x[k].clone());
                logp[k].push(lp[k]);
            }
        }
        if let Some(p) = progress {
            if it % 100 == 99 {
                p(100);
            }
        }
    }
    Ok(GroupOut {
        chains,
        logp,
        accepted,
        evaluations: w.evaluations,
    })
}

/// Runs `settings.ensembles` ensembles in parallel. `progress` (if any) is
/// called with the number of iterations just completed by one ensemble.
pub fn sample_ensemble(
    density: &dyn LogDensity,
    start: &Start,
    settings: &EnsembleSettings,
    seed: u64,
    progress: Option<&(dyn Fn(u64) + Sync)>,
) -> Result<SampleRun, McmcError> {
    let d = density.dim();
    start.check(d)?;
    let std = Standardized::new(density, start);
    let unit = Start::ball(vec![0.0; d], 1.0);
    let (density, start): (&dyn LogDensity, &Start) = (&std, &unit);
    check_settings(settings, d)?;
    let t0 = std::time::Instant::now();
    let outs: Vec<GroupOut> = (0..settings.ensembles)
        .into_par_iter()
        .map(|e| run_one(density, start, settings, seed, e, progress))
        .collect::<Result<_, _>>()?;
    Ok(SampleRun::from_groups(
        "ensemble",
        outs,
        settings.draws * settings.thin,
        &std,
        t0,
    ))
}
