//! The FE runs behind the localisation model of one RD as independent
//! units, what the shards of a study's localize step compute
//! (`crate::steps::localize`, `crate::run::shard`): unit 0 the nodule-free pass
//! F0 ([`LocSetup::baseline_pass`]), then one unit per scan of the
//! surrogate's design (the depths [`Surrogate::design`] gives for
//! [`LocSetup::scan_model`]: the training ones, then the held-out ones).
//! Each unit is computed alone ([`ModelUnits::compute`]), anywhere, and the
//! model is assembled once all are there ([`ModelUnits::assemble`], the
//! surrogate by [`Surrogate::from_runs`]): the model
//! [`LocModel::load_or_build`] makes in one process, but for the build
//! times (tested in `studies/tests/integration/localize_units.rs`). With
//! the end lean ([`LocSetup::lean`], the study's default) its FE scans
//! ([`lean::cases`]) are units too, after the design's scans.
//!
//! The scan model is a type parameter so that the enumeration and the
//! assembly can be tested on a cheap stand-in for the FE scan; a study
//! uses [`ModelUnits::r2`].

use super::{lean, Baseline, LocModel, LocSetup};
use crate::run::surrogate::code_version;
use palpate_core::{ForwardModel, Loading};
use palpate_fe::r2_scan::R2NoduleScan;
use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateRequest};
use serde::{Deserialize, Serialize};

/// The result of one unit, as a run folder caches it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ModelRun {
    /// Unit 0: the nodule-free pass.
    Baseline(Baseline),
    /// A scan of the design: the force at the offsets, or why the FE run
    /// failed (the surrogate leaves a failed run out, as `Surrogate::build`).
    Scan(Result<Vec<f64>, String>),
    /// A lean scan ([`lean::scan`]): the force at the lean's offsets.
    Lean(Vec<f64>),
}

/// The FE scan of one lean case (distance from the end, depth), or a
/// stand-in for it in tests.
pub type LeanScan = Box<dyn Fn((f64, f64)) -> Result<Vec<f64>, String> + Send + Sync>;

/// The units of one RD's localisation model.
pub struct ModelUnits<M> {
    setup: LocSetup,
    scan: M,
    loading: Loading,
    bounds: ParamBox,
    /// The scan depths, training then held-out.
    points: Vec<Vec<f64>>,
    /// With the end lean: its scan of each of [`lean::cases`].
    lean: Option<LeanScan>,
}

impl ModelUnits<R2NoduleScan> {
    /// The units of `setup`'s model (checked: RD, scan and design).
    pub fn r2(setup: &LocSetup) -> anyhow::Result<Self> {
        setup
            .check()
            .map_err(|(f, r)| anyhow::anyhow!("{f} {}: {r}", setup.template.rd))?;
        Self::new(setup, setup.scan_model())
    }
}

impl<M: ForwardModel> ModelUnits<M> {
    /// The units of `setup` with `scan` as the scanned model (depth ->
    /// force at `setup.offsets()`).
    pub fn new(setup: &LocSetup, scan: M) -> anyhow::Result<Self> {
        let bounds = setup.scan_bounds(&scan)?;
        let mut u = ModelUnits {
            setup: setup.clone(),
            scan,
            loading: setup.scan_loading(),
            bounds,
            points: Vec::new(),
            lean: None,
        };
        if setup.lean {
            let s = setup.clone();
            u.lean = Some(Box::new(move |c| lean::scan(&s, c)));
        }
        u.points = Surrogate::design(&u.request())
            .map_err(|e| anyhow::anyhow!("the design of the R2 scan surrogate: {e}"))?;
        Ok(u)
    }

    /// The same units with `scan` for the lean's FE scans (a cheap
    /// stand-in in tests); `setup.lean` must be set.
    pub fn with_lean_scan(mut self, scan: LeanScan) -> Self {
        if self.setup.lean {
            self.lean = Some(scan);
        }
        self
    }

    /// The number of lean units (0 without the lean).
    fn lean_units(&self) -> usize {
        if self.lean.is_some() {
            lean::cases().len()
        } else {
            0
        }
    }

    /// The surrogate's request; its description is `palpate localize`'s
    /// (the setup and the code version), so the assembled surrogate has
    /// the key of the one [`LocModel::load_or_build`] caches.
    pub fn request(&self) -> SurrogateRequest<'_> {
        SurrogateRequest {
            model: &self.scan,
            loading: &self.loading,
            bounds: self.bounds.clone(),
            options: self.setup.scan_options(),
            description: format!("{}; {}", self.setup.description(), code_version()),
        }
    }

    /// Number of units: the baseline, the design's scans and the lean's.
    pub fn len(&self) -> usize {
        1 + self.points.len() + self.lean_units()
    }

    /// Never empty (the baseline is always a unit).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Everything unit `k`'s result depends on but the code version (a
    /// study adds it to the cache key): the setup (RD, laws, mesh, block,
    /// path, scan), and for a scan the model, the offsets and the depth.
    pub fn inputs(&self, k: usize) -> String {
        let setup = self.setup.description();
        let scans = 1 + self.points.len();
        match k {
            0 => format!("R2 localisation baseline; {setup}"),
            k if k >= scans => {
                let (e, d) = lean::cases()[k - scans];
                format!(
                    "R2 localisation lean scan; {setup}; distance {e} mm; depth {d} mm; offsets {:?}",
                    self.setup.lean_offsets()
                )
            }
            _ => format!(
                "R2 localisation scan; {setup}; {}; offsets {:?}; depth {:?}",
                self.scan.name(),
                self.loading.drive,
                self.points[k - 1]
            ),
        }
    }

    /// Computes unit `k` (an FE run: seconds to minutes). A failed scan
    /// is a result (the surrogate leaves it out); a failed baseline is an
    /// error, as the model cannot do without it.
    pub fn compute(&self, k: usize) -> anyhow::Result<ModelRun> {
        anyhow::ensure!(
            k < self.len(),
            "unit {k} of a localisation model of {} units",
            self.len()
        );
        let scans = 1 + self.points.len();
        Ok(match (k, &self.lean) {
            (0, _) => ModelRun::Baseline(self.setup.baseline_pass(None)?),
            (k, Some(scan)) if k >= scans => {
                ModelRun::Lean(scan(lean::cases()[k - scans]).map_err(anyhow::Error::msg)?)
            }
            _ => ModelRun::Scan(self.scan_run(k)),
        })
    }

    /// The FE scan of unit `k >= 1`: forces at the offsets, or why it
    /// failed.
    pub fn scan_run(&self, k: usize) -> Result<Vec<f64>, String> {
        Surrogate::run_point(&self.scan, &self.loading, &self.points[k - 1])
    }

    /// The scan surrogate from the baseline and the scans (units 1..):
    /// along the block, of the excess ([`LocSetup::excess_curve`]),
    /// otherwise of the force.
    ///
    /// With `centre` (the model scanned at the centre) the surrogate along
    /// the block is of what the scans add to the centre's excess.
    pub fn surrogate(
        &self,
        baseline: &Baseline,
        scans: Vec<Result<Vec<f64>, String>>,
        centre: Option<&LocModel>,
    ) -> anyhow::Result<Surrogate> {
        let offsets = self.setup.offsets();
        let scans = if self.setup.along_block {
            scans
                .into_iter()
                .zip(&self.points)
                .map(|(r, theta)| {
                    let mut e = self.setup.excess_curve(baseline, theta, &r?);
                    if let Some(c) = centre {
                        let mut grid = vec![0.0; c.scan.loading().len()];
                        c.excess_grid(theta[0], c.centre, &mut grid)
                            .map_err(|err| err.to_string())?;
                        for (v, &o) in e.iter_mut().zip(&offsets) {
                            *v -= c.excess_at(&grid, o, false);
                        }
                    }
                    Ok(e)
                })
                .collect()
        } else {
            scans
        };
        Surrogate::from_runs(&self.request(), scans)
            .map_err(|e| anyhow::anyhow!("building the surrogate of {}: {e}", self.scan.name()))
    }

    /// The model from every unit's result, in unit order.
    pub fn assemble(&self, runs: Vec<ModelRun>) -> anyhow::Result<LocModel> {
        let rd = self.setup.template.rd;
        anyhow::ensure!(
            runs.len() == self.len(),
            "{} results for the {} units of the localisation model at RD {rd}",
            runs.len(),
            self.len()
        );
        let mut runs = runs.into_iter();
        let Some(ModelRun::Baseline(baseline)) = runs.next() else {
            anyhow::bail!("unit 0 of the localisation model at RD {rd} is not the baseline");
        };
        let (mut scans, mut leans) = (Vec::new(), Vec::new());
        for (k, r) in runs.enumerate() {
            let want_scan = k < self.points.len();
            match r {
                ModelRun::Scan(s) if want_scan => scans.push(s),
                ModelRun::Lean(f) if !want_scan => leans.push(f),
                _ => anyhow::bail!(
                    "unit {} of the localisation model at RD {rd} is not a {}",
                    k + 1,
                    if want_scan { "scan" } else { "lean scan" }
                ),
            }
        }
        let s = self.surrogate(&baseline, scans, None)?;
        let mut m = LocModel::from_parts(&self.setup, s, baseline, None, None)?;
        if self.lean.is_some() {
            m.lean = Some(lean::from_runs(&m, &self.setup, &leans)?);
        }
        Ok(m)
    }
}
