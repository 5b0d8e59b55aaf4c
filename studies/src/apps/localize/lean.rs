//! The end lean of a nodule's excess force (`palpate localize --scan
//! lean`): near the block's ends translation invariance fails and one
//! nodule's excess E(p - x_n; d) peaks a little away from x_n, towards the
//! nearer end for shallow nodules and away from it for deep ones
//! (docs/validation/r2-localisation.md, `tools/src/bin/r2_excess_shape.rs`). The
//! centre model, which assumes the excess the same everywhere, then reads
//! shallow nodules 25-45 mm from an end ~0.16 mm towards it, twice their
//! posterior SD.
//!
//! This module models the lean as a shift only, one number per nodule
//! position and depth:
//!
//!   E_end(p; x_n, d) = E_centre(p - x_n + sgn(x_n) delta(e, d); d),
//!
//! e = the distance from x_n to the nearer end, sgn = +1 left of the
//! block's centre and -1 right of it (the mirror image), delta > 0 a peak
//! moved towards the nearer end. delta is measured on FE scans past one
//! nodule at a few (e, d) (the same FE model as the centre scans), each
//! fitted to the centre model's excess by a shift and an amplitude
//! ([`fit_shift`]), and interpolated bilinearly in (e, d); it is zero from
//! the last measured distance to the centre. One number per scan cannot fit
//! the centre surrogate's own error or the mesh differences between scans
//! the way a correction of the whole curve did (that fitted ~0.1 N of
//! noise and cost depth accuracy).

use super::{LocModel, LocSetup};
use crate::run::surrogate::load_or_compute;
use palpate_fe::r2_scan::R2NoduleScan;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Measured shifts on a grid of (distance to the nearer end, depth).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Lean {
    /// Distances from the nodule's centre to the nearer block end (mm),
    /// increasing.
    pub distance: Vec<f64>,
    /// Nodule depths (mm), increasing.
    pub depth: Vec<f64>,
    /// `shift[i][j]`: delta (mm) at `distance[i]`, `depth[j]`, positive
    /// towards the nearer end.
    pub shift: Vec<Vec<f64>>,
    /// The fitted amplitude of each scan relative to the centre's excess
    /// (reported, not used: the scale nuisance and the depth absorb it).
    pub amplitude: Vec<Vec<f64>>,
    /// The half-distance between the block's ends (mm): delta falls
    /// linearly from its value at the last `distance` to zero there.
    pub centre: f64,
}

/// Linear interpolation weights of `v` in the increasing `grid`, clamped to
/// its ends: `(k, t)` with the value `(1 - t) g[k] + t g[k + 1]`.
fn locate(grid: &[f64], v: f64) -> (usize, f64) {
    let n = grid.len();
    if n < 2 || v <= grid[0] {
        return (0, 0.0);
    }
    if v >= grid[n - 1] {
        return (n - 2, 1.0);
    }
    let k = grid
        .partition_point(|&g| g <= v)
        .saturating_sub(1)
        .min(n - 2);
    (k, (v - grid[k]) / (grid[k + 1] - grid[k]))
}

impl Lean {
    /// delta (mm, towards the nearer end) of a nodule at distance `e` from
    /// the nearer end and depth `d`: bilinear in the grid, the depth
    /// clamped to its range, and linear to zero between the last distance
    /// and the centre.
    pub fn delta(&self, e: f64, d: f64) -> f64 {
        if self.distance.is_empty() || self.depth.is_empty() {
            return 0.0;
        }
        let (j, u) = locate(&self.depth, d);
        let at = |i: usize| {
            let row = &self.shift[i];
            if row.len() < 2 {
                row[0]
            } else {
                (1.0 - u) * row[j] + u * row[j + 1]
            }
        };
        let last = self.distance.len() - 1;
        if e >= self.distance[last] {
            let span = self.centre - self.distance[last];
            if span <= 0.0 || e >= self.centre {
                return 0.0;
            }
            return at(last) * (self.centre - e) / span;
        }
        if self.distance.len() < 2 {
            return at(0);
        }
        let (i, t) = locate(&self.distance, e);
        (1.0 - t) * at(i) + t * at(i + 1)
    }

    /// The signed shift to add to a wheel offset `p - x` of a nodule at `x`
    /// and depth `d`, on a block whose centre is `self.centre`.
    pub fn offset_shift(&self, x: f64, d: f64) -> f64 {
        let left = x <= self.centre;
        let e = if left { x } else { 2.0 * self.centre - x };
        let delta = self.delta(e, d);
        if left {
            delta
        } else {
            -delta
        }
    }
}

/// The shift `delta` and amplitude `a` that fit `excess[k]` at offsets
/// `offsets[k]` (nodule at the block's left half: the nearer end at
/// negative offsets) by `a centre(o + delta)`: least squares, `a` in closed
/// form for each `delta`, `delta` by golden-section search on
/// `[-max_shift, max_shift]` after a coarse scan (the misfit is smooth and,
/// for the sub-millimetre shifts here, unimodal near its minimum).
pub fn fit_shift(
    offsets: &[f64],
    excess: &[f64],
    centre: impl Fn(f64) -> f64,
    max_shift: f64,
) -> (f64, f64) {
    let misfit = |delta: f64| -> (f64, f64) {
        let (mut sxy, mut syy) = (0.0, 0.0);
        for (&o, &e) in offsets.iter().zip(excess) {
            let c = centre(o + delta);
            sxy += c * e;
            syy += c * c;
        }
        let a = if syy > 0.0 { sxy / syy } else { 0.0 };
        let r: f64 = offsets
            .iter()
            .zip(excess)
            .map(|(&o, &e)| {
                let r = e - a * centre(o + delta);
                r * r
            })
            .sum();
        (r, a)
    };
    // coarse scan, then golden section around the best point
    let n = 40;
    let h = 2.0 * max_shift / n as f64;
    let best = (0..=n)
        .map(|k| -max_shift + h * k as f64)
        .min_by(|a, b| misfit(*a).0.total_cmp(&misfit(*b).0))
        .unwrap_or(0.0);
    let (mut lo, mut hi) = ((best - h).max(-max_shift), (best + h).min(max_shift));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (hi - g * (hi - lo), lo + g * (hi - lo));
    for _ in 0..60 {
        if misfit(c).0 < misfit(d).0 {
            hi = d;
        } else {
            lo = c;
        }
        c = hi - g * (hi - lo);
        d = lo + g * (hi - lo);
    }
    let delta = 0.5 * (lo + hi);
    (delta, misfit(delta).1)
}

/// The (distance from the nearer end, depth) of each lean FE scan, in
/// the order of [`Lean::shift`]'s rows then columns.
pub fn cases() -> Vec<(f64, f64)> {
    LocSetup::LEAN_DISTANCES
        .iter()
        .flat_map(|&e| LocSetup::LEAN_DEPTHS.iter().map(move |&d| (e, d)))
        .collect()
}

/// The lean FE scan of `case` (distance `e` from the left end, depth `d`):
/// the force at the wheel offsets [`LocSetup::lean_offsets`] from the
/// nodule (offsets off the rolled path clamped to it), or why it failed.
pub fn scan(setup: &LocSetup, case: (f64, f64)) -> Result<Vec<f64>, String> {
    let (e, d) = case;
    R2NoduleScan::along_block(setup.template.clone(), false)
        .scan(&[d, e.ln()], &setup.lean_offsets())
        .map_err(|err| format!("the R2 lean scan at x = {e} mm, depth {d} mm: {err}"))
}

/// The end lean of the centre model `model`: FE scans past one nodule at
/// each of the setup's distances from the end and depths (cached, in
/// parallel, with a progress bar), each fitted to this model's excess by a
/// shift and an amplitude ([`from_runs`]).
pub fn load_or_measure(model: &LocModel, setup: &LocSetup, cache: &Path) -> anyhow::Result<Lean> {
    let cases = cases();
    let (runs, _) = load_or_compute("r2-lean", &setup.lean_description(), cache, || {
        use rayon::prelude::*;
        let bar = crate::run::limits::Progress::new(
            cases.len() as u64,
            &format!("R2 end-lean FE scans, RD {}", setup.template.rd),
            "{msg} [{bar:40}] {pos}/{len} FE scans ({elapsed}, eta {eta})",
        );
        let runs: Vec<Vec<f64>> = cases
            .par_iter()
            .map(|&c| {
                let r = scan(setup, c);
                bar.inc(1);
                r.map_err(|err| anyhow::anyhow!(err))
            })
            .collect::<anyhow::Result<_>>()?;
        bar.finish();
        Ok(runs)
    })?;
    from_runs(model, setup, &runs)
}

/// The lean from the FE scans `runs` of [`cases`] (in that order, each at
/// [`LocSetup::lean_offsets`]): each scan's excess over `model`'s
/// nodule-free pass, on the rolled path, fitted by [`fit_shift`] to the
/// centre model's excess at the same depth.
pub fn from_runs(model: &LocModel, setup: &LocSetup, runs: &[Vec<f64>]) -> anyhow::Result<Lean> {
    let cases = cases();
    let offsets = setup.lean_offsets();
    anyhow::ensure!(
        runs.len() == cases.len(),
        "{} lean scans for the {} of the model at RD {}",
        runs.len(),
        cases.len(),
        setup.template.rd
    );
    let (lo, hi) = model.path;
    let mut grid = vec![0.0; model.scan.loading().len()];
    let nd = LocSetup::LEAN_DEPTHS.len();
    let mut shift = vec![vec![0.0; nd]; LocSetup::LEAN_DISTANCES.len()];
    let mut amplitude = shift.clone();
    for (k, (&(e, d), forces)) in cases.iter().zip(runs).enumerate() {
        anyhow::ensure!(
            forces.len() == offsets.len(),
            "the lean scan at x = {e} mm, depth {d} mm has {} forces for {} offsets",
            forces.len(),
            offsets.len()
        );
        // the excess at the offsets on the rolled path
        let (mut os, mut es) = (Vec::new(), Vec::new());
        for (&o, &f) in offsets.iter().zip(forces) {
            if e + o >= lo - 1e-9 && e + o <= hi + 1e-9 {
                os.push(o);
                es.push(f - model.baseline_at(e + o));
            }
        }
        model.excess_grid(d, model.centre, &mut grid)?;
        let (delta, a) = fit_shift(&os, &es, |o| model.excess_at(&grid, o, false), model.step);
        shift[k / nd][k % nd] = delta;
        amplitude[k / nd][k % nd] = a;
    }
    Ok(Lean {
        distance: LocSetup::LEAN_DISTANCES.to_vec(),
        depth: LocSetup::LEAN_DEPTHS.to_vec(),
        shift,
        amplitude,
        centre: model.centre,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bell curve shifted by 0.3 mm and scaled by 0.9 is fitted back.
    #[test]
    fn a_shifted_scaled_curve_is_fitted_back() {
        let centre = |o: f64| 5.0 * (-(o * o) / 30.0).exp();
        let offsets: Vec<f64> = (-6..=6).map(|k| 2.0 * k as f64).collect();
        let excess: Vec<f64> = offsets.iter().map(|&o| 0.9 * centre(o + 0.3)).collect();
        let (delta, a) = fit_shift(&offsets, &excess, centre, 1.0);
        assert!((delta - 0.3).abs() < 1e-6, "{delta}");
        assert!((a - 0.9).abs() < 1e-6, "{a}");
    }

    /// Bilinear inside the grid, clamped in depth, linear to zero at the
    /// centre, mirrored right of it.
    #[test]
    fn the_shift_interpolates_and_mirrors() {
        let lean = Lean {
            distance: vec![20.0, 40.0],
            depth: vec![10.0, 20.0],
            shift: vec![vec![0.4, -0.2], vec![0.2, -0.1]],
            amplitude: vec![vec![1.0; 2]; 2],
            centre: 75.0,
        };
        assert!((lean.delta(20.0, 10.0) - 0.4).abs() < 1e-12);
        assert!((lean.delta(30.0, 15.0) - 0.075).abs() < 1e-12);
        assert!((lean.delta(10.0, 5.0) - 0.4).abs() < 1e-12);
        assert!((lean.delta(57.5, 10.0) - 0.1).abs() < 1e-12);
        assert_eq!(lean.delta(75.0, 10.0), 0.0);
        assert!((lean.offset_shift(20.0, 10.0) - 0.4).abs() < 1e-12);
        assert!((lean.offset_shift(130.0, 10.0) + 0.4).abs() < 1e-12);
    }
}
