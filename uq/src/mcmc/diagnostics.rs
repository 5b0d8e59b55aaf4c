//! Convergence diagnostics exactly as ArviZ computes them.
//!
//! * Rank-normalised split R-hat, the maximum of the bulk and the folded
//!   (tail) versions: Vehtari, Gelman, Simpson, Carpenter & Bürkner (2021),
//!   "Rank-normalization, folding, and localization: an improved R-hat",
//!   *Bayesian Analysis* 16(2), eqs. 1-4 and section 4.
//! * Bulk ESS (ESS of the rank-normalised split chains) and tail ESS (the
//!   minimum ESS of the 5 % and 95 % quantile indicators), same paper,
//!   section 4.3; the autocorrelation is combined across chains as in
//!   Stan / ArviZ and truncated by Geyer's initial positive sequence, then
//!   made monotone (Geyer 1992, "Practical Markov chain Monte Carlo",
//!   *Statistical Science* 7, section 3.3).
//! * MCSE of the mean: sd / sqrt(ESS of the split chains, no ranking).
//! * Integrated autocorrelation time tau = N_total / ESS.
//!
//! Each function takes the draws of one parameter as `chains[c][t]` (the
//! `(chain, draw)` array of ArviZ) and follows `arviz.stats.diagnostics`
//! (0.x) line by line, so results agree to rounding
//! (`uq/tests/integration/mcmc_arviz.rs` checks against committed ArviZ output). The
//! autocovariance is summed directly lag by lag instead of by FFT: the
//! Geyer truncation stops after a few autocorrelation times, so the direct
//! sum costs O(N tau), less than an FFT for well-mixed chains, and needs no
//! FFT crate.

use statrs::distribution::{ContinuousCDF, Normal};

/// Splits each chain into its first and last halves (the middle draw of an
/// odd-length chain is dropped), doubling the chain count.
pub fn split_chains(chains: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut out = Vec::with_capacity(2 * chains.len());
    for c in chains {
        let half = c.len() / 2;
        out.push(c[..half].to_vec());
    }
    for c in chains {
        let half = c.len() / 2;
        out.push(c[c.len() - half..].to_vec());
    }
    out
}

/// Rank normalisation: average ranks r over all draws, then
/// z = Phi^-1((r - 3/8) / (S - 3/4 + 1)) (Blom's offset; Vehtari et al. eq. 14).
pub fn z_scale(chains: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let flat: Vec<f64> = chains.iter().flatten().copied().collect();
    let ranks = average_ranks(&flat);
    let size = flat.len() as f64;
    let normal = Normal::standard();
    let mut it = ranks.into_iter();
    chains
        .iter()
        .map(|c| {
            c.iter()
                .map(|_| {
                    let r = it.next().unwrap_or(0.0);
                    normal.inverse_cdf((r - 0.375) / (size - 0.75 + 1.0))
                })
                .collect()
        })
        .collect()
}

/// Ranks 1..n with ties given their average rank (`scipy.stats.rankdata`, method "average").
fn average_ranks(x: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut ranks = vec![0.0; x.len()];
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && x[idx[j + 1]] == x[idx[i]] {
            j += 1;
        }
        let avg = (i + j) as f64 / 2.0 + 1.0;
        for &k in &idx[i..=j] {
            ranks[k] = avg;
        }
        i = j + 1;
    }
    ranks
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

fn var_ddof1(x: &[f64]) -> f64 {
    let m = mean(x);
    x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (x.len() as f64 - 1.0)
}

/// Classic (non-split, non-ranked) potential scale reduction of the given chains:
/// sqrt(((N - 1)/N W + B/N) / W) with B = N var(chain means), W = mean chain variance.
pub fn rhat_basic(chains: &[Vec<f64>]) -> f64 {
    let n = chains[0].len() as f64;
    let means: Vec<f64> = chains.iter().map(|c| mean(c)).collect();
    let b = n * var_ddof1(&means);
    let w = mean(&chains.iter().map(|c| var_ddof1(c)).collect::<Vec<_>>());
    ((b / w + n - 1.0) / n).sqrt()
}

/// Rank-normalised split R-hat: max of bulk R-hat and folded R-hat
/// (folding |x - median| with the median over all draws).
pub fn rhat(chains: &[Vec<f64>]) -> f64 {
    if !valid(chains, 4) {
        return f64::NAN;
    }
    let bulk = rhat_basic(&z_scale(&split_chains(chains)));
    let flat: Vec<f64> = chains.iter().flatten().copied().collect();
    let med = quantile(&flat, 0.5);
    let folded: Vec<Vec<f64>> = chains
        .iter()
        .map(|c| c.iter().map(|v| (v - med).abs()).collect())
        .collect();
    let tail = rhat_basic(&z_scale(&split_chains(&folded)));
    bulk.max(tail)
}

/// Bulk effective sample size.
pub fn ess_bulk(chains: &[Vec<f64>]) -> f64 {
    if !valid(chains, 4) {
        return f64::NAN;
    }
    ess_raw(&z_scale(&split_chains(chains)))
}

/// Tail effective sample size: min of the ESS of I(x <= q05) and I(x <= q95).
pub fn ess_tail(chains: &[Vec<f64>]) -> f64 {
    if !valid(chains, 4) {
        return f64::NAN;
    }
    ess_quantile(chains, 0.05).min(ess_quantile(chains, 0.95))
}

/// ESS of the indicator I(x <= q_p) on split chains.
pub fn ess_quantile(chains: &[Vec<f64>], p: f64) -> f64 {
    let flat: Vec<f64> = chains.iter().flatten().copied().collect();
    let q = quantile(&flat, p);
    let ind: Vec<Vec<f64>> = chains
        .iter()
        .map(|c| c.iter().map(|&v| if v <= q { 1.0 } else { 0.0 }).collect())
        .collect();
    ess_raw(&split_chains(&ind))
}

/// ESS for the mean (split chains, no rank normalisation).
pub fn ess_mean(chains: &[Vec<f64>]) -> f64 {
    if !valid(chains, 4) {
        return f64::NAN;
    }
    ess_raw(&split_chains(chains))
}

/// Monte Carlo standard error of the mean: sd (ddof 1, all draws) / sqrt(ess_mean).
pub fn mcse_mean(chains: &[Vec<f64>]) -> f64 {
    let flat: Vec<f64> = chains.iter().flatten().copied().collect();
    var_ddof1(&flat).sqrt() / ess_mean(chains).sqrt()
}

/// Integrated autocorrelation time of the (unsplit) chains, tau = N_total / ESS,
/// with ESS from Geyer's initial monotone sequence estimator.
pub fn integrated_autocorrelation_time(chains: &[Vec<f64>]) -> f64 {
    let total: usize = chains.iter().map(|c| c.len()).sum();
    total as f64 / ess_raw(chains)
}

fn valid(chains: &[Vec<f64>], min_draws: usize) -> bool {
    !chains.is_empty()
        && chains.iter().all(|c| c.len() == chains[0].len())
        && chains[0].len() >= min_draws
        && chains.iter().flatten().all(|v| v.is_finite())
}

/// Linear-interpolation quantile (`numpy.quantile`, method "linear").
pub fn quantile(x: &[f64], p: f64) -> f64 {
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    let pos = p * (s.len() as f64 - 1.0);
    let lo = pos.floor() as usize;
    let hi = (lo + 1).min(s.len() - 1);
    let frac = pos - lo as f64;
    s[lo] + frac * (s[hi] - s[lo])
}

/// Autocovariance at lag `t` with the 1/n normalisation of ArviZ's FFT version.
fn autocov(x: &[f64], m: f64, t: usize) -> f64 {
    let n = x.len();
    let mut s = 0.0;
    for i in 0..n - t {
        s += (x[i] - m) * (x[i + t] - m);
    }
    s / n as f64
}

/// ESS of the chains as given (ArviZ `_ess`): multi-chain autocorrelation
/// rho_t = 1 - (W - mean_c acov_c(t)) / var_plus, Geyer initial positive
/// then monotone sequence, tau = -1 + 2 sum rho, ESS = M N / max(tau, 1/log10(M N)).
pub fn ess_raw(chains: &[Vec<f64>]) -> f64 {
    let m = chains.len();
    let n = chains[0].len();
    let (lo, hi) = chains
        .iter()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi - lo < 1e-15 {
        return (m * n) as f64;
    }
    let means: Vec<f64> = chains.iter().map(|c| mean(c)).collect();
    let mean_acov = |t: usize| -> f64 {
        chains
            .iter()
            .zip(&means)
            .map(|(c, &mu)| autocov(c, mu, t))
            .sum::<f64>()
            / m as f64
    };
    let nf = n as f64;
    let mean_var = mean_acov(0) * nf / (nf - 1.0);
    let mut var_plus = mean_var * (nf - 1.0) / nf;
    if m > 1 {
        var_plus += var_ddof1(&means);
    }
    let mut rho = vec![0.0; n];
    let mut rho_even = 1.0;
    rho[0] = rho_even;
    let mut rho_odd = 1.0 - (mean_var - mean_acov(1)) / var_plus;
    rho[1] = rho_odd;
    let mut t = 1;
    while t + 3 < n && rho_even + rho_odd > 0.0 {
        rho_even = 1.0 - (mean_var - mean_acov(t + 1)) / var_plus;
        rho_odd = 1.0 - (mean_var - mean_acov(t + 2)) / var_plus;
        if rho_even + rho_odd >= 0.0 {
            rho[t + 1] = rho_even;
            rho[t + 2] = rho_odd;
        }
        t += 2;
    }
    // ArviZ's max_t = t - 2 may be -1 when the loop never ran (n < 5).
    let max_t = t as isize - 2;
    if rho_even > 0.0 {
        rho[(max_t + 1) as usize] = rho_even;
    }
    let mut t = 1isize;
    while t <= max_t - 2 {
        let u = t as usize;
        if rho[u + 1] + rho[u + 2] > rho[u - 1] + rho[u] {
            rho[u + 1] = (rho[u - 1] + rho[u]) / 2.0;
            rho[u + 2] = rho[u + 1];
        }
        t += 2;
    }
    let total = (m * n) as f64;
    let upto = (max_t + 1).max(0) as usize;
    let mut tau =
        -1.0 + 2.0 * rho[..upto].iter().sum::<f64>() + rho.get(upto).copied().unwrap_or(0.0);
    tau = tau.max(1.0 / total.log10());
    if rho.iter().any(|r| r.is_nan()) {
        return f64::NAN;
    }
    total / tau
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcmc::rng::{chain_rng, std_normal};

    fn ar1_chains(phi: f64, m: usize, n: usize, seed: u64) -> Vec<Vec<f64>> {
        (0..m)
            .map(|c| {
                let mut rng = chain_rng(seed, c);
                let mut x = std_normal(&mut rng) / (1.0 - phi * phi).sqrt();
                (0..n)
                    .map(|_| {
                        x = phi * x + std_normal(&mut rng);
                        x
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn iid_draws_have_rhat_one_and_full_ess() {
        let ch = ar1_chains(0.0, 4, 2000, 1);
        assert!((rhat(&ch) - 1.0).abs() < 0.005, "{}", rhat(&ch));
        let e = ess_bulk(&ch);
        assert!(e > 6500.0 && e < 9500.0, "{e}");
    }

    #[test]
    fn ar1_autocorrelation_time_matches_theory() {
        // tau = (1 + phi) / (1 - phi) = 9 for phi = 0.8.
        let ch = ar1_chains(0.8, 4, 20000, 2);
        let tau = integrated_autocorrelation_time(&ch);
        assert!((tau - 9.0).abs() < 0.6, "{tau}");
    }

    #[test]
    fn shifted_chain_is_flagged() {
        let mut ch = ar1_chains(0.0, 4, 1000, 3);
        for v in &mut ch[0] {
            *v += 1.0;
        }
        assert!(rhat(&ch) > 1.05, "{}", rhat(&ch));
    }

    #[test]
    fn ranks_average_ties() {
        assert_eq!(
            average_ranks(&[3.0, 1.0, 3.0, 2.0]),
            vec![3.5, 1.0, 3.5, 2.0]
        );
    }
}
