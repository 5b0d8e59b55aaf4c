//! The posterior of the nodules' positions and depths given an R2 record,
//! sampled by palpate-uq's NUTS (default) or its affine-invariant ensemble
//! sampler (`palpate_uq::mcmc`, extended until R-hat < 1.01 and bulk ESS >=
//! 400 or a draw cap), on the model of [`super::LocModel`].
//!
//! Why NUTS by default: on the RD 6 three-nodule record (8 parameters) the
//! ensemble sampler stopped at its draw cap with R-hat 1.03-1.04 on every
//! record tried (50 seeds), in 10-60 s; NUTS (4 chains, gradients
//! by finite differences of the surrogate's density) converges to R-hat
//! 1.005 with the same means and SDs to 0.01 mm, in 4.7 s for the whole
//! study step (docs/validation/r2-localisation.md).
//!
//! Parameters: per nodule x_n (uniform on the rolled path) and d_n (uniform
//! on the surrogate's depth box), the modulus scale s (log-uniform on
//! [1/2, 2]), the noise SD sigma (log-uniform on [1e-4, 0.2] x the mean
//! force). Labels are fixed by ordering: x_1 < x_2 - 10 mm < ... (the
//! nodules are 10 mm across and cannot overlap in x closer than that).
//! Likelihood: independent Gaussian residuals with variance sigma^2 + the
//! surrogate's held-out error variance at the record's position
//! (`Surrogate::validation().error_variance`, summed over the nodules).
//! The posterior is palpate-uq's
//! [`ModelErrorPosterior`] of the model as a `ForwardModel`
//! ([`super::forward::LocForward`], which states that error variance): its
//! priors (uniform on x_n and d_n, `Prior::LogUniform` on s and sigma),
//! the ordering constraint as a joint prior term ([`log_prior_terms`]), the bound transforms
//! (logit of every parameter's box) and their Jacobian those of
//! palpate-core's `ParamSpace`.
//!
//! Chains start in a small ball (in the unbounded coordinates) around a
//! grid fit (peaks of the record's excess over F0, then coordinate sweeps
//! over x and depth).
//!
//! A depth is `identifiable` when its posterior is bounded by the data
//! inside the box: less than 0.5 % of the draws within 2.5 % of the box
//! width (0.45 mm) of either end ([`bounded_inside`]; the box's upper end,
//! 24 mm, is the end of the studied range 8-24 mm and the deepest nodule
//! the block holds; a posterior that reaches it is the paper's "NI").

use super::forward::LocForward;
use super::LocModel;
use palpate_core::{Evaluator, ForwardModel, Loading, ParamSpec};
use palpate_uq::likelihood::Prior;
use palpate_uq::mcmc::{
    sample_until_converged, summarize, Chains, Convergence, EnsembleSettings, NutsSettings,
    Sampler, Start,
};
use palpate_uq::model_error::ModelErrorPosterior;
use serde::{Deserialize, Serialize};

/// Smallest x distance between two nodules' centres (mm): a diameter.
pub const MIN_SEPARATION: f64 = 10.0;

/// mean, SD and 94 % HDI of one quantity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    pub mean: f64,
    pub sd: f64,
    pub hdi_3: f64,
    pub hdi_97: f64,
}

/// One nodule's estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoduleEstimate {
    pub x_mm: Interval,
    pub depth_mm: Interval,
    pub identifiable: bool,
}

/// The surrogate's size and error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurrogateInfo {
    pub fe_runs: usize,
    pub max_rel_error: f64,
}

/// The JSON of `palpate localize --json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Localisation {
    pub nodules: Vec<NoduleEstimate>,
    pub noise_sd: f64,
    pub surrogate: SurrogateInfo,
    pub rhat_max: f64,
    pub ess_bulk_min: f64,
}

/// What the sampler is asked.
#[derive(Debug, Clone)]
pub struct LocOptions {
    pub nodules: usize,
    pub seed: u64,
    /// Draw cap per walker (the run is extended up to it until converged).
    pub max_draws: usize,
    pub tune: usize,
    pub draws: usize,
    pub sampler: LocSampler,
}

/// The MCMC sampler of a localisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LocSampler {
    /// NUTS, 4 chains (`tune` and `draws` per chain).
    #[default]
    Nuts,
    /// The affine-invariant ensemble sampler, 2 ensembles of 2 x dim
    /// walkers (`tune` and `draws` per walker).
    Ensemble,
}

impl std::str::FromStr for LocSampler {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "nuts" => Ok(LocSampler::Nuts),
            "ensemble" => Ok(LocSampler::Ensemble),
            other => Err(format!("sampler `{other}`: expected nuts or ensemble")),
        }
    }
}

impl Default for LocOptions {
    fn default() -> Self {
        LocOptions {
            nodules: 3,
            seed: 1,
            max_draws: 4000,
            tune: 600,
            draws: 500,
            sampler: LocSampler::Nuts,
        }
    }
}

/// A localisation with the draws and the run's figures.
pub struct LocRun {
    pub result: Localisation,
    /// Physical draws: x_1, d_1, ..., x_N, d_N, s, sigma.
    pub chains: Chains,
    pub names: Vec<String>,
    /// Posterior mean fit at the record's positions.
    pub fit: Vec<f64>,
    pub converged: bool,
    pub scale: Interval,
    /// Grid-fit start (physical).
    pub start: Vec<f64>,
    pub wall_s: f64,
    pub evaluations: u64,
}

/// The joint prior term of the localisation (module docs): `-inf` unless
/// x_1 < x_2 - [`MIN_SEPARATION`] < ..., 0 otherwise. `x` holds x_1, d_1,
/// ..., x_N, d_N, s, sigma.
pub fn log_prior_terms(x: &[f64], n: usize) -> f64 {
    for k in 1..n {
        if x[2 * k] - x[2 * (k - 1)] < MIN_SEPARATION {
            return f64::NEG_INFINITY;
        }
    }
    0.0
}

/// Sum of squared residuals of nodules `nod` and scale `s` (infinite when
/// the model refuses them).
fn sse(ev: &mut dyn Evaluator, loading: &Loading, y: &[f64], nod: &[(f64, f64)], s: f64) -> f64 {
    let mut pred = vec![0.0; y.len()];
    if ev
        .predict_into(&LocForward::theta(nod, s), loading, &mut pred)
        .is_err()
    {
        return f64::INFINITY;
    }
    y.iter().zip(&pred).map(|(y, p)| (y - p).powi(2)).sum()
}

/// The grid fit the chains start from: `(nodules, s, sigma)`.
fn grid_start(
    model: &LocModel,
    fwd: &LocForward,
    x: &[f64],
    y: &[f64],
    f0: &[f64],
    n: usize,
) -> (Vec<(f64, f64)>, f64) {
    let loading = LocForward::loading(x);
    let mut ev = fwd.evaluator();
    let (lo, hi) = model.path;
    let (dlo, dhi) = model.depth_box;
    let mid = 0.5 * (dlo + dhi);
    // peaks of the excess, smoothed over +-2 mm
    let r: Vec<f64> = (0..x.len())
        .map(|i| {
            let w: Vec<usize> = (0..x.len())
                .filter(|&j| (x[j] - x[i]).abs() <= 2.0)
                .collect();
            w.iter().map(|&j| y[j] - f0[j]).sum::<f64>() / w.len() as f64
        })
        .collect();
    let mut nod: Vec<(f64, f64)> = Vec::new();
    for _ in 0..n {
        let best = (0..x.len())
            .filter(|&i| {
                nod.iter()
                    .all(|&(xn, _)| (x[i] - xn).abs() >= 1.5 * MIN_SEPARATION)
            })
            .max_by(|&a, &b| r[a].total_cmp(&r[b]));
        let xn = match best {
            Some(i) => x[i],
            None => lo + (hi - lo) * (nod.len() as f64 + 0.5) / n as f64,
        };
        nod.push((xn, mid));
    }
    nod.sort_by(|a, b| a.0.total_cmp(&b.0));
    // separation
    for k in 1..n {
        if nod[k].0 - nod[k - 1].0 < MIN_SEPARATION {
            nod[k].0 = nod[k - 1].0 + MIN_SEPARATION + 0.5;
        }
    }
    let depths: Vec<f64> = (0..=36)
        .map(|k| dlo + (dhi - dlo) * k as f64 / 36.0)
        .collect();
    let mut s = 1.0;
    for _sweep in 0..3 {
        for j in 0..n {
            let mut best = (sse(&mut *ev, &loading, y, &nod, s), nod[j]);
            for &d in &depths {
                for dx in -8..=8 {
                    let mut t = nod.clone();
                    t[j] = (
                        (nod[j].0 + 0.5 * dx as f64).clamp(lo + 0.01, hi - 0.01),
                        d.clamp(dlo + 1e-6, dhi - 1e-6),
                    );
                    let ordered = (1..n).all(|k| t[k].0 - t[k - 1].0 >= MIN_SEPARATION);
                    if !ordered {
                        continue;
                    }
                    let e = sse(&mut *ev, &loading, y, &t, s);
                    if e < best.0 {
                        best = (e, t[j]);
                    }
                }
            }
            nod[j] = best.1;
        }
        // best scale for these nodules (least squares, clamped to the prior)
        let mut p = vec![0.0; x.len()];
        if ev
            .predict_into(&LocForward::theta(&nod, 1.0), &loading, &mut p)
            .is_err()
        {
            p.copy_from_slice(f0);
        }
        let num: f64 = p.iter().zip(y).map(|(a, b)| a * b).sum();
        let den: f64 = p.iter().map(|a| a * a).sum();
        s = (num / den).clamp(0.51, 1.99);
    }
    (nod, s)
}

/// Edge band of [`bounded_inside`], as a fraction of the box width.
pub const EDGE_BAND: f64 = 0.025;
/// Largest posterior mass in an edge band of an identifiable depth.
pub const EDGE_MASS: f64 = 0.005;

/// Whether the draws are bounded by the data inside `[lo, hi]`: less than
/// [`EDGE_MASS`] of them within [`EDGE_BAND`] of the box width of either
/// end. (A test on the HDI would not do: the posterior of an invisible deep
/// nodule is flat over the deep part of the box, and a 94 % HDI of a flat
/// posterior can stop anywhere short of the end.)
pub fn bounded_inside(draws: &[f64], lo: f64, hi: f64) -> bool {
    let band = EDGE_BAND * (hi - lo);
    let n = draws.len().max(1) as f64;
    let low = draws.iter().filter(|&&d| d < lo + band).count() as f64 / n;
    let high = draws.iter().filter(|&&d| d > hi - band).count() as f64 / n;
    !draws.is_empty() && low < EDGE_MASS && high < EDGE_MASS
}

/// Samples the posterior of `n` nodules given the record (`x`
/// increasing, inside the path; `y` forces).
pub fn localize(
    model: &LocModel,
    x: &[f64],
    y: &[f64],
    o: &LocOptions,
    progress: Option<&(dyn Fn(u64) + Sync)>,
) -> anyhow::Result<LocRun> {
    let n = o.nodules;
    anyhow::ensure!(n >= 1, "--nodules {n}: at least one nodule");
    let (lo, hi) = model.path;
    anyhow::ensure!(
        (n - 1) as f64 * MIN_SEPARATION < hi - lo,
        "--nodules {n}: {n} nodules {MIN_SEPARATION} mm apart do not fit on the path {lo}..{hi} mm"
    );
    let t0 = std::time::Instant::now();
    let f0: Vec<f64> = x.iter().map(|&p| model.baseline_at(p)).collect();
    let mean_f = y.iter().map(|v| v.abs()).sum::<f64>() / y.len() as f64;
    let (dlo, dhi) = model.depth_box;
    let fwd = LocForward::new(model, n);
    let (nod, s) = grid_start(model, &fwd, x, y, &f0, n);
    let (p, _) = model.predict(x, &nod, s)?;
    let rms = (p.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / y.len() as f64)
        .sqrt()
        .clamp(2e-4 * mean_f, 0.1 * mean_f);
    let mut model_priors = Vec::with_capacity(2 * n + 1);
    for _ in 0..n {
        model_priors.push(Prior::Uniform {
            lower: lo,
            upper: hi,
        });
        model_priors.push(Prior::Uniform {
            lower: dlo,
            upper: dhi,
        });
    }
    let (s_lo, s_hi) = super::forward::SCALE_BOUNDS;
    model_priors.push(Prior::LogUniform {
        lower: s_lo,
        upper: s_hi,
    });
    let (sd_lo, sd_hi) = (1e-4 * mean_f, 0.2 * mean_f);
    let noise = ParamSpec::new("noise_sd_N", "N", sd_lo, sd_hi, rms);
    let posterior = ModelErrorPosterior::new(
        &fwd,
        LocForward::loading(x),
        y.to_vec(),
        model_priors,
        noise,
        Prior::LogUniform {
            lower: sd_lo,
            upper: sd_hi,
        },
    )
    .map_err(|e| anyhow::anyhow!("the localisation posterior: {e}"))?
    .with_joint_prior(Box::new(move |t: &[f64]| log_prior_terms(t, n)));
    let space = posterior.space().clone();
    let names = space.names();
    let mut start_phys = LocForward::theta(&nod, s);
    start_phys.push(rms);
    // strictly inside the boxes (the separation sweep may push the last
    // nodule past the path's end)
    let center: Vec<f64> = space
        .params
        .iter()
        .zip(&start_phys)
        .map(|(p, &v)| {
            let eps = 1e-6 * (p.upper - p.lower);
            p.to_unbounded(v.clamp(p.lower + eps, p.upper - eps))
        })
        .collect();
    let start = Start::ball(center, 0.01);
    let sampler = match o.sampler {
        LocSampler::Nuts => Sampler::Nuts(NutsSettings {
            chains: 4,
            tune: o.tune,
            draws: o.draws,
            ..Default::default()
        }),
        LocSampler::Ensemble => Sampler::Ensemble(EnsembleSettings {
            ensembles: 2,
            walkers: 0,
            tune: o.tune,
            draws: o.draws,
            thin: 1,
            a: 2.0,
        }),
    };
    let conv = Convergence {
        max_draws: o.max_draws.max(o.draws),
        ..Default::default()
    };
    let to_phys = |z: &[f64]| space.from_unbounded(z);
    let run = sample_until_converged(
        &sampler,
        &posterior,
        &start,
        o.seed,
        &conv,
        &to_phys,
        progress,
        &mut |_| {},
        &mut |_, _| {},
    )
    .map_err(|e| anyhow::anyhow!("sampling the localisation posterior: {e}"))?;
    let chains = run.run.chains.map(to_phys);
    let summary = summarize(&chains, &names);
    let iv = |k: usize| Interval {
        mean: summary[k].mean,
        sd: summary[k].sd,
        hdi_3: summary[k].hdi_3,
        hdi_97: summary[k].hdi_97,
    };
    let nodules: Vec<NoduleEstimate> = (0..n)
        .map(|j| {
            let draws: Vec<f64> = chains.param(2 * j + 1).into_iter().flatten().collect();
            NoduleEstimate {
                x_mm: iv(2 * j),
                depth_mm: iv(2 * j + 1),
                identifiable: bounded_inside(&draws, dlo, dhi),
            }
        })
        .collect();
    let mean_nod: Vec<(f64, f64)> = nodules
        .iter()
        .map(|e| (e.x_mm.mean, e.depth_mm.mean))
        .collect();
    let fit = model
        .predict(x, &mean_nod, summary[2 * n].mean)
        .map(|p| p.0)
        .unwrap_or_default();
    Ok(LocRun {
        result: Localisation {
            nodules,
            noise_sd: summary[2 * n + 1].mean,
            surrogate: SurrogateInfo {
                fe_runs: model.fe_runs(),
                max_rel_error: model.max_rel_error(),
            },
            rhat_max: run.worst.rhat_max,
            ess_bulk_min: run.worst.ess_bulk_min,
        },
        chains,
        names,
        fit,
        converged: run.converged,
        scale: iv(2 * n),
        start: start_phys,
        wall_s: t0.elapsed().as_secs_f64(),
        evaluations: run.evaluations,
    })
}
