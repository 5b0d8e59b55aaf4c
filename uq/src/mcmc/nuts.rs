//! The No-U-Turn sampler: multinomial NUTS with dual-averaging step size and
//! windowed diagonal mass-matrix adaptation.
//!
//! * Trajectory building and the U-turn criterion: Hoffman & Gelman (2014),
//!   "The No-U-Turn Sampler", *JMLR* 15, algorithms 3 and 6; the multinomial
//!   variant (trajectory states weighted by exp(-H), biased progressive
//!   sampling between the old tree and a new subtree, uniform progressive
//!   sampling inside subtrees) and the generalised criterion on the summed
//!   momentum rho: Betancourt (2017), "A conceptual introduction to
//!   Hamiltonian Monte Carlo", arXiv:1701.02434, appendix A.3-A.4; the extra
//!   checks across the two halves of a merged tree follow Stan >= 2.26.
//! * Step size: dual averaging (Hoffman & Gelman algorithm 5, gamma = 0.05,
//!   t0 = 10, kappa = 0.75, target acceptance 0.8) after the initial-step
//!   heuristic of their algorithm 4.
//! * Mass matrix: Stan's windowed adaptation (75-iteration initial buffer,
//!   doubling windows from 25, 50-iteration terminal buffer), the inverse
//!   metric set to the regularised sample variance
//!   (n / (n + 5)) var + 1e-3 (5 / (n + 5)).
//!
//! Written here rather than taken from nuts-rs 0.19: nuts-rs wants rand 0.10
//! (the workspace uses 0.9), brings arrow and another faer version into the
//! build, and owns seeding and threading of its chains, whereas palpate needs
//! one stream per chain from one seed so that results are bit-identical
//! whatever the thread count. The algorithm is ~300 lines and is checked here
//! against a correlated Gaussian with known moments.
//!
//! Gradients come from [`DensityWorker::value_and_gradient`](super::DensityWorker::value_and_gradient)
//! (finite differences unless the density provides exact ones).

use super::chains::{Chains, SampleRun};
use super::density::{Counted, LogDensity};
use super::error::McmcError;
use super::rng::{chain_rng, std_normal, uniform, ChainRng};
use super::standardized::Standardized;
use super::start::Start;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Settings of NUTS.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NutsSettings {
    /// Independent chains (run in parallel).
    pub chains: usize,
    /// Warm-up (adaptation) iterations, discarded.
    pub tune: usize,
    /// Stored draws per chain.
    pub draws: usize,
    /// Maximum tree depth (at most 2^depth - 1 leapfrog steps).
    pub max_depth: usize,
    /// Target mean acceptance statistic of the dual averaging.
    pub target_accept: f64,
    /// An energy error above this is a divergence.
    pub max_energy_error: f64,
}

impl Default for NutsSettings {
    fn default() -> Self {
        NutsSettings {
            chains: 4,
            tune: 1000,
            draws: 1000,
            max_depth: 10,
            target_accept: 0.8,
            max_energy_error: 1000.0,
        }
    }
}

#[derive(Clone)]
struct Point {
    q: Vec<f64>,
    p: Vec<f64>,
    g: Vec<f64>,
    logp: f64,
}

struct Ctx<'a, 'b> {
    w: &'a mut Counted<'b>,
    minv: &'a [f64],
    eps: f64,
    h0: f64,
    max_err: f64,
    rng: &'a mut ChainRng,
}

impl Ctx<'_, '_> {
    fn energy(&self, pt: &Point) -> f64 {
        -pt.logp
            + 0.5
                * pt.p
                    .iter()
                    .zip(self.minv)
                    .map(|(p, m)| p * p * m)
                    .sum::<f64>()
    }

    fn leapfrog(&mut self, from: &Point, dir: f64) -> Point {
        let e = dir * self.eps;
        let mut pt = from.clone();
        for k in 0..pt.q.len() {
            pt.p[k] += 0.5 * e * pt.g[k];
            pt.q[k] += e * self.minv[k] * pt.p[k];
        }
        pt.logp = self.w.value_and_gradient(&pt.q, &mut pt.g);
        for k in 0..pt.q.len() {
            pt.p[k] += 0.5 * e * pt.g[k];
        }
        pt
    }

    /// True when the trajectory with summed momentum `rho` between end
    /// momenta `pl` (backward end) and `pr` (forward end) makes a U-turn.
    fn turning(&self, rho: &[f64], pl: &[f64], pr: &[f64]) -> bool {
        let dl: f64 = pl
            .iter()
            .zip(self.minv)
            .zip(rho)
            .map(|((p, m), r)| p * m * r)
            .sum();
        let dr: f64 = pr
            .iter()
            .zip(self.minv)
            .zip(rho)
            .map(|((p, m), r)| p * m * r)
            .sum();
        dl <= 0.0 || dr <= 0.0
    }
}

struct Tree {
    left: Point,
    right: Point,
    proposal: Point,
    log_w: f64,
    rho: Vec<f64>,
}

#[derive(Default)]
struct Stats {
    n_leapfrog: usize,
    sum_accept: f64,
    divergent: bool,
}

fn log_add_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    if m == f64::NEG_INFINITY {
        m
    } else {
        m + ((a - m).exp() + (b - m).exp()).ln()
    }
}

fn vadd(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + y).collect()
}

/// Whether the merge of two adjacent trees given in spatial order (`l`
/// backward of `r`) makes a U-turn: `true` when the merged tree (or one of
/// the cross checks) turns.
fn merged_turns(ctx: &Ctx, l: &Tree, r: &Tree, rho: &[f64]) -> bool {
    ctx.turning(rho, &l.left.p, &r.right.p)
        || ctx.turning(&vadd(&l.rho, &r.left.p), &l.left.p, &r.left.p)
        || ctx.turning(&vadd(&l.right.p, &r.rho), &l.right.p, &r.right.p)
}

/// Builds a subtree of 2^depth leapfrog steps from `edge` in direction
/// `dir`; `None` when it diverged or turned (its states are then not used).
fn build(ctx: &mut Ctx, edge: &Point, dir: f64, depth: usize, st: &mut Stats) -> Option<Tree> {
    if depth == 0 {
        let pt = ctx.leapfrog(edge, dir);
        let h = ctx.energy(&pt);
        st.n_leapfrog += 1;
        let err = h - ctx.h0;
        if !err.is_finite() || err > ctx.max_err {
            st.divergent = true;
            return None;
        }
        st.sum_accept += (-err).exp().min(1.0);
        return Some(Tree {
            left: pt.clone(),
            right: pt.clone(),
            rho: pt.p.clone(),
            proposal: pt,
            log_w: -err,
        });
    }
    let a = build(ctx, edge, dir, depth - 1, st)?;
    let outer = if dir > 0.0 { &a.right } else { &a.left };
    let b = build(ctx, &outer.clone(), dir, depth - 1, st)?;
    let log_w = log_add_exp(a.log_w, b.log_w);
    let take_b = uniform(ctx.rng).ln() < b.log_w - log_w;
    let rho = vadd(&a.rho, &b.rho);
    let (l, r) = if dir > 0.0 { (&a, &b) } else { (&b, &a) };
    if merged_turns(ctx, l, r, &rho) {
        return None;
    }
    let (left, right) = (l.left.clone(), r.right.clone());
    let proposal = if take_b { b.proposal } else { a.proposal };
    Some(Tree {
        left,
        right,
        proposal,
        log_w,
        rho,
    })
}

/// One NUTS transition from `z0`; returns the new point and the statistics.
fn transition(ctx: &mut Ctx, z0: &Point, max_depth: usize) -> (Point, Stats) {
    let mut start = z0.clone();
    for k in 0..start.p.len() {
        start.p[k] = std_normal(ctx.rng) / ctx.minv[k].sqrt();
    }
    ctx.h0 = ctx.energy(&start);
    let mut tree = Tree {
        left: start.clone(),
        right: start.clone(),
        rho: start.p.clone(),
        proposal: start,
        log_w: 0.0,
    };
    let mut st = Stats::default();
    for depth in 0..max_depth {
        let dir = if uniform(ctx.rng) < 0.5 { -1.0 } else { 1.0 };
        let edge = if dir > 0.0 {
            tree.right.clone()
        } else {
            tree.left.clone()
        };
        let Some(sub) = build(ctx, &edge, dir, depth, &mut st) else {
            break;
        };
        if uniform(ctx.rng).ln() < sub.log_w - tree.log_w {
            tree.proposal = sub.proposal.clone();
        }
        tree.log_w = log_add_exp(tree.log_w, sub.log_w);
        let rho = vadd(&tree.rho, &sub.rho);
        let turned = if dir > 0.0 {
            merged_turns(ctx, &tree, &sub, &rho)
        } else {
            merged_turns(ctx, &sub, &tree, &rho)
        };
        if dir > 0.0 {
            tree.right = sub.right;
        } else {
            tree.left = sub.left;
        }
        tree.rho = rho;
        if turned {
            break;
        }
    }
    (tree.proposal, st)
}

/// Dual averaging of log step size (Hoffman & Gelman 2014, algorithm 5).
struct DualAveraging {
    mu: f64,
    h_bar: f64,
    log_eps: f64,
    log_eps_bar: f64,
    m: f64,
    target: f64,
}

impl DualAveraging {
    fn new(eps: f64, target: f64) -> Self {
        DualAveraging {
            mu: (10.0 * eps).ln(),
            h_bar: 0.0,
            log_eps: eps.ln(),
            log_eps_bar: 0.0,
            m: 0.0,
            target,
        }
    }
    fn update(&mut self, accept: f64) -> f64 {
        const T0: f64 = 10.0;
        const GAMMA: f64 = 0.05;
        const KAPPA: f64 = 0.75;
        self.m += 1.0;
        let w = 1.0 / (self.m + T0);
        self.h_bar = (1.0 - w) * self.h_bar + w * (self.target - accept);
        self.log_eps = self.mu - self.m.sqrt() / GAMMA * self.h_bar;
        let eta = self.m.powf(-KAPPA);
        self.log_eps_bar = eta * self.log_eps + (1.0 - eta) * self.log_eps_bar;
        self.log_eps.exp()
    }
    fn final_eps(&self) -> f64 {
        self.log_eps_bar.exp()
    }
}

/// Ends of the mass-matrix adaptation windows (Stan's schedule).
fn window_ends(tune: usize) -> Vec<usize> {
    if tune < 20 {
        return Vec::new();
    }
    let (init, term, base) = if tune >= 150 {
        (75, 50, 25)
    } else {
        let init = tune * 15 / 100;
        let term = tune / 10;
        (init, term, tune - init - term)
    };
    let last = tune - term;
    let mut ends = Vec::new();
    let mut start = init;
    let mut size = base;
    while start < last {
        let mut end = start + size;
        if end + 2 * size > last {
            end = last;
        }
        ends.push(end);
        start = end;
        size *= 2;
    }
    ends
}

/// Initial step size: double or halve until the one-step acceptance crosses
/// 1/2 (Hoffman & Gelman algorithm 4).
fn initial_eps(ctx: &mut Ctx, z: &Point) -> f64 {
    let mut pt = z.clone();
    for k in 0..pt.p.len() {
        pt.p[k] = std_normal(ctx.rng) / ctx.minv[k].sqrt();
    }
    ctx.h0 = ctx.energy(&pt);
    let log_ratio = |ctx: &mut Ctx| {
        let q = ctx.leapfrog(&pt, 1.0);
        let d = ctx.h0 - ctx.energy(&q);
        if d.is_finite() {
            d
        } else {
            f64::NEG_INFINITY
        }
    };
    let first = log_ratio(ctx);
    let dir: f64 = if first > 0.5f64.ln() { 1.0 } else { -1.0 };
    for _ in 0..60 {
        let lr = log_ratio(ctx);
        if lr.is_nan() || dir * lr <= -dir * 2f64.ln() {
            break;
        }
        ctx.eps *= 2f64.powf(dir);
    }
    ctx.eps
}

/// What one NUTS chain returns (draws in the standardised space).
pub(crate) struct ChainOut {
    pub(crate) draws: Vec<Vec<f64>>,
    pub(crate) logp: Vec<f64>,
    pub(crate) accept: f64,
    pub(crate) divergences: usize,
    pub(crate) eps: f64,
    pub(crate) evaluations: u64,
}

/// The checks of [`sample_nuts`]'s settings.
pub(crate) fn check_settings(settings: &NutsSettings) -> Result<(), McmcError> {
    if settings.chains == 0
        || settings.draws < 4
        || settings.max_depth == 0
        || !(settings.target_accept > 0.0 && settings.target_accept < 1.0)
    {
        return Err(McmcError::InvalidSettings {
            field: "chains/draws/max_depth/target_accept".into(),
            reason: "need chains >= 1, draws >= 4, max_depth >= 1, 0 < target_accept < 1".into(),
        });
    }
    Ok(())
}

/// Chain `c` of a NUTS run, alone: its stream is `chain_rng(seed, c)`, so
/// it is the same whichever other chains run, where, or when.
pub(crate) fn run_chain(
    density: &dyn LogDensity,
    start: &Start,
    s: &NutsSettings,
    seed: u64,
    c: usize,
    progress: Option<&(dyn Fn(u64) + Sync)>,
) -> Result<ChainOut, McmcError> {
    let d = density.dim();
    let mut rng = chain_rng(seed, c);
    let mut w = Counted::new(density.worker());
    let (z, _) = start.draw(&mut rng, &mut w, c)?;
    let mut g = vec![0.0; d];
    let logp = w.value_and_gradient(&z, &mut g);
    if !logp.is_finite() {
        return Err(McmcError::NoFiniteStart { chain: c, tries: 1 });
    }
    let mut cur = Point {
        q: z,
        p: vec![0.0; d],
        g,
        logp,
    };
    let mut minv: Vec<f64> = start.scale.iter().map(|s| (s * s).max(1e-300)).collect();
    let ends = window_ends(s.tune);
    let window_start = |i: usize| {
        if i == 0 {
            if s.tune >= 150 {
                75
            } else {
                s.tune * 15 / 100
            }
        } else {
            ends[i - 1]
        }
    };
    let mut win = 0;
    let (mut n_w, mut mean_w, mut m2_w) = (0.0, vec![0.0; d], vec![0.0; d]);
    let mut ctx_eps = {
        let mut ctx = Ctx {
            w: &mut w,
            minv: &minv,
            eps: 1.0,
            h0: 0.0,
            max_err: s.max_energy_error,
            rng: &mut rng,
        };
        initial_eps(&mut ctx, &cur)
    };
    let mut da = DualAveraging::new(ctx_eps, s.target_accept);
    let mut out = ChainOut {
        draws: Vec::with_capacity(s.draws),
        logp: Vec::with_capacity(s.draws),
        accept: 0.0,
        divergences: 0,
        eps: 0.0,
        evaluations: 0,
    };
    for it in 0..s.tune + s.draws {
        let (next, st) = {
            let mut ctx = Ctx {
                w: &mut w,
                minv: &minv,
                eps: ctx_eps,
                h0: 0.0,
                max_err: s.max_energy_error,
                rng: &mut rng,
            };
            transition(&mut ctx, &cur, s.max_depth)
        };
        cur = next;
        let accept = if st.n_leapfrog > 0 {
            st.sum_accept / st.n_leapfrog as f64
        } else {
            0.0
        };
        if it < s.tune {
            ctx_eps = da.update(accept);
            if win < ends.len() && it >= window_start(win) {
                n_w += 1.0;
                for k in 0..d {
                    let delta = cur.q[k] - mean_w[k];
                    mean_w[k] += delta / n_w;
                    m2_w[k] += delta * (cur.q[k] - mean_w[k]);
                }
                if it + 1 == ends[win] {
                    for k in 0..d {
                        let var = m2_w[k] / (n_w - 1.0);
                        minv[k] = (n_w / (n_w + 5.0)) * var + 1e-3 * (5.0 / (n_w + 5.0));
                    }
                    let mut ctx = Ctx {
                        w: &mut w,
                        minv: &minv,
                        eps: ctx_eps,
                        h0: 0.0,
                        max_err: s.max_energy_error,
                        rng: &mut rng,
                    };
                    ctx_eps = initial_eps(&mut ctx, &cur);
                    da = DualAveraging::new(ctx_eps, s.target_accept);
                    win += 1;
                    n_w = 0.0;
                    mean_w.iter_mut().for_each(|v| *v = 0.0);
                    m2_w.iter_mut().for_each(|v| *v = 0.0);
                }
            }
            if it + 1 == s.tune {
                ctx_eps = da.final_eps();
            }
        } else {
            out.accept += accept / s.draws as f64;
            out.divergences += st.divergent as usize;
            out.draws.push(cur.q.clone());
            out.logp.push(cur.logp);
        }
        if let Some(p) = progress {
            if it % 100 == 99 {
                p(100);
            }
        }
    }
    out.eps = ctx_eps;
    out.evaluations = w.evaluations;
    Ok(out)
}

/// Runs `settings.chains` NUTS chains in parallel.
pub fn sample_nuts(
    density: &dyn LogDensity,
    start: &Start,
    settings: &NutsSettings,
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
    let outs: Vec<ChainOut> = (0..settings.chains)
        .into_par_iter()
        .map(|c| run_chain(density, start, settings, seed, c, progress))
        .collect::<Result<_, _>>()?;
    let mut all = Vec::new();
    let mut run = SampleRun {
        sampler: "nuts".into(),
        chains: Chains::from_nested(&[]),
        log_density: Vec::new(),
        acceptance: Vec::new(),
        evaluations: 0,
        wall_time_s: 0.0,
        divergences: Vec::new(),
        step_size: Vec::new(),
    };
    for o in outs {
        all.push(o.draws);
        run.log_density.push(o.logp);
        run.acceptance.push(o.accept);
        run.divergences.push(o.divergences);
        run.step_size.push(o.eps);
        run.evaluations += o.evaluations;
    }
    run.chains = Chains::from_nested(&all).map(|y| std.to_original(y));
    run.wall_time_s = t0.elapsed().as_secs_f64();
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_follow_stan_schedule() {
        assert_eq!(window_ends(1000), vec![100, 150, 250, 450, 950]);
        assert!(window_ends(10).is_empty());
    }
}
