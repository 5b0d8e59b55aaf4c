//! Meshes made for a stated accuracy: the refinement level of a model's
//! mesh family whose estimated discretisation error of the force at the
//! deepest sample is within a target (e.g. 1 %).
//!
//! A model that can be rebuilt at a refinement level ([`Refinable`]: level
//! `L` has the element sizes of level 1 divided by `L`, levels need not be
//! integers) is run on the experiment's loading at a level `L` and at
//! `L / ratio`, and the error of the level-`L` force at the deepest sample
//! is estimated by Richardson extrapolation with the model's stated order
//! ([`crate::discretisation::richardson`], the same estimate as `palpate
//! simulate`'s). Starting from the family's coarsest useful level, the
//! level grows to the one the estimate predicts meets the target
//! (`L (e / target)^(1/p)`, rounded up to a quarter level; by
//! [`AccuracyOptions::min_growth`] where a solve stopped early),
//! until the target is met or the family's finest level is reached (an
//! error saying what was reached). The first level met is the cheapest the
//! ladder found.
//!
//! The choice is cached on disk ([`cache_key`]: a hash of the model's
//! description without its mesh, the loading's deepest sample and the
//! target) in a directory the caller gives, so that an estimator, which
//! runs the model many times, pays for the search once.

use std::path::{Path, PathBuf};

use crate::discretisation::{richardson, ConvergenceOrder};
use crate::mesh::Grading;
use crate::model::{graded_mesh_words, PlaneCell};
use crate::n3::{N3Element, N3Mesh};
use crate::{FeError, N1Needle, N3Needle};
use palpate_core::{ForwardError, Loading};

/// A model whose mesh belongs to a family of refinement levels.
pub trait Refinable: Clone {
    /// The model with its mesh at `level` of its family (element sizes of
    /// level 1 divided by `level`); everything but the mesh kept.
    fn at_level(&self, level: f64) -> Self;
    /// The order of convergence of its force with the element size.
    fn convergence_order(&self) -> ConvergenceOrder;
    /// Its mesh in words, for messages and reports.
    fn mesh_words(&self) -> String;
    /// The model without its mesh, for the cache key (two models with the
    /// same description but different meshes give the same text).
    fn description(&self) -> String;
    /// The coarsest level the search starts from.
    fn start_level(&self) -> f64 {
        1.0
    }
    /// The finest level the machine can hold within reasonable time.
    fn max_level(&self) -> f64;
}

/// How the level is searched.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyOptions {
    /// Target relative error of the force at the deepest sample (> 0).
    pub target: f64,
    /// Element-size ratio of the companion mesh of each estimate (> 1).
    pub ratio: f64,
    /// The factor to the next level where a level has no estimate (a
    /// solve stopped before the deepest sample) (> 1).
    pub min_growth: f64,
    /// Where the chosen level is cached (`None`: not cached).
    pub cache_dir: Option<PathBuf>,
}

/// The default target: 1 % at the deepest sample.
pub const DEFAULT_ACCURACY: f64 = 0.01;

impl AccuracyOptions {
    /// `target` with the ratio of `palpate simulate`'s estimate (2), 1.25
    /// past a level without an estimate, no cache.
    pub fn new(target: f64) -> Self {
        AccuracyOptions {
            target,
            ratio: 2.0,
            min_growth: 1.25,
            cache_dir: None,
        }
    }

    fn check(&self) -> Result<(), FeError> {
        let bad = |field: &str, v: f64, want: &str| {
            Err(FeError::InvalidConfig {
                field: field.into(),
                reason: format!("{v}: {want}"),
            })
        };
        if !(self.target > 0.0 && self.target < 1.0) {
            return bad(
                "accuracy",
                self.target,
                "a relative error between 0 and 1 (0.01 is 1 %)",
            );
        }
        if !(self.ratio > 1.0 && self.ratio.is_finite()) {
            return bad("ratio", self.ratio, "must be > 1");
        }
        if !(self.min_growth > 1.0 && self.min_growth.is_finite()) {
            return bad("min_growth", self.min_growth, "must be > 1");
        }
        Ok(())
    }
}

/// One level tried: its force at the deepest sample and the estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    pub level: f64,
    pub force: f64,
    /// Estimated relative error of `force` (`None` where the companion
    /// did not reach the deepest sample).
    pub relative: Option<f64>,
}

/// The level chosen for a target.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Choice {
    pub level: f64,
    /// Its estimated relative error at the deepest sample.
    pub estimate: f64,
    pub target: f64,
    /// The mesh in words.
    pub mesh: String,
    /// Model solves the search made (0 when read from the cache).
    #[serde(skip)]
    pub solves: usize,
    /// The levels tried, in order (empty when read from the cache).
    #[serde(skip)]
    pub trials: Vec<Trial>,
    /// Read from the cache.
    #[serde(skip)]
    pub cached: bool,
}

impl Choice {
    /// One line for reports: the mesh and its estimated error.
    pub fn line(&self) -> String {
        format!(
            "mesh for {:.2} % accuracy: level {} ({}), estimated error {:+.2} % at the deepest sample{}",
            100.0 * self.target,
            round3(self.level),
            self.mesh,
            100.0 * self.estimate,
            if self.cached {
                " (level read from the cache)".to_string()
            } else {
                format!(" ({} solves)", self.solves)
            }
        )
    }
}

fn round3(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

/// The loading up to its deepest sample (largest |drive|): the part of
/// the history the accuracy is judged on.
pub fn to_deepest(loading: &Loading) -> Loading {
    let k = loading
        .drive
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |(kb, b), (k, d)| {
            if d.abs() > b {
                (k, d.abs())
            } else {
                (kb, b)
            }
        })
        .0;
    Loading {
        drive_kind: loading.drive_kind,
        drive: loading.drive[..=k.min(loading.drive.len().saturating_sub(1))].to_vec(),
        time: loading.time.as_ref().map(|t| t[..=k].to_vec()),
    }
}

/// The cache key: FNV-1a of the description, the deepest drive and the
/// target, as 16 hex digits (stable across builds and platforms).
pub fn cache_key(description: &str, deepest: &Loading, target: f64) -> String {
    let text = format!("{description}\n{:?}\n{target:e}", deepest);
    let mut h: u64 = 0xcbf29ce484222325;
    for b in text.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    format!("{h:016x}")
}

fn cache_file(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("mesh-{key}.toml"))
}

/// Chooses the level of `model`'s family for `opts.target`; `run` solves
/// a model on `loading` cut at its deepest sample ([`to_deepest`]) and
/// returns its forces (`ForwardModel::predict` with the parameters at
/// hand). A companion that stops early makes that level's estimate
/// unavailable and the search refines.
pub fn choose<M: Refinable>(
    model: &M,
    loading: &Loading,
    opts: &AccuracyOptions,
    mut run: impl FnMut(&M, &Loading) -> Result<Vec<f64>, ForwardError>,
) -> Result<Choice, FeError> {
    opts.check()?;
    if loading.is_empty() {
        return Err(FeError::InvalidConfig {
            field: "loading".into(),
            reason: "no samples to judge the mesh on".into(),
        });
    }
    let deepest = to_deepest(loading);
    let key = cache_key(&model.description(), &deepest, opts.target);
    if let Some(dir) = &opts.cache_dir {
        if let Some(c) = std::fs::read_to_string(cache_file(dir, &key))
            .ok()
            .and_then(|t| toml::from_str::<Choice>(&t).ok())
            .filter(|c| c.level > 0.0 && c.level <= model.max_level())
        {
            return Ok(Choice { cached: true, ..c });
        }
    }
    let order = model.convergence_order().order;
    let max = model.max_level();
    let mut solves = 0;
    let mut memo: Vec<(f64, Option<f64>)> = Vec::new();
    let mut force_at = |level: f64, solves: &mut usize| -> Result<Option<f64>, FeError> {
        if let Some((_, f)) = memo.iter().find(|(l, _)| (l - level).abs() < 1e-9) {
            return Ok(*f);
        }
        *solves += 1;
        let f = match run(&model.at_level(level), &deepest) {
            Ok(f) if f.len() == deepest.len() => f.last().copied(),
            Ok(_) | Err(ForwardError::NotConverged { .. }) => None,
            Err(e) => {
                return Err(FeError::InvalidConfig {
                    field: "mesh".into(),
                    reason: format!("level {level}: {e}"),
                })
            }
        };
        memo.push((level, f));
        Ok(f)
    };
    let mut trials = Vec::new();
    let mut level = model.start_level().min(max);
    loop {
        let fine = force_at(level, &mut solves)?;
        let coarse = force_at(level / opts.ratio, &mut solves)?;
        let relative = match (fine, coarse) {
            (Some(f), Some(c)) => richardson(&[f], &[c], opts.ratio, order)?[0]
                .relative
                .or(Some(0.0)),
            _ => None,
        };
        trials.push(Trial {
            level,
            force: fine.unwrap_or(f64::NAN),
            relative,
        });
        if let Some(e) = relative.filter(|e| e.abs() <= opts.target) {
            let m = model.at_level(level);
            let choice = Choice {
                level,
                estimate: e,
                target: opts.target,
                mesh: m.mesh_words(),
                solves,
                trials,
                cached: false,
            };
            if let Some(dir) = &opts.cache_dir {
                // a cache that cannot be written costs the search next time
                let _ = std::fs::create_dir_all(dir).and_then(|_| {
                    std::fs::write(
                        cache_file(dir, &key),
                        toml::to_string(&choice).unwrap_or_default(),
                    )
                });
            }
            return Ok(choice);
        }
        if level >= max {
            let reached = match relative {
                Some(e) => format!("an estimated error of {:+.2} %", 100.0 * e),
                None => "no estimate (a solve stopped before the deepest sample)".into(),
            };
            return Err(FeError::InvalidConfig {
                field: "accuracy".into(),
                reason: format!(
                    "{:.2} % not met: the finest level this model allows ({}, {}) has {reached}; \
                     ask for a larger accuracy or give a mesh level",
                    100.0 * opts.target,
                    round3(max),
                    model.at_level(max).mesh_words()
                ),
            });
        }
        // the level the estimate predicts (quarter levels: meshes a user
        // can name again), at least a quarter level finer
        let next = match relative {
            Some(e) => (level * (e.abs() / opts.target).powf(1.0 / order) * 1.02).max(level + 0.25),
            None => level * opts.min_growth,
        };
        let next = (next * 4.0).ceil() / 4.0;
        level = next.min(max);
    }
}

/// The N1 Q2/P1 mesh family: 9-node cells of `1 / level` mm in a 2 mm zone
/// under the tool, growing by `1 + 0.5 / level` beyond it. Level 2 is the
/// benchmark mesh ([`N1_QUAD9_BENCH`]).
pub fn n1_quad9_grading(level: f64) -> Grading {
    Grading {
        h_fine: 1.0 / level,
        fine_length: 2.0,
        growth: 1.0 + 0.5 / level,
    }
}

/// The N1 Q2/P1 benchmark mesh (`mesh = "bench"`, the default of `palpate
/// simulate --benchmark N1`): 0.5 mm 9-node cells (nodes every 0.25 mm) in
/// a 2 mm zone under the needle, growing by 1.25 (320 cells, 3560
/// unknowns), within 0.5 % of the converged force at 2, 5 and 10 mm with
/// 0.25 mm increments (docs/validation/fe.md, "N1 speed").
pub const N1_QUAD9_BENCH: Grading = Grading {
    h_fine: 0.5,
    fine_length: 2.0,
    growth: 1.25,
};

/// The N1 Q1/P0 family: [`crate::MeshDensity`]'s grading at a real level
/// (`0.4 / level` mm in the fine zone, growth `1 + 0.2 / level`).
pub fn n1_quad4_grading(level: f64, fine_zone: f64) -> Grading {
    Grading {
        h_fine: 0.4 / level,
        fine_length: fine_zone,
        growth: 1.0 + 0.2 / level,
    }
}

impl Refinable for N1Needle {
    fn at_level(&self, level: f64) -> Self {
        let mut m = self.clone();
        m.grading = Some(match self.element {
            PlaneCell::Quad9 => n1_quad9_grading(level),
            PlaneCell::Quad4 => n1_quad4_grading(level, self.fine_zone),
        });
        m
    }
    fn convergence_order(&self) -> ConvergenceOrder {
        (**self).convergence_order()
    }
    fn mesh_words(&self) -> String {
        let g = self
            .grading
            .unwrap_or_else(|| self.mesh.grading(self.fine_zone));
        let cell = match self.element {
            PlaneCell::Quad9 => "9-node Q2/P1",
            PlaneCell::Quad4 => "4-node Q1/P0",
        };
        format!("{cell}, {}", graded_mesh_words(g, "tool"))
    }
    fn description(&self) -> String {
        let mut s = (**self).clone();
        s.grading = None;
        s.mesh = crate::MeshDensity { level: 0 };
        format!("{s:?}")
    }
    fn max_level(&self) -> f64 {
        match self.element {
            // level 4: 13,034 unknowns, ~20 s to 10 mm
            PlaneCell::Quad9 => 6.0,
            PlaneCell::Quad4 => 12.0,
        }
    }
}

/// The N3 Q1/P0 family at a real level ([`crate::n3::n3_grading`]).
pub fn n3_hex8_grading(level: f64) -> Grading {
    Grading {
        h_fine: 0.8 / level,
        fine_length: 4.0,
        growth: 1.0 + 0.4 / level,
    }
}

/// The N3 Q2/P1 family at a real level ([`crate::n3::n3_quadratic_grading`]).
pub fn n3_hex27_grading(level: f64) -> Grading {
    Grading {
        h_fine: 1.6 / level,
        fine_length: 4.0,
        growth: 1.0 + 0.8 / level,
    }
}

impl Refinable for N3Needle {
    fn at_level(&self, level: f64) -> Self {
        let mut m = self.clone();
        m.grading = Some(match self.element {
            N3Element::Hex8 => n3_hex8_grading(level),
            N3Element::Hex27 => n3_hex27_grading(level),
        });
        m.core_cells = None;
        m
    }
    fn convergence_order(&self) -> ConvergenceOrder {
        (**self).convergence_order()
    }
    fn mesh_words(&self) -> String {
        let g = self.grading.unwrap_or_else(|| match self.element {
            N3Element::Hex8 => crate::n3::n3_grading(self.level),
            N3Element::Hex27 => crate::n3::n3_quadratic_grading(self.level),
        });
        let (cell, layout) = (
            match self.element {
                N3Element::Hex8 => "8-node Q1/P0",
                N3Element::Hex27 => "27-node Q2/P1",
            },
            match self.mesh {
                N3Mesh::Box => "box",
                N3Mesh::OGrid => "O-grid",
            },
        );
        format!("{cell} {layout}, {}", graded_mesh_words(g, "tool"))
    }
    fn description(&self) -> String {
        let mut s = (**self).clone();
        s.grading = None;
        s.core_cells = None;
        s.level = 0;
        format!("{s:?}")
    }
    fn max_level(&self) -> f64 {
        // Hex27 level 2: 27,750 equations, ~1,600 s of CPU to 10 mm;
        // Hex8 level 2: ~70,000 (docs/validation/fe.md, N3)
        2.0
    }
}

/// The observed orders a three-level estimate accepts: outside them the
/// meshes are not in the asymptotic range and the estimate is a bound.
pub const OBSERVED_ORDERS: (f64, f64) = (0.5, 4.0);

/// A run's discretisation error at one sample, from its mesh family at
/// three levels ([`from_levels`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelError {
    /// The run's force minus the estimated converged force (N).
    pub error: f64,
    /// The order observed at this sample; `None`: the levels' changes do
    /// not shrink as an order within [`OBSERVED_ORDERS`] would, and
    /// `error` is the bound (the run's distance from the finest level plus
    /// the largest change between two levels), signed as the run's
    /// difference from the finest level.
    pub order: Option<f64>,
}

/// The discretisation error of a run from the forces of its own mesh
/// family at three levels whose element sizes halve (`forces`: coarse,
/// middle, fine; `run`: which of them is the run, 0, 1 or 2), at the
/// samples all three reached. Where the changes shrink (`q = (F0 - F1) /
/// (F1 - F2) > 1`) with an observed order `p = log2 q` within
/// [`OBSERVED_ORDERS`], the converged force is the finest one extrapolated
/// (Richardson with `p`); elsewhere the error is bounded by the run's
/// distance from the finest force plus the largest change between two
/// levels (at least the finest level's error if its error is no larger
/// than the last change, which is what an order of 1 or more gives).
pub fn from_levels(forces: [&[f64]; 3], run: usize) -> Result<Vec<LevelError>, FeError> {
    if run > 2 {
        return Err(FeError::InvalidConfig {
            field: "run".into(),
            reason: format!("{run}: the run is level 0, 1 or 2 of the three"),
        });
    }
    if let Some(x) = forces
        .iter()
        .flat_map(|f| f.iter())
        .find(|x| !x.is_finite())
    {
        return Err(FeError::InvalidConfig {
            field: "forces".into(),
            reason: format!("{x} is not finite"),
        });
    }
    let n = forces.iter().map(|f| f.len()).min().unwrap_or(0);
    Ok((0..n)
        .map(|k| {
            let (f0, f1, f2) = (forces[0][k], forces[1][k], forces[2][k]);
            let fr = forces[run][k];
            let (d01, d12) = (f0 - f1, f1 - f2);
            let agree = crate::discretisation::AGREEMENT * f1.abs().max(f2.abs());
            if d12.abs() <= agree && d01.abs() <= agree {
                return LevelError {
                    error: fr - f2,
                    order: Some(f64::INFINITY),
                };
            }
            let q = d01 / d12;
            let p = q.log2();
            if q > 1.0 && p >= OBSERVED_ORDERS.0 && p <= OBSERVED_ORDERS.1 {
                let converged = f2 - d12 / (2f64.powf(p) - 1.0);
                LevelError {
                    error: fr - converged,
                    order: Some(p),
                }
            } else {
                let bound = (fr - f2).abs() + d01.abs().max(d12.abs());
                let sign = if run == 2 { d12 } else { fr - f2 };
                LevelError {
                    error: if sign < 0.0 { -bound } else { bound },
                    order: None,
                }
            }
        })
        .collect())
}

/// The three levels (coarse to fine, element sizes halving) that estimate
/// the error of a run at `level`, and which of them is the run: a run
/// coarser than the description's default level (2) is compared with the
/// level twice as fine (and half as fine), since the coarser levels alone
/// cannot see what the finer mesh changes; a run at the default level or
/// finer with the two levels below it.
pub fn levels_about(level: f64) -> ([f64; 3], usize) {
    if level < crate::cylinder::DEFAULT_LEVEL {
        ([0.5 * level, level, 2.0 * level], 1)
    } else {
        ([0.25 * level, 0.5 * level, level], 2)
    }
}

/// One line saying how a run's error was estimated from its levels and
/// what it is at the deepest sample both reached (`drive`: the samples'
/// drives, `forces`: the run's, `errors`: [`from_levels`]).
pub fn levels_line(
    levels: [f64; 3],
    drive: &[f64],
    run_forces: &[f64],
    errors: &[LevelError],
) -> String {
    let head = format!(
        "discretisation error (from the tool's own mesh levels {}, {} and {}, compared at the run's samples: \
         Richardson with the order they show where their changes shrink, else bounded by the distance to \
         the finest level plus the largest change between levels)",
        round3(levels[0]),
        round3(levels[1]),
        round3(levels[2])
    );
    let Some(k) = errors.len().checked_sub(1).filter(|&k| k > 0) else {
        return format!("{head}: not estimated, a level stopped before the first sample");
    };
    let e = errors[k];
    let d = drive[k];
    let f = run_forces[k];
    let converged = f - e.error;
    let rel = if converged != 0.0 {
        e.error / converged
    } else {
        0.0
    };
    let bounds = errors.iter().filter(|e| e.order.is_none()).count();
    let how = match e.order {
        Some(p) if p.is_finite() => format!("observed order {:.2} at {d} mm", p),
        Some(_) => format!("the levels agree to round-off at {d} mm"),
        None => format!("a bound at {d} mm, where the levels' changes do not shrink"),
    };
    let mut line = format!(
        "{head}: {}{:+.2} % at {d} mm ({how}; estimated converged force {converged:.6} N; \
         bounds at {bounds} of {} samples)",
        if e.order.is_none() { "at most " } else { "" },
        100.0 * rel,
        errors.len()
    );
    if errors.len() < drive.len() {
        line.push_str(&format!(
            "; a level stopped at {} mm, no estimate beyond",
            drive[errors.len() - 1]
        ));
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_core::Drive;
    use palpate_material::Law;

    /// F(h) = F* + C h^p on three levels: the converged force recovered
    /// with the observed order, for the run at any of the three; where the
    /// changes do not shrink, a bound that covers the finest level's
    /// difference.
    #[test]
    fn three_levels_extrapolate_with_their_order_or_bound() {
        for p in [0.8, 1.5, 3.0] {
            let exact = [2.0, 5.0, 9.0];
            let c = [0.3, -0.8, 1.1];
            let at = |h: f64| -> Vec<f64> {
                exact
                    .iter()
                    .zip(&c)
                    .map(|(e, c)| e + c * h.powf(p))
                    .collect()
            };
            let (f0, f1, f2) = (at(1.0), at(0.5), at(0.25));
            for run in 0..3 {
                let fr = [&f0, &f1, &f2][run];
                let est = from_levels([&f0, &f1, &f2], run).unwrap();
                for k in 0..3 {
                    assert!((est[k].order.unwrap() - p).abs() < 1e-9, "{est:?}");
                    assert!(
                        (fr[k] - est[k].error - exact[k]).abs() < 1e-9,
                        "p {p} run {run}: {est:?}"
                    );
                }
            }
        }
        // the middle level off the trend (a jump): a bound, signed as the
        // run's difference from the finest level, covering it
        let (f0, f1, f2) = ([10.0, 20.0], [10.5, 19.0], [10.2, 21.0]);
        let est = from_levels([&f0[..], &f1[..], &f2[..]], 1).unwrap();
        for k in 0..2 {
            assert_eq!(est[k].order, None);
            assert!(est[k].error.abs() >= (f1[k] - f2[k]).abs());
            assert_eq!(est[k].error.signum(), (f1[k] - f2[k]).signum());
        }
        assert!((est[1].error - (-2.0 - 2.0)).abs() < 1e-12, "{est:?}");
        // the estimate covers the samples all three reached
        let est = from_levels([&f0[..], &f1[..1], &f2[..]], 1).unwrap();
        assert_eq!(est.len(), 1);
        assert!(from_levels([&f0[..], &f1[..], &[f64::NAN, 1.0][..]], 1).is_err());
        // the levels: the finer level for a run below the default
        assert_eq!(levels_about(1.0), ([0.5, 1.0, 2.0], 1));
        assert_eq!(levels_about(2.0), ([0.5, 1.0, 2.0], 2));
        assert_eq!(levels_about(3.0), ([0.75, 1.5, 3.0], 2));
    }

    fn nh() -> Law {
        "neo-hookean".parse().expect("law")
    }

    /// A manufactured family F(L) = F* (1 + C L^-p): the search stops at
    /// the first level of its ladder whose estimate meets the target, the
    /// estimate is exact for the true order, and the cache answers the
    /// second call without a solve.
    #[derive(Clone, Debug)]
    struct Manufactured {
        level: f64,
        c: f64,
        p: f64,
    }
    impl Refinable for Manufactured {
        fn at_level(&self, level: f64) -> Self {
            Manufactured { level, ..*self }
        }
        fn convergence_order(&self) -> ConvergenceOrder {
            ConvergenceOrder {
                order: self.p,
                source: "manufactured".into(),
            }
        }
        fn mesh_words(&self) -> String {
            format!("level {}", self.level)
        }
        fn description(&self) -> String {
            format!("manufactured c {} p {}", self.c, self.p)
        }
        fn max_level(&self) -> f64 {
            16.0
        }
    }
    fn forces(m: &Manufactured, l: &Loading) -> Result<Vec<f64>, ForwardError> {
        Ok(l.drive
            .iter()
            .map(|d| d * (1.0 + m.c * m.level.powf(-m.p)))
            .collect())
    }
    fn ramp() -> Loading {
        Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 1.0, 2.0, 1.5])
    }

    #[test]
    fn the_search_meets_the_target_with_an_exact_estimate() {
        let m = Manufactured {
            level: 1.0,
            c: 0.2,
            p: 1.5,
        };
        let dir = std::env::temp_dir().join(format!("palpate-accuracy-{}", std::process::id()));
        let mut opts = AccuracyOptions::new(0.01);
        opts.cache_dir = Some(dir.clone());
        let mut seen = Vec::new();
        let c = choose(&m, &ramp(), &opts, |m, l| {
            seen.push(l.drive.clone());
            forces(m, l)
        })
        .unwrap();
        // judged on the loading cut at its deepest sample
        assert!(seen.iter().all(|d| d == &[0.0, 1.0, 2.0]));
        // the estimate is relative to the converged force (2)
        let exact = 0.2 * c.level.powf(-1.5);
        assert!(
            c.estimate <= 0.01 && (c.estimate - exact).abs() < 1e-12,
            "{c:?}"
        );
        // near the cheapest: the level predicted from the first pair,
        // rounded up to a quarter, within a tenth of the exact cheapest
        // level (0.2 L^-1.5 = 0.01)
        let cheapest = 20f64.powf(1.0 / 1.5);
        assert!(c.level >= cheapest && c.level <= 1.1 * cheapest, "{c:?}");
        assert!(!c.cached && c.solves >= 2 && c.trials.len() >= 2);
        assert!(c.line().contains("1.00 % accuracy"), "{}", c.line());
        let again = choose(&m, &ramp(), &opts, |_, _| panic!("cached")).unwrap();
        assert!(again.cached && again.level == c.level && again.estimate == c.estimate);
        // another target or another model is another key
        let other = cache_key(&m.description(), &to_deepest(&ramp()), 0.02);
        assert_ne!(
            other,
            cache_key(&m.description(), &to_deepest(&ramp()), 0.01)
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn an_unreachable_target_and_bad_options_are_named() {
        let m = Manufactured {
            level: 1.0,
            c: 50.0,
            p: 0.5,
        };
        let e = choose(&m, &ramp(), &AccuracyOptions::new(0.001), forces)
            .unwrap_err()
            .to_string();
        assert!(e.contains("accuracy") && e.contains("finest level"), "{e}");
        for t in [0.0, -0.1, 1.5, f64::NAN] {
            let e = choose(&m, &ramp(), &AccuracyOptions::new(t), forces)
                .unwrap_err()
                .to_string();
            assert!(e.contains("accuracy"), "{e}");
        }
        let empty = Loading::quasi_static(Drive::DisplacementMm, vec![]);
        assert!(choose(&m, &empty, &AccuracyOptions::new(0.01), forces).is_err());
    }

    #[test]
    fn the_model_families() {
        let n1 = N1Needle::new(nh());
        let mut q9 = n1.clone();
        q9.element = PlaneCell::Quad9;
        assert_eq!(q9.at_level(2.0).grading, Some(N1_QUAD9_BENCH));
        // level L's companion at L/2 is the coarser() of simulate's estimate
        let c = q9.at_level(2.0).coarser().model.grading.unwrap();
        let g = q9.at_level(1.0).grading.unwrap();
        assert!((c.h_fine - g.h_fine).abs() < 1e-15 && (c.growth - g.growth).abs() < 1e-15);
        // the integer levels of Q1/P0 are MeshDensity's
        let g = n1.at_level(3.0).grading.unwrap();
        assert_eq!(g, crate::MeshDensity::FINE.grading(n1.fine_zone));
        assert_eq!(n1.at_level(3.0).description(), n1.description());
        assert_ne!(q9.description(), n1.description());
        assert!(q9.at_level(2.0).mesh_words().contains("9-node"));

        let n3 = N3Needle::new(nh());
        assert_eq!(n3.at_level(1.0).grading, Some(crate::n3::n3_grading(1)));
        let mut h27 = n3.clone();
        h27.element = N3Element::Hex27;
        h27.mesh = N3Mesh::OGrid;
        let (a, b) = (
            h27.at_level(1.0).grading.unwrap(),
            crate::n3::n3_quadratic_grading(1),
        );
        assert!(
            (a.h_fine - b.h_fine).abs() < 1e-12
                && (a.growth - b.growth).abs() < 1e-12
                && (a.fine_length - b.fine_length).abs() < 1e-12,
            "{a:?} vs {b:?}"
        );
        assert_eq!(h27.at_level(1.5).description(), h27.description());
        assert!(h27
            .at_level(1.0)
            .mesh_words()
            .contains("27-node Q2/P1 O-grid"));
    }

    #[test]
    fn the_deepest_sample_cuts_the_loading() {
        let l = Loading::timed(
            Drive::DisplacementMm,
            vec![0.0, 1.0, 2.0, 3.0],
            vec![0.0, 2.0, 1.0, 2.0],
        );
        let d = to_deepest(&l);
        assert_eq!(d.drive, [0.0, 2.0]);
        assert_eq!(d.time.as_deref(), Some(&[0.0, 1.0][..]));
    }
}
