//! Differential-evolution Markov chain with sampling from the past (DE-MCz).
//!
//! ter Braak & Vrugt (2008), "Differential Evolution Markov Chain with
//! snooker updater and fewer chains", *Statistics and Computing* 18, 435-446,
//! eq. 2 and section 3: a population of N (3) chains; chain i proposes
//!
//!   x* = x_i + gamma (1 + u) (z_r1 - z_r2) + eps,
//!
//! with z_r1, z_r2 two distinct random points of the archive Z of past
//! states, gamma = 2.38 / sqrt(2 d) (gamma = 1 every tenth iteration, to jump
//! between modes), u ~ U(-0.1, 0.1) and eps ~ N(0, 1e-6^2) per coordinate
//! (DREAM's b and b*, Vrugt 2016, *Env. Modelling & Software* 75, eq. 23),
//! accepted with the Metropolis ratio; every `archive_every` iterations all
//! chains' states are appended to Z. Because Z learns the posterior's shape,
//! the proposal becomes the optimal random-walk proposal for correlated
//! posteriors without gradients: the population sampler for expensive
//! black-box models. The snooker update is left out (it matters for
//! multimodal targets, not for the unimodal calibration posteriors here).
//!
//! Independent populations run in parallel (rayon), each with its own random
//! stream; every chain of every population is reported.

use super::chains::{GroupOut, SampleRun};
use super::density::{Counted, LogDensity};
use super::error::McmcError;
use super::rng::{chain_rng, std_normal, uniform};
use super::standardized::Standardized;
use super::start::Start;
use rand::Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Settings of DE-MCz.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DemcSettings {
    /// Independent populations (run in parallel).
    pub populations: usize,
    /// Chains per population (ter Braak & Vrugt use 3).
    pub chains: usize,
    /// Initial archive size; 0 picks 10 d.
    pub archive_init: usize,
    /// Append the chains' states to the archive every this many iterations.
    pub archive_every: usize,
    /// Warm-up iterations discarded.
    pub tune: usize,
    /// Stored draws per chain.
    pub draws: usize,
    /// Keep one iteration in `thin`.
    pub thin: usize,
}

impl Default for DemcSettings {
    fn default() -> Self {
        DemcSettings {
            populations: 2,
            chains: 3,
            archive_init: 0,
            archive_every: 10,
            tune: 2000,
            draws: 5000,
            thin: 1,
        }
    }
}

/// The checks of [`sample_demc`]'s settings.
pub(crate) fn check_settings(settings: &DemcSettings) -> Result<(), McmcError> {
    if settings.populations == 0
        || settings.chains < 1
        || settings.draws < 4
        || settings.thin == 0
        || settings.archive_every == 0
    {
        return Err(McmcError::InvalidSettings {
            field: "populations/chains/draws/thin/archive_every".into(),
            reason: "need populations >= 1, chains >= 1, draws >= 4, thin >= 1, archive_every >= 1"
                .into(),
        });
    }
    Ok(())
}

/// Population `pop` of a DE-MCz run, alone (its stream is `chain_rng(seed, pop)`).
pub(crate) fn run_population(
    density: &dyn LogDensity,
    start: &Start,
    s: &DemcSettings,
    seed: u64,
    pop: usize,
    progress: Option<&(dyn Fn(u64) + Sync)>,
) -> Result<GroupOut, McmcError> {
    let d = density.dim();
    let mut rng = chain_rng(seed, pop);
    let mut w = Counted::new(density.worker());
    let m0 = if s.archive_init == 0 {
        (10 * d).max(2 * s.chains)
    } else {
        s.archive_init
    };
    // The archive starts from start-point draws (no density needed), the
    // chains from jittered points with a finite density.
    let mut archive: Vec<Vec<f64>> = (0..m0)
        .map(|_| {
            start
                .center
                .iter()
                .zip(&start.scale)
                .map(|(c, sc)| c + sc * std_normal(&mut rng))
                .collect()
        })
        .collect();
    let n = s.chains;
    let mut x = Vec::with_capacity(n);
    let mut lp = Vec::with_capacity(n);
    for i in 0..n {
        let (z, l) = start.draw(&mut rng, &mut w, pop * n + i)?;
        x.push(z);
        lp.push(l);
    }
    let gamma0 = 2.38 / (2.0 * d as f64).sqrt();
    let mut chains = vec![Vec::with_capacity(s.draws); n];
    let mut logp = vec![Vec::with_capacity(s.draws); n];
    let mut accepted = vec![0usize; n];
    let total = s.tune + s.draws * s.thin;
    let mut y = vec![0.0; d];
    for it in 0..total {
        let gamma = if it % 10 == 9 { 1.0 } else { gamma0 };
        for i in 0..n {
            let m = archive.len();
            let r1 = rng.random_range(0..m);
            let mut r2 = rng.random_range(0..m - 1);
            if r2 >= r1 {
                r2 += 1;
            }
            let g = gamma * (1.0 + 0.1 * (2.0 * uniform(&mut rng) - 1.0));
            for k in 0..d {
                y[k] =
                    x[i][k] + g * (archive[r1][k] - archive[r2][k]) + 1e-6 * std_normal(&mut rng);
            }
            let ly = w.log_density(&y);
            if uniform(&mut rng).ln() < ly - lp[i] {
                x[i].copy_from_slice(&y);
                lp[i] = ly;
                if it >= s.tune {
                    accepted[i] += 1;
                }
            }
        }
        if it % s.archive_every == s.archive_every - 1 {
            archive.extend(x.iter().cloned());
        }
        if it >= s.tune && (it - s.tune).is_multiple_of(s.thin) {
            for i in 0..n {
                chains[i].push(x[i].clone());
                logp[i].push(lp[i]);
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

/// Runs `settings.populations` DE-MCz populations in parallel.
pub fn sample_demc(
    density: &dyn LogDensity,
    start: &Start,
    settings: &DemcSettings,
    seed: u64,
    progress: Option<&(dyn Fn(u64) + Sync)>,
) -> Result<SampleRun, McmcError> {
    let d = density.dim();
    start.check(d)?;
    let std = Standardized::new(density, start);
    let unit = Start::ball(vec![0.0; d], 1.0);
    let (density, start): (&dyn LogDensity, &Start) = (&std, &unit);
    check_settings(settings)?;
    let t0 = std::time::Instant::now();
    let outs: Vec<GroupOut> = (0..settings.populations)
        .into_par_iter()
        .map(|p| run_population(density, start, settings, seed, p, progress))
        .collect::<Result<_, _>>()?;
    Ok(SampleRun::from_groups(
        "demc",
        outs,
        settings.draws * settings.thin,
        &std,
        t0,
    ))
}
