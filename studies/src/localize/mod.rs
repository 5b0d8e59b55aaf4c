//! R2 tumour localisation (`palpate localize --benchmark R2`): the force
//! record of a wheel rolled over a block with nodules is explained by
//!
//!   F(p) = s [ F0(p) + sum_n E(|p - x_n|; d_n) ],
//!
//! p the wheel position, F0 the FE force of the block without nodules, E the
//! excess force of ONE nodule at depth d at a wheel offset |p - x_n| from it
//! (translation invariance of the block away from its ends, and
//! superposition of the excesses of nodules far apart; both measured against
//! FE in docs/validation/r2-localisation.md), s a common scale of the tissue
//! and nodule moduli (a nuisance that costs no FE run: every force is linear
//! in it, `palpate_fe::r2_scan`).
//!
//! E comes from the one surrogate of palpate (`palpate_uq::surrogate`, a
//! reduced basis of the scanned curve with a GP per coefficient) of the FE
//! model [`R2NoduleScan`] (depth -> force at offsets 0, step, ..,
//! half-width from a nodule at the block's centre; the mesh and block are
//! symmetric about the centre, so E(-o) = E(o)), minus F0 at the same
//! positions; F0 is one nodule-free FE pass from the centre to the end of
//! the path (also symmetric). Both are cached on disk per RD
//! ([`crate::surrogate`]). The surrogate's held-out error variance, per
//! offset, is added to the likelihood's noise variance (posterior.rs).
//!
//! Between grid points E and F0 are interpolated by Catmull-Rom cubics
//! (C1, so the log-posterior is smooth in x_n); E is tapered to zero over
//! one step past the half-width.

pub mod posterior;
pub mod record;
pub mod units;

use crate::surrogate::{load_or_build, load_or_compute, CacheStatus};
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::r2::check_model;
use palpate_fe::r2_scan::R2NoduleScan;
use palpate_fe::R2Rolling;
use palpate_material::Law;
use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// How the localisation model of one RD is built.
#[derive(Debug, Clone)]
pub struct LocSetup {
    /// The R2 model (RD, laws, mesh, block, path); its nodules are ignored.
    pub template: R2Rolling,
    /// Offsets scanned from the nodule: 0..=half_width every `step` (mm).
    pub half_width: f64,
    pub step: f64,
    /// Surrogate design: training and held-out FE scans.
    pub training: usize,
    pub holdout: usize,
}

impl LocSetup {
    /// BENCHMARKS.md R2 at rolling depth `rd`: mesh level 1 (h = 2 mm, the
    /// accuracy level of docs/validation/fe.md R2), offsets 0..30 mm every
    /// 2 mm, 6 training + 2 held-out scans (depth is one parameter; a scan
    /// is ~70 s of CPU at RD 6, so this is what fits the 10-minute budget
    /// on 2 cores).
    pub fn r2(rd: f64) -> Self {
        LocSetup {
            template: R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd)
                .with_nodules(Vec::new()),
            half_width: 30.0,
            step: 2.0,
            training: 6,
            holdout: 2,
        }
    }

    /// The block centre, where the scanned nodule sits.
    pub fn centre(&self) -> f64 {
        0.5 * self.template.length
    }

    /// Checks RD and the scan against the block: `(option, reason)`.
    pub fn check(&self) -> Result<(), (String, String)> {
        check_model(&self.template).map_err(|(f, r)| {
            if f == "rd" {
                ("--rd".to_string(), r)
            } else {
                (f, r)
            }
        })?;
        let t = &self.template;
        if !(self.step > 0.0 && self.half_width >= 2.0 * self.step) {
            return Err((
                "scan".into(),
                format!(
                    "half-width {} mm and step {} mm: need a step > 0 and at least two steps",
                    self.half_width, self.step
                ),
            ));
        }
        if self.centre() + self.baseline_end() > t.length - t.wheel_radius
            || self.centre() + self.half_width > t.length - t.wheel_radius
        {
            return Err((
                "scan".into(),
                format!(
                    "the scan reaches past the block ({} mm long) for the path {}..{} mm",
                    t.length, t.press_x, t.roll_to
                ),
            ));
        }
        if self.training < 3 || self.holdout < 1 {
            return Err((
                "--design".into(),
                format!(
                    "{} training and {} held-out FE scans: need at least 3 and 1",
                    self.training, self.holdout
                ),
            ));
        }
        Ok(())
    }

    /// Offsets of the scan.
    pub fn offsets(&self) -> Vec<f64> {
        let n = (self.half_width / self.step).round() as usize;
        (0..=n).map(|k| self.step * k as f64).collect()
    }

    /// Farthest offset of the nodule-free pass from the centre: the path's
    /// far end from the centre, rounded up to the grid.
    fn baseline_end(&self) -> f64 {
        let t = &self.template;
        let far = (t.roll_to - self.centre())
            .abs()
            .max((self.centre() - t.press_x).abs());
        (far / self.step).ceil() * self.step
    }

    /// The FE model of the scan: one nodule at the block's centre, its
    /// depth the parameter.
    pub fn scan_model(&self) -> R2NoduleScan {
        R2NoduleScan::new(self.template.clone(), false)
    }

    /// The scan's loading: the offsets from the nodule.
    pub fn scan_loading(&self) -> Loading {
        Loading::quasi_static(Drive::PositionMm, self.offsets())
    }

    /// The surrogate's box: every depth the mesh allows for `scan`.
    pub fn scan_bounds(&self, scan: &dyn ForwardModel) -> anyhow::Result<ParamBox> {
        let p = &scan.space().params[0];
        ParamBox::new(scan.space(), &[p.lower], &[p.upper])
            .map_err(|e| anyhow::anyhow!("depth box: {e}"))
    }

    /// The surrogate's design sizes.
    pub fn scan_options(&self) -> SurrogateOptions {
        SurrogateOptions {
            training_runs: self.training,
            validation_runs: self.holdout,
            basis_tolerance: 1e-5,
        }
    }

    /// Wheel positions of the nodule-free pass: the centre, then every
    /// `step` to the far end of the path from it.
    pub fn baseline_positions(&self) -> Vec<f64> {
        let n = (self.baseline_end() / self.step).round() as usize;
        (0..=n)
            .map(|k| self.centre() + self.step * k as f64)
            .collect()
    }

    /// The nodule-free FE pass from the centre. Always in 2 segments (not
    /// one per thread): a segment's press differs from the rolled state in
    /// the solver's last digits, and the force must not depend on the
    /// machine's thread count (a study's shards and its single run agree
    /// byte for byte). `tick` is called once per solved position.
    pub fn baseline_pass(&self, tick: Option<&(dyn Fn() + Sync)>) -> anyhow::Result<Baseline> {
        let t = &self.template;
        let positions = self.baseline_positions();
        let mut m = t.with_nodules(Vec::new());
        m.press_x = self.centre();
        m.roll_to = self.centre() + self.baseline_end();
        let t0 = std::time::Instant::now();
        let (rows, _) = m
            .rolled_pass(&R2Rolling::BENCHMARK_PARAMS, &positions, 2, tick)
            .map_err(|e| anyhow::anyhow!("the nodule-free R2 pass at RD {}: {e}", t.rd))?;
        Ok(Baseline {
            centre: self.centre(),
            step: self.step,
            force: rows.iter().map(|r| r[0]).collect(),
            time_s: t0.elapsed().as_secs_f64(),
        })
    }

    /// Everything that defines the cached FE results (the code version is
    /// added by the cache).
    pub fn description(&self) -> String {
        format!(
            "R2 localisation; template {:?}; half-width {}; step {}",
            self.template, self.half_width, self.step
        )
    }
}

/// The nodule-free force every `step` mm from the block's centre.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    pub centre: f64,
    pub step: f64,
    /// F0 at centre + k step, k = 0, 1, ...
    pub force: Vec<f64>,
    /// Wall time of the FE pass (s).
    pub time_s: f64,
}

/// The localisation model of one RD: scan surrogate plus baseline.
pub struct LocModel {
    pub rd: f64,
    /// The rolled path (mm): where a record may have positions.
    pub path: (f64, f64),
    /// The depth box of the surrogate (mm).
    pub depth_box: (f64, f64),
    pub step: f64,
    pub half_width: f64,
    pub scan: Surrogate,
    pub baseline: Baseline,
    /// Where each came from (None for a model built in memory).
    pub scan_status: Option<CacheStatus>,
    pub baseline_status: Option<CacheStatus>,
}

/// Catmull-Rom interpolation of the uniform grid `g` (g[k] at u = k) at
/// u >= 0, with the even extension g[-k] = g[k] and `past` beyond the end.
fn catmull(g: &[f64], u: f64, past: impl Fn(isize) -> f64) -> f64 {
    let n = g.len() as isize;
    let at = |k: isize| {
        let k = k.abs();
        if k < n {
            g[k as usize]
        } else {
            past(k)
        }
    };
    let k = u.floor() as isize;
    let t = u - k as f64;
    let (p0, p1, p2, p3) = (at(k - 1), at(k), at(k + 1), at(k + 2));
    let t2 = t * t;
    let t3 = t2 * t;
    0.5 * (2.0 * p1
        + (-p0 + p2) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3)
}

impl LocModel {
    /// Loads from `cache` or builds (FE runs in parallel, with progress
    /// bars) the model of `setup`.
    pub fn load_or_build(setup: &LocSetup, cache: &Path) -> anyhow::Result<LocModel> {
        setup
            .check()
            .map_err(|(f, r)| anyhow::anyhow!("{f} {}: {r}", setup.template.rd))?;
        let (baseline, baseline_status) =
            load_or_compute("r2-baseline", &setup.description(), cache, || {
                let bar = crate::limits::Progress::new(
                    setup.baseline_positions().len() as u64,
                    "nodule-free FE pass",
                    "{msg} [{bar:40}] {pos}/{len} positions ({elapsed}, eta {eta})",
                );
                let tick = || bar.inc(1);
                let b = setup.baseline_pass(Some(&tick));
                bar.finish();
                b
            })?;
        let scan = setup.scan_model();
        let (s, status) = load_or_build(
            &scan,
            &setup.scan_loading(),
            setup.scan_bounds(&scan)?,
            setup.scan_options(),
            &setup.description(),
            cache,
            &format!("R2 scan surrogate, RD {}", setup.template.rd),
        )?;
        Self::from_parts(setup, s, baseline, Some(status), Some(baseline_status))
    }

    /// The model from a surrogate of the scan (`depth` -> force at
    /// `setup.offsets()`) and the baseline.
    pub fn from_parts(
        setup: &LocSetup,
        scan: Surrogate,
        baseline: Baseline,
        scan_status: Option<CacheStatus>,
        baseline_status: Option<CacheStatus>,
    ) -> anyhow::Result<LocModel> {
        let n = setup.offsets().len();
        anyhow::ensure!(
            scan.loading().len() == n && baseline.force.len() >= n,
            "the scan surrogate has {} offsets and the baseline {} positions; the setup needs {n}",
            scan.loading().len(),
            baseline.force.len()
        );
        let b = scan.bounds();
        Ok(LocModel {
            rd: setup.template.rd,
            path: (setup.template.press_x, setup.template.roll_to),
            depth_box: (b.lower[0], b.upper[0]),
            step: setup.step,
            half_width: setup.half_width,
            scan,
            baseline,
            scan_status,
            baseline_status,
        })
    }

    /// F0 at `p`.
    pub fn baseline_at(&self, p: f64) -> f64 {
        let g = &self.baseline.force;
        let last = *g.last().unwrap_or(&0.0);
        catmull(
            g,
            (p - self.baseline.centre).abs() / self.baseline.step,
            |_| last,
        )
    }

    /// The excess E at the grid offsets for `depth` (refuses a depth outside
    /// the surrogate's box).
    pub fn excess_grid(&self, depth: f64, out: &mut [f64]) -> anyhow::Result<()> {
        self.scan
            .predict_outputs(&[depth], out)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        for (o, f0) in out.iter_mut().zip(&self.baseline.force) {
            *o -= f0;
        }
        Ok(())
    }

    /// E at offset `o` from the excess grid `grid`.
    pub fn excess_at(&self, grid: &[f64], o: f64) -> f64 {
        let u = o.abs() / self.step;
        if u > grid.len() as f64 + 1.0 {
            return 0.0;
        }
        catmull(grid, u, |_| 0.0)
    }

    /// The surrogate's error variance (N^2) at offset `o` (linear between
    /// grid points, zero past the scan).
    pub fn error_variance_at(&self, o: f64) -> f64 {
        let v = &self.scan.validation().error_variance;
        let u = o.abs() / self.step;
        let k = u.floor() as usize;
        if k + 1 >= v.len() {
            return if k < v.len() { v[k] } else { 0.0 };
        }
        let t = u - k as f64;
        (1.0 - t) * v[k] + t * v[k + 1]
    }

    /// The model force at `positions` for nodules `(x, depth)` and scale
    /// `s`, and the surrogate's error variance there (scaled).
    pub fn predict(
        &self,
        positions: &[f64],
        nodules: &[(f64, f64)],
        s: f64,
    ) -> anyhow::Result<(Vec<f64>, Vec<f64>)> {
        let mut grid = vec![0.0; self.scan.loading().len()];
        let mut f: Vec<f64> = positions.iter().map(|&p| self.baseline_at(p)).collect();
        let mut v = vec![0.0; positions.len()];
        for &(x, d) in nodules {
            self.excess_grid(d, &mut grid)?;
            for (i, &p) in positions.iter().enumerate() {
                f[i] += self.excess_at(&grid, p - x);
                v[i] += self.error_variance_at(p - x);
            }
        }
        for (fi, vi) in f.iter_mut().zip(v.iter_mut()) {
            *fi *= s;
            *vi *= s * s;
        }
        Ok((f, v))
    }

    /// FE runs behind the model: the surrogate's design and held-out scans,
    /// and the nodule-free pass.
    pub fn fe_runs(&self) -> usize {
        self.scan.fe_runs + 1
    }
}

#[cfg(test)]
mod tests {
    use super::catmull;

    /// Catmull-Rom reproduces the grid values and a quadratic exactly
    /// between points (it is exact for cubics' ... quadratics on a uniform
    /// grid), and uses the even extension at 0.
    #[test]
    fn interpolation_is_exact_for_an_even_quadratic() {
        let g: Vec<f64> = (0..10).map(|k| 1.0 + 0.3 * (k * k) as f64).collect();
        for &u in &[0.0, 0.25, 1.5, 3.7, 7.9] {
            let want = 1.0 + 0.3 * u * u;
            let got = catmull(&g, u, |k| 1.0 + 0.3 * (k * k) as f64);
            assert!((got - want).abs() < 1e-12, "{u}: {got} vs {want}");
        }
    }
}
