//! Draws of several chains and what the sampler spent on them.

use serde::{Deserialize, Serialize};

/// Draws stored chain-major: value of parameter `k` at draw `t` of chain `c`
/// is `values[(c * n_draws + t) * dim + k]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Chains {
    pub n_chains: usize,
    pub n_draws: usize,
    pub dim: usize,
    pub values: Vec<f64>,
}

impl Chains {
    /// Chains from per-chain draw lists (`chains[c][t]` is a point).
    pub fn from_nested(chains: &[Vec<Vec<f64>>]) -> Chains {
        let n_chains = chains.len();
        let n_draws = chains.first().map_or(0, |c| c.len());
        let dim = chains
            .first()
            .and_then(|c| c.first())
            .map_or(0, |p| p.len());
        let mut values = Vec::with_capacity(n_chains * n_draws * dim);
        for c in chains {
            for p in c {
                values.extend_from_slice(p);
            }
        }
        Chains {
            n_chains,
            n_draws,
            dim,
            values,
        }
    }

    /// One point.
    pub fn point(&self, chain: usize, draw: usize) -> &[f64] {
        let i = (chain * self.n_draws + draw) * self.dim;
        &self.values[i..i + self.dim]
    }

    /// Parameter `k` as one series per chain (the `(chain, draw)` array of ArviZ).
    pub fn param(&self, k: usize) -> Vec<Vec<f64>> {
        (0..self.n_chains)
            .map(|c| (0..self.n_draws).map(|t| self.point(c, t)[k]).collect())
            .collect()
    }

    /// Every point, chain after chain.
    pub fn points(&self) -> impl Iterator<Item = &[f64]> {
        self.values.chunks_exact(self.dim.max(1))
    }

    /// The same draws mapped point by point (e.g. unbounded -> physical).
    pub fn map(&self, f: impl Fn(&[f64]) -> Vec<f64>) -> Chains {
        let mut values = Vec::with_capacity(self.values.len());
        let mut dim = self.dim;
        for p in self.points() {
            let q = f(p);
            dim = q.len();
            values.extend(q);
        }
        Chains {
            n_chains: self.n_chains,
            n_draws: self.n_draws,
            dim,
            values,
        }
    }

    /// CSV text with columns `chain,draw,<names...>`.
    pub fn to_csv(&self, names: &[String]) -> String {
        let mut s = String::from("chain,draw");
        for n in names {
            s.push(',');
            s.push_str(n);
        }
        s.push('\n');
        for c in 0..self.n_chains {
            for t in 0..self.n_draws {
                s.push_str(&format!("{c},{t}"));
                for v in self.point(c, t) {
                    s.push_str(&format!(",{v:e}"));
                }
                s.push('\n');
            }
        }
        s
    }
}

/// What a sampler produced: the draws in the sampler's (unbounded) space and
/// its bookkeeping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleRun {
    /// Sampler name (`ensemble`, `demc`, `nuts`).
    pub sampler: String,
    /// Draws after warm-up, in the unbounded space.
    pub chains: Chains,
    /// Log-density of each stored draw, `[chain][draw]`.
    pub log_density: Vec<Vec<f64>>,
    /// Fraction of accepted proposals per chain after warm-up (NUTS: mean
    /// acceptance statistic).
    pub acceptance: Vec<f64>,
    /// Log-density evaluations, warm-up included (a finite-difference
    /// gradient counts 2 d + 1).
    pub evaluations: u64,
    /// Wall-clock time of the whole run in seconds.
    pub wall_time_s: f64,
    /// NUTS only: divergent transitions after warm-up, per chain.
    pub divergences: Vec<usize>,
    /// NUTS only: adapted step size per chain.
    pub step_size: Vec<f64>,
}

/// What one group of chains that run together returns (a DE-MCz population,
/// an ensemble of walkers): draws `[chain][draw][dim]` in the standardised
/// space, their log-densities, accepted proposals per chain, evaluations.
pub(crate) struct GroupOut {
    pub chains: Vec<Vec<Vec<f64>>>,
    pub logp: Vec<Vec<f64>>,
    pub accepted: Vec<usize>,
    pub evaluations: u64,
}

impl SampleRun {
    /// Concatenates the groups' chains in group order (fixed, so the result
    /// does not depend on the thread count), maps the draws back from the
    /// standardised space, and turns accepted counts into rates over
    /// `iterations` post-warm-up proposals per chain.
    pub(crate) fn from_groups(
        sampler: &str,
        groups: Vec<GroupOut>,
        iterations: usize,
        std: &super::standardized::Standardized<'_>,
        started: std::time::Instant,
    ) -> SampleRun {
        let mut all = Vec::new();
        let mut logp = Vec::new();
        let mut acceptance = Vec::new();
        let mut evaluations = 0;
        for g in groups {
            acceptance.extend(g.accepted.iter().map(|&a| a as f64 / iterations as f64));
            all.extend(g.chains);
            logp.extend(g.logp);
            evaluations += g.evaluations;
        }
        SampleRun {
            sampler: sampler.into(),
            chains: Chains::from_nested(&all).map(|y| std.to_original(y)),
            log_density: logp,
            acceptance,
            evaluations,
            wall_time_s: started.elapsed().as_secs_f64(),
            divergences: Vec::new(),
            step_size: Vec::new(),
        }
    }
}
