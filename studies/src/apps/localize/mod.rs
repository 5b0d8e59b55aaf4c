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
//! model [`R2NoduleScan`], minus F0 at the same positions; F0 is one
//! nodule-free FE pass from the centre to the end of the path (the block
//! and path are symmetric about the centre). Three forms of the scan:
//!
//! * at the centre ([`LocSetup::r2`], `--scan centre`): depth -> force at
//!   offsets 0..half-width from a nodule at the block's centre, E(-o) =
//!   E(o) by symmetry, and translation invariance assumed everywhere. Near
//!   the block's ends the excess leans towards the nearer end, so shallow
//!   nodules 25-45 mm from an end are placed ~0.16 mm towards it
//!   (docs/validation/r2-localisation.md);
//! * along the block ([`LocSetup::r2_along`], `--scan along`): the centre
//!   model plus FE scans over (depth, ln x_n) at signed offsets
//!   -half-width..half-width for nodules left of the centre (a nodule
//!   right of it is the mirror image, E(o; d, x) = E(-o; d, L - x)), and a
//!   surrogate of what they add to the centre's excess
//!   ([`LocSetup::excess_curve`] minus the centre's E; offsets off the
//!   rolled path are undefined, so one trend + GP per offset). It removes
//!   most of the shallow nodules' lean, but on the FE records its depths
//!   are worse than the centre model's (the correction also fits the mesh
//!   differences between the scans): not the default (measurements in
//!   the validation doc);
//! * the centre model with the end lean ([`LocSetup::r2_lean`], the
//!   default of `palpate localize` and of a study's localize step): each
//!   nodule's excess shifted by one measured lean per position and depth
//!   ([`lean`]); its 94 % x intervals cover at the nominal rate on 50 FE
//!   records, where the centre model's cover 81 %.
//!
//! All are cached on disk per RD ([`crate::run::surrogate`]). The surrogate's
//! held-out error variance, per offset, is added to the likelihood's noise
//! variance (posterior.rs).
//!
//! Between grid points E and F0 are interpolated by Catmull-Rom cubics
//! (C1, so the log-posterior is smooth in x_n); E is tapered to zero over
//! one step past the half-width.

pub mod forward;
pub mod lean;
pub mod plot;
pub mod posterior;
pub mod record;
pub mod units;

use crate::run::surrogate::{load_or_build, load_or_compute, CacheStatus};
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
    /// Whether the scan has the nodule's position as a parameter (module
    /// docs); otherwise translation invariance is assumed.
    pub along_block: bool,
    /// Whether the centre model's excess is shifted by the end lean
    /// measured on FE scans near the end ([`lean`], `--scan lean`).
    pub lean: bool,
}

impl LocSetup {
    /// docs/benchmarks.md R2 at rolling depth `rd`: mesh level 1 (h = 2 mm, the
    /// accuracy level of docs/validation/fe.md R2), offsets 0..30 mm every
    /// 2 mm, 6 training + 2 held-out scans of depth at the block's centre
    /// (a scan is ~35 s of CPU at RD 6, so this fits the 10-minute budget
    /// on 2 cores), translation invariance assumed.
    pub fn r2(rd: f64) -> Self {
        LocSetup {
            template: R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd)
                .with_nodules(Vec::new()),
            half_width: 30.0,
            step: 2.0,
            training: 6,
            holdout: 2,
            along_block: false,
            lean: false,
        }
    }

    /// The centre model with the end lean ([`lean`]): [`Self::r2`] plus
    /// [`Self::LEAN_DISTANCES`] x [`Self::LEAN_DEPTHS`] FE scans of
    /// [`Self::LEAN_HALF_WINDOW`] on each side of one nodule.
    pub fn r2_lean(rd: f64) -> Self {
        LocSetup {
            lean: true,
            ..Self::r2(rd)
        }
    }

    /// Distances (mm) from the nearer block end of the lean's FE scans.
    pub const LEAN_DISTANCES: [f64; 4] = [15.0, 25.0, 35.0, 50.0];
    /// Nodule depths (mm) of the lean's FE scans (the studied 8-24 mm).
    pub const LEAN_DEPTHS: [f64; 4] = [8.0, 12.0, 16.0, 24.0];
    /// The offsets of a lean scan: -w..w mm every `step` (the peak and its
    /// flanks, where a shift shows).
    pub const LEAN_HALF_WINDOW: f64 = 12.0;

    /// The scan along the block (depth and ln x_n; module docs): offsets
    /// -30..30 mm every 2 mm, 16 training + 4 held-out scans of up to 60
    /// mm (~6 min of wall time on 2 cores at RD 6).
    pub fn r2_along(rd: f64) -> Self {
        LocSetup {
            training: 16,
            holdout: 4,
            along_block: true,
            ..Self::r2(rd)
        }
    }

    /// The same model scanned at the block's centre only
    /// ([`LocSetup::r2`]'s design).
    pub fn at_centre(&self) -> LocSetup {
        LocSetup {
            training: 6,
            holdout: 2,
            along_block: false,
            lean: false,
            ..self.clone()
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
        if self.along_block && (t.press_x + t.roll_to - t.length).abs() > 1e-9 {
            return Err((
                "scan".into(),
                format!(
                    "the scan along the block mirrors nodules about its centre, so the path {}..{} mm must be symmetric on the {} mm block",
                    t.press_x, t.roll_to, t.length
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

    /// Offsets of the scan: signed along the block, else from 0.
    pub fn offsets(&self) -> Vec<f64> {
        let n = (self.half_width / self.step).round() as i64;
        let first = if self.along_block { -n } else { 0 };
        (first..=n).map(|k| self.step * k as f64).collect()
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
        if self.along_block {
            R2NoduleScan::along_block(self.template.clone(), false)
        } else {
            R2NoduleScan::new(self.template.clone(), false)
        }
    }

    /// The scan's loading: the offsets from the nodule.
    pub fn scan_loading(&self) -> Loading {
        Loading::quasi_static(Drive::PositionMm, self.offsets())
    }

    /// The surrogate's box: every depth the mesh allows for `scan` (and
    /// every nodule position from the path's start to the centre).
    pub fn scan_bounds(&self, scan: &dyn ForwardModel) -> anyhow::Result<ParamBox> {
        let ps = &scan.space().params;
        let lower: Vec<f64> = ps.iter().map(|p| p.lower).collect();
        let upper: Vec<f64> = ps.iter().map(|p| p.upper).collect();
        ParamBox::new(scan.space(), &lower, &upper).map_err(|e| anyhow::anyhow!("scan box: {e}"))
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

    /// The excess E = F - F0 of a scan along the block at `theta` (depth,
    /// ln x) from its forces at [`Self::offsets`]; undefined (NaN) where
    /// x + o is off the rolled path (no data is ever there, and the
    /// surrogate then fits each offset on the scans that reach it,
    /// `palpate_uq::surrogate`). What the surrogate along the block is
    /// fitted to: F0 near the ends is not invariant in x, and subtracting
    /// it leaves the curves of different x alike.
    pub fn excess_curve(&self, baseline: &Baseline, theta: &[f64], forces: &[f64]) -> Vec<f64> {
        let x = theta.get(1).map_or(self.centre(), |l| l.exp());
        let (lo, hi) = (self.template.press_x, self.template.roll_to);
        self.offsets()
            .iter()
            .zip(forces)
            .map(|(&o, f)| {
                if x + o >= lo - 1e-9 && x + o <= hi + 1e-9 {
                    f - baseline.at(x + o)
                } else {
                    f64::NAN
                }
            })
            .collect()
    }

    /// Everything that defines the cached FE results (the code version is
    /// added by the cache).
    pub fn description(&self) -> String {
        format!(
            "R2 localisation; template {:?}; half-width {}; step {}{}",
            self.template,
            self.half_width,
            self.step,
            if self.along_block {
                "; scan along the block (depth, ln x)"
            } else {
                ""
            }
        )
    }

    /// The offsets of one lean scan.
    pub fn lean_offsets(&self) -> Vec<f64> {
        let n = (Self::LEAN_HALF_WINDOW / self.step).round() as i64;
        (-n..=n).map(|k| self.step * k as f64).collect()
    }

    /// What defines the cached lean scans.
    pub(crate) fn lean_description(&self) -> String {
        format!(
            "{}; lean scans at distances {:?}, depths {:?}, offsets {:?}",
            self.at_centre().description(),
            Self::LEAN_DISTANCES,
            Self::LEAN_DEPTHS,
            self.lean_offsets()
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

impl Baseline {
    /// F0 at `p` (Catmull-Rom between the grid points, even about the
    /// centre, the last value past the end).
    pub fn at(&self, p: f64) -> f64 {
        let g = &self.force;
        let last = *g.last().unwrap_or(&0.0);
        catmull(g, (p - self.centre).abs() / self.step, |_| last)
    }
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
    /// Whether the scan is along the block ([`LocSetup::along_block`]).
    pub along_block: bool,
    /// The block's centre (mm): nodules right of it are mirrored.
    pub centre: f64,
    pub scan: Surrogate,
    /// Along the block: the model at the centre whose excess the scan's
    /// surrogate corrects (E = E_centre + the surrogate's), or `None` when
    /// the surrogate is of E itself.
    pub centre_model: Option<Box<LocModel>>,
    /// The end lean of the excess (`--scan lean`), or `None`.
    pub lean: Option<lean::Lean>,
    pub baseline: Baseline,
    /// Where each came from (None for a model built in memory).
    pub scan_status: Option<CacheStatus>,
    pub baseline_status: Option<CacheStatus>,
}

/// The Catmull-Rom cubic through the grid values `at(k)` at u (between
/// `at(floor u)` and `at(floor u + 1)`).
fn cubic(at: impl Fn(isize) -> f64, u: f64) -> f64 {
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

/// Catmull-Rom interpolation of the uniform grid `g` (g[k] at u = k) at
/// any u, zero outside the grid.
fn catmull_zero_outside(g: &[f64], u: f64) -> f64 {
    let n = g.len() as isize;
    let at = |k: isize| {
        if (0..n).contains(&k) {
            g[k as usize]
        } else {
            0.0
        }
    };
    cubic(at, u)
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
    cubic(at, u)
}

impl LocModel {
    /// Loads from `cache` or builds (FE runs in parallel, with progress
    /// bars) the model of `setup`.
    pub fn load_or_build(setup: &LocSetup, cache: &Path) -> anyhow::Result<LocModel> {
        setup
            .check()
            .map_err(|(f, r)| anyhow::anyhow!("{f} {}: {r}", setup.template.rd))?;
        if setup.along_block {
            return Self::load_or_build_along(setup, cache);
        }
        let (baseline, baseline_status) =
            load_or_compute("r2-baseline", &setup.description(), cache, || {
                let bar = crate::run::limits::Progress::new(
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
        let mut m = Self::from_parts(setup, s, baseline, Some(status), Some(baseline_status))?;
        if setup.lean {
            m.lean = Some(lean::load_or_measure(&m, setup, cache)?);
        }
        Ok(m)
    }

    /// What to add to a wheel offset `p - x` from a nodule at `x` and depth
    /// `d` before reading its excess: the end lean's shift, or zero.
    pub fn offset_shift(&self, x: f64, d: f64) -> f64 {
        self.lean.as_ref().map_or(0.0, |l| l.offset_shift(x, d))
    }

    /// The model along the block: the centre model of the same RD (its
    /// scans and baseline, cached as `--scan centre`'s), the scans along
    /// the block, and the surrogate of what they add to the centre's
    /// excess (small and smooth in x: the centre scan keeps the accuracy
    /// in depth).
    fn load_or_build_along(setup: &LocSetup, cache: &Path) -> anyhow::Result<LocModel> {
        let centre = Self::load_or_build(&setup.at_centre(), cache)?;
        let baseline = centre.baseline.clone();
        let baseline_status = centre.baseline_status.clone();
        let units = units::ModelUnits::r2(setup)?;
        let n = units.len() - 1;
        let label = format!("R2 scan surrogate, RD {}", setup.template.rd);
        // the FE scans are cached (not the surrogate: assembling it from
        // them takes a second), with the time they took
        let ((runs, time_s, cpu_s), status) = load_or_compute(
            "r2-scan-runs",
            &format!("{}; {:?}", setup.description(), setup.scan_options()),
            cache,
            || {
                use rayon::prelude::*;
                let (t0, c0) = (
                    std::time::Instant::now(),
                    palpate_uq::surrogate::cpu_seconds(),
                );
                let bar = crate::run::limits::Progress::new(
                    n as u64,
                    &label,
                    "{msg} [{bar:40}] {pos}/{len} FE scans ({elapsed}, eta {eta})",
                );
                let runs: Vec<Result<Vec<f64>, String>> = (1..=n)
                    .into_par_iter()
                    .map(|k| {
                        let r = units.scan_run(k);
                        bar.inc(1);
                        r
                    })
                    .collect();
                bar.finish();
                let cpu = palpate_uq::surrogate::cpu_seconds()
                    .zip(c0)
                    .map(|(a, b)| a - b);
                Ok((runs, t0.elapsed().as_secs_f64(), cpu))
            },
        )?;
        let mut s = units.surrogate(&baseline, runs, Some(&centre))?;
        // the build time of the FE scans, not of the assembly alone
        s.build_time_s += time_s;
        s.build_cpu_s = s.build_cpu_s.zip(cpu_s).map(|(a, b)| a + b);
        let mut m = Self::from_parts(setup, s, baseline, Some(status), baseline_status)?;
        m.centre_model = Some(Box::new(centre));
        Ok(m)
    }

    /// The model from a surrogate of the scan (`depth` -> force at
    /// `setup.offsets()`; along the block (depth, ln x) -> the excess
    /// force, [`LocSetup::excess_curve`]) and the baseline.
    pub fn from_parts(
        setup: &LocSetup,
        scan: Surrogate,
        baseline: Baseline,
        scan_status: Option<CacheStatus>,
        baseline_status: Option<CacheStatus>,
    ) -> anyhow::Result<LocModel> {
        let n = setup.offsets().len();
        let n_base = (setup.half_width / setup.step).round() as usize + 1;
        anyhow::ensure!(
            scan.loading().len() == n && baseline.force.len() >= n_base,
            "the scan surrogate has {} offsets and the baseline {} positions; the setup needs {n} and {n_base}",
            scan.loading().len(),
            baseline.force.len()
        );
        let b = scan.bounds();
        anyhow::ensure!(
            b.len() == 1 + usize::from(setup.along_block),
            "the scan surrogate has {} parameters; the setup's scan {}",
            b.len(),
            if setup.along_block {
                "is along the block (depth, ln x)"
            } else {
                "has the depth only"
            }
        );
        Ok(LocModel {
            rd: setup.template.rd,
            path: (setup.template.press_x, setup.template.roll_to),
            depth_box: (b.lower[0], b.upper[0]),
            step: setup.step,
            half_width: setup.half_width,
            along_block: setup.along_block,
            centre: setup.centre(),
            scan,
            centre_model: None,
            lean: None,
            baseline,
            scan_status,
            baseline_status,
        })
    }

    /// F0 at `p`.
    pub fn baseline_at(&self, p: f64) -> f64 {
        self.baseline.at(p)
    }

    /// The excess E at the grid offsets of a nodule at `x` and `depth`
    /// (refuses a depth outside the surrogate's box). Along the block the
    /// grid is that of the nodule's mirror image when `x` is right of the
    /// centre: the return value says so (pass it to [`Self::excess_at`] and
    /// [`Self::error_variance_at`]); offsets whose position is off the
    /// path continue the curve linearly.
    pub fn excess_grid(&self, depth: f64, x: f64, out: &mut [f64]) -> anyhow::Result<bool> {
        if !self.along_block {
            self.scan
                .predict_outputs(&[depth], out)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            for (o, f0) in out.iter_mut().zip(&self.baseline.force) {
                *o -= f0;
            }
            return Ok(false);
        }
        let mirrored = x > self.centre;
        let xl = if mirrored { 2.0 * self.centre - x } else { x };
        let b = self.scan.bounds();
        let lnx = xl.max(1e-9).ln().clamp(b.lower[1], b.upper[1]);
        // the surrogate along the block is one of the excess itself
        // (`LocSetup::excess_curve`); offsets off the path (never a data
        // position, but the interpolation's neighbours next to the path's
        // end) continue the curve linearly from the first two on it
        self.scan
            .predict_outputs(&[depth, lnx], out)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let n = out.len();
        let half = (n - 1) / 2;
        if let Some(c) = &self.centre_model {
            // E = the centre's excess + this surrogate's correction
            let mut grid = [0.0; 64];
            let m = c.scan.loading().len();
            anyhow::ensure!(m <= grid.len(), "a centre scan of {m} offsets");
            c.excess_grid(depth, c.centre, &mut grid[..m])?;
            for (j, v) in out.iter_mut().enumerate() {
                *v += c.excess_at(&grid[..m], self.step * (j as f64 - half as f64), false);
            }
        }
        let (lo, hi) = self.path;
        let on = |j: usize| {
            let p = xl + self.step * (j as f64 - half as f64);
            p >= lo - 1e-9 && p <= hi + 1e-9
        };
        if let Some(first) = (0..n).find(|&j| on(j)) {
            for j in (0..first).rev() {
                out[j] = if j + 2 < n {
                    2.0 * out[j + 1] - out[j + 2]
                } else {
                    out[j + 1]
                };
            }
        }
        Ok(mirrored)
    }

    /// E at offset `o` (wheel minus nodule) from the excess grid `grid` of
    /// [`Self::excess_grid`].
    pub fn excess_at(&self, grid: &[f64], o: f64, mirrored: bool) -> f64 {
        if self.along_block {
            let o = if mirrored { -o } else { o };
            let u = (o + self.half_width) / self.step;
            if u < -2.0 || u > grid.len() as f64 + 1.0 {
                return 0.0;
            }
            return catmull_zero_outside(grid, u);
        }
        let u = o.abs() / self.step;
        if u > grid.len() as f64 + 1.0 {
            return 0.0;
        }
        catmull(grid, u, |_| 0.0)
    }

    /// The surrogate's error variance (N^2) at offset `o` (linear between
    /// grid points, zero past the scan).
    pub fn error_variance_at(&self, o: f64, mirrored: bool) -> f64 {
        let centre = self
            .centre_model
            .as_ref()
            .map_or(0.0, |c| c.error_variance_at(o, false));
        centre + self.own_error_variance_at(o, mirrored)
    }

    /// The error variance of this model's own surrogate at `o`.
    fn own_error_variance_at(&self, o: f64, mirrored: bool) -> f64 {
        let v = &self.scan.validation().error_variance;
        let u = if self.along_block {
            let o = if mirrored { -o } else { o };
            let u = (o + self.half_width) / self.step;
            if u < 0.0 {
                return 0.0;
            }
            u
        } else {
            o.abs() / self.step
        };
        let k = u.floor() as usize;
        if k + 1 >= v.len() {
            return if k < v.len() { v[k] } else { 0.0 };
        }
        let t = u - k as f64;
        (1.0 - t) * v[k] + t * v[k + 1]
    }

    /// The force with the wheel over one nodule at the block's centre
    /// (R2-1), at `depth`: the scan surrogate at offset 0.
    pub fn peak_force(&self, depth: f64) -> anyhow::Result<f64> {
        let mut grid = vec![0.0; self.scan.loading().len()];
        if self.along_block {
            // the surrogate along the block is of the excess
            self.excess_grid(depth, self.centre, &mut grid)?;
            return Ok(grid[self.zero_offset()] + self.baseline_at(self.centre));
        }
        self.scan
            .predict_outputs(&[depth], &mut grid)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(grid[0])
    }

    /// Index of offset 0 in the scan's grid.
    pub fn zero_offset(&self) -> usize {
        if self.along_block {
            (self.scan.loading().len() - 1) / 2
        } else {
            0
        }
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
        let mut f = vec![0.0; positions.len()];
        let mut v = vec![0.0; positions.len()];
        self.predict_into(positions, nodules, s, &mut f, &mut grid)?;
        self.error_variance_into(positions, nodules, s, &mut v);
        Ok((f, v))
    }

    /// The model force at `positions` for nodules `(x, depth)` and scale
    /// `s`, into `f`; `grid` is scratch of the scan's length.
    pub fn predict_into(
        &self,
        positions: &[f64],
        nodules: &[(f64, f64)],
        s: f64,
        f: &mut [f64],
        grid: &mut [f64],
    ) -> anyhow::Result<()> {
        for (fi, &p) in f.iter_mut().zip(positions) {
            *fi = self.baseline_at(p);
        }
        for &(x, d) in nodules {
            let m = self.excess_grid(d, x, grid)?;
            let shift = self.offset_shift(x, d);
            for (fi, &p) in f.iter_mut().zip(positions) {
                *fi += self.excess_at(grid, p - x + shift, m);
            }
        }
        for fi in f.iter_mut() {
            *fi *= s;
        }
        Ok(())
    }

    /// The surrogate's error variance (N^2) at `positions` for nodules
    /// `(x, depth)` and scale `s` (the variances of the nodules' excesses
    /// add up; scaled by s^2), into `v`.
    pub fn error_variance_into(
        &self,
        positions: &[f64],
        nodules: &[(f64, f64)],
        s: f64,
        v: &mut [f64],
    ) {
        v.iter_mut().for_each(|vi| *vi = 0.0);
        for &(x, d) in nodules {
            let m = self.mirrored(x);
            let shift = self.offset_shift(x, d);
            for (vi, &p) in v.iter_mut().zip(positions) {
                *vi += self.error_variance_at(p - x + shift, m);
            }
        }
        for vi in v.iter_mut() {
            *vi *= s * s;
        }
    }

    /// Whether the excess of a nodule at `x` is read from its mirror image
    /// ([`Self::excess_grid`]'s return value).
    pub fn mirrored(&self, x: f64) -> bool {
        self.along_block && x > self.centre
    }

    /// FE runs behind the model: the surrogate's design and held-out scans,
    /// the end lean's scans and the nodule-free pass.
    pub fn fe_runs(&self) -> usize {
        let lean = self
            .lean
            .as_ref()
            .map_or(0, |l| l.distance.len() * l.depth.len());
        self.scan.fe_runs + lean + self.centre_model.as_ref().map_or(1, |c| c.fe_runs())
    }

    /// The surrogate's held-out error relative to the peak force of its
    /// scans; along the block with a centre model, the larger of the
    /// centre's and the correction's largest error over the centre's
    /// smallest peak excess (the deepest nodule's).
    pub fn max_rel_error(&self) -> f64 {
        let own = self.scan.validation().max_relative_error;
        let Some(c) = &self.centre_model else {
            return own;
        };
        let abs = self
            .scan
            .validation()
            .max_abs_error
            .iter()
            .fold(0.0f64, |a, b| a.max(*b));
        let mut grid = vec![0.0; c.scan.loading().len()];
        let peak = c
            .excess_grid(c.depth_box.1, c.centre, &mut grid)
            .map(|_| grid[0].abs())
            .unwrap_or(0.0);
        c.max_rel_error().max(abs / peak.max(1e-300))
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
