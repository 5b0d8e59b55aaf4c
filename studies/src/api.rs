//! The typed library API of palpate: typed options in, typed results out,
//! nothing printed (progress goes to an observer the caller gives, or
//! nowhere). The `palpate` command line reads its options into these types
//! and calls it, and so does the Python package, so the two check and
//! compute the same; the errors name the command line's options (`--law`,
//! `--param`, ...), which the Python keywords mirror.
//!
//! * [`calibrate`]: fit a law to records ([`CalibrateOptions`] -> [`Calibration`]);
//! * [`diagnose::diagnose`]: the sim-to-real gap of a record
//!   ([`diagnose::gap_options`] -> `GapReport`);
//! * [`localize`]: nodules from an R2 rolled record ([`LocalizeOptions`] -> [`Localized`]);
//! * [`identify::identify_q1`]: the staged identification of a Q1
//!   ramp-and-hold record ([`identify::Q1Options`] -> `TwoStageResult`);
//! * [`calibrate_experiment`]: fit an experiment description's parameters
//!   to force records by finite elements ([`experiment_spec`] reads the
//!   description, [`ExperimentFitOptions`]);
//! * [`simulate::simulate`]: an FE benchmark's or experiment's force curve
//!   ([`simulate::SimulateOptions`] -> [`simulate::Simulated`]), and
//!   [`simulate::r2::scan`] the R2 scan (-> [`simulate::r2::Scan`]);
//! * [`sample::sample`]: the posterior of a law's or an experiment's
//!   parameters by MCMC ([`sample::SampleOptions`] -> [`sample::Sampled`]:
//!   the draws, their diagnostics, the report);
//! * [`run_study`] and [`check_study`]: a study manifest into its run folder,
//!   or only checked.
//!
//! Records are read with [`crate::records::data_option`] (files, or
//! columns in memory). What a long run says (summaries, progress bars) goes
//! to an [`Observer`]: [`Silent`] shows nothing, [`Stderr`] what the command
//! line shows.
//!
//! ```no_run
//! use palpate_studies::api::{calibrate, CalibrateOptions};
//! use palpate_studies::records::{TestData, TestKind};
//! let kind = TestKind::parse("uniaxial")?;
//! let data = TestData::read("uniaxial", kind, "uniaxial.csv".as_ref())?;
//! let fit = calibrate(&[data], &CalibrateOptions::new("yeoh".parse()?))?;
//! println!("{:?}", fit.params);
//! # Ok::<(), anyhow::Error>(())
//! ```

use crate::apps::localize::posterior::{localize as sample_localisation, LocOptions, LocRun};
use crate::apps::localize::record::Record;
use crate::apps::localize::{LocModel, LocSetup};
use crate::model::calibration::{calibrate as fit_law, Request};
use crate::model::{ExperimentSpec, ModelSpec, Viscous};
use crate::records::TestData;
use crate::study::runner::{run_study_counted, RunObserver, RunOptions, RunSummary};
use palpate_inverse::{Method, ResidualKind};
use palpate_material::Law;
use std::path::{Path, PathBuf};

pub mod diagnose;
mod estimate;
pub mod identify;
pub mod sample;
pub mod simulate;

/// Where a long run's lines (summaries, warnings, the error estimate) and
/// progress bars go.
pub trait Observer {
    /// A line the command line prints on standard error.
    fn message(&self, text: &str);
    /// Whether to draw progress bars (on standard error, when it is a
    /// terminal).
    fn bars(&self) -> bool {
        false
    }
}

/// Lines and progress bars on standard error, as the command line shows
/// them.
pub struct Stderr;

impl Observer for Stderr {
    fn message(&self, text: &str) {
        eprintln!("{text}");
    }
    fn bars(&self) -> bool {
        true
    }
}

pub use crate::apps::localize::posterior::LocSampler;
pub use crate::model::calibration::Calibration;

/// The estimator of a calibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Estimator {
    /// Levenberg-Marquardt.
    #[default]
    Lm,
    /// BFGS (argmin).
    Bfgs,
    /// L-BFGS with a memory of 10 (argmin).
    Lbfgs,
}

impl Estimator {
    /// The method with its default settings.
    pub fn method(self) -> Method {
        match self {
            Estimator::Lm => Method::LevenbergMarquardt(Default::default()),
            Estimator::Bfgs => Method::Bfgs(Default::default()),
            Estimator::Lbfgs => Method::Lbfgs {
                memory: 10,
                options: Default::default(),
            },
        }
    }
}

impl std::str::FromStr for Estimator {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Self> {
        match s {
            "lm" => Ok(Estimator::Lm),
            "bfgs" => Ok(Estimator::Bfgs),
            "lbfgs" => Ok(Estimator::Lbfgs),
            _ => anyhow::bail!("unknown estimator `{s}`; expected lm, bfgs or lbfgs"),
        }
    }
}

/// How to fit a law to records.
#[derive(Debug, Clone)]
pub struct CalibrateOptions {
    pub law: Law,
    pub residual: ResidualKind,
    pub estimator: Estimator,
    /// Parameters held, by name.
    pub fixed: Vec<(String, f64)>,
    /// A viscoelastic form of the homogeneous tests (timed records).
    pub viscous: Option<Viscous>,
}

impl CalibrateOptions {
    /// `law` by Levenberg-Marquardt on absolute residuals, nothing held,
    /// elastic.
    pub fn new(law: Law) -> Self {
        CalibrateOptions {
            law,
            residual: ResidualKind::Absolute,
            estimator: Estimator::Lm,
            fixed: Vec::new(),
            viscous: None,
        }
    }
}

/// Fits `options.law` to `data` (each record's test gives its model). The
/// errors name the parameter or record at fault.
pub fn calibrate(data: &[TestData], options: &CalibrateOptions) -> anyhow::Result<Calibration> {
    anyhow::ensure!(!data.is_empty(), "data: give at least one record");
    for (k, (name, v)) in options.fixed.iter().enumerate() {
        anyhow::ensure!(v.is_finite(), "fixed {name}: {v} is not a finite number");
        anyhow::ensure!(
            !options.fixed[..k].iter().any(|(n, _)| n == name),
            "fixed {name}: held twice; give each parameter once"
        );
    }
    crate::run::checks::check_fixed(&options.law, &options.fixed, "fixed")?;
    fit_law(Request {
        law: options.law,
        model: None,
        fitted: data,
        predict: &[],
        residual: options.residual,
        method: options.estimator.method(),
        fixed: options.fixed.clone(),
        observer: None,
        viscous: options.viscous,
    })
}

impl CalibrateOptions {
    /// The options as the command line and the Python package give them
    /// (names of the law, residual, estimator and viscoelastic form); the
    /// errors name the option (`--law`, `--residual`, `--estimator`,
    /// `--fix`, `--viscoelastic`) as `palpate calibrate` does.
    pub fn parse(
        law: &str,
        residual: &str,
        estimator: &str,
        fixed: Vec<(String, f64)>,
        viscoelastic: Option<&str>,
    ) -> anyhow::Result<Self> {
        let law: Law = law
            .parse()
            .map_err(|e| anyhow::anyhow!("--law {law}: {e}"))?;
        let residual: ResidualKind = residual
            .parse()
            .map_err(|e| anyhow::anyhow!("--residual: {e}"))?;
        let estimator: Estimator = anyhow::Context::context(estimator.parse(), "--estimator")?;
        crate::run::checks::check_fixed(&law, &fixed, "--fix")?;
        let viscous = viscoelastic
            .map(Viscous::parse)
            .transpose()
            .map_err(|e| anyhow::anyhow!("--viscoelastic {e}"))?;
        Ok(CalibrateOptions {
            law,
            residual,
            estimator,
            fixed,
            viscous,
        })
    }
}

/// The experiment a calibration fits: the description `experiment` (a
/// file, a preset's name or JSON text), or the preset named `benchmark`
/// (N1, N3) with its law replaced by `law` when given; `None` for the other
/// calibrations (homogeneous tests, C1, Q1).
pub fn experiment_spec(
    experiment: Option<&str>,
    benchmark: Option<&str>,
    law: Option<&str>,
) -> anyhow::Result<Option<ExperimentSpec>> {
    if let Some(e) = experiment {
        return ExperimentSpec::from_option(e).map(Some);
    }
    let Some(b) = benchmark else {
        return Ok(None);
    };
    if b.eq_ignore_ascii_case("c1") || b.eq_ignore_ascii_case("q1") {
        return Ok(None);
    }
    let Some(preset) = crate::model::experiment::preset(b) else {
        anyhow::bail!(
            "--benchmark {b}: calibrate takes C1, Q1 or a preset of the experiment descriptions ({})",
            crate::model::experiment::preset_names().join(", ")
        );
    };
    let mut spec = ExperimentSpec {
        source: crate::model::ExperimentSource::Preset(b.to_ascii_uppercase()),
        experiment: Box::new(preset),
    };
    if let Some(law) = law {
        law.parse::<Law>()
            .map_err(|e| anyhow::anyhow!("--law {law}: {e}"))?;
        let materials = &mut spec.experiment.materials;
        anyhow::ensure!(
            materials.len() == 1,
            "--law {law}: preset {b} has {} materials; give the laws in an experiment file (palpate experiment show {b})",
            materials.len()
        );
        for m in materials.values_mut() {
            if m.law != *law {
                m.law = law.to_string();
                m.params.clear();
            }
        }
    }
    spec.check()?;
    Ok(Some(spec))
}

/// How to fit an experiment's parameters ([`calibrate_experiment`]).
#[derive(Debug, Clone, Default)]
pub struct ExperimentFitOptions {
    pub residual: ResidualKind,
    pub estimator: Estimator,
    /// Parameters held, by name, beside the description's fixed ones.
    pub fixed: Vec<(String, f64)>,
}

impl ExperimentFitOptions {
    /// The residual and estimator by name, errors naming the option as
    /// `palpate calibrate` does.
    pub fn parse(
        residual: &str,
        estimator: &str,
        fixed: Vec<(String, f64)>,
    ) -> anyhow::Result<Self> {
        Ok(ExperimentFitOptions {
            residual: residual
                .parse()
                .map_err(|e| anyhow::anyhow!("--residual: {e}"))?,
            estimator: anyhow::Context::context(estimator.parse(), "--estimator")?,
            fixed,
        })
    }
}

/// Fits the fitted parameters of the experiment `spec` to the force
/// records `data` by finite elements, its fixed parameters and
/// `options.fixed` held. The mesh is sized for the deepest displacement of
/// the records when the description's protocol is the record's.
pub fn calibrate_experiment(
    spec: ExperimentSpec,
    data: &[TestData],
    options: &ExperimentFitOptions,
) -> anyhow::Result<Calibration> {
    let space = spec
        .experiment
        .param_space()
        .map_err(|e| anyhow::anyhow!("{}: {e}", spec.source))?;
    let names = space.names();
    for (k, (name, value)) in options.fixed.iter().enumerate() {
        anyhow::ensure!(
            names.iter().any(|n| n == name),
            "--fix {name}={value}: the experiment has no parameter `{name}`; its parameters: {}",
            names.join(", ")
        );
        anyhow::ensure!(
            value.is_finite(),
            "--fix {name}={value}: `{value}` is not a finite number"
        );
        anyhow::ensure!(
            !options.fixed[..k].iter().any(|(n, _)| n == name),
            "--fix {name}={value}: {name} is fixed twice; give each parameter once"
        );
    }
    let law: Law = spec
        .law_text()
        .parse()
        .map_err(|e| anyhow::anyhow!("{}: {e}", spec.source))?;
    let deepest = data
        .iter()
        .flat_map(|d| d.loading.drive.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let mut spec = spec;
    spec.experiment.size_for_depth(deepest);
    spec.check()?;
    let model = ModelSpec::Experiment(spec);
    model
        .validate()
        .map_err(|e| anyhow::anyhow!("{}", e.expected))?;
    fit_law(Request {
        law,
        model: Some(&model),
        fitted: data,
        predict: &[],
        residual: options.residual,
        method: options.estimator.method(),
        fixed: options.fixed.clone(),
        observer: None,
        viscous: None,
    })
}

/// The localisation model's scan ([`LocSetup`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scan {
    /// The centre model with the end lean ([`LocSetup::r2_lean`]).
    #[default]
    Lean,
    /// The scan at the block's centre only ([`LocSetup::r2`]).
    Centre,
    /// The scan along the block ([`LocSetup::r2_along`]).
    Along,
}

impl std::str::FromStr for Scan {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Self> {
        match s {
            "lean" => Ok(Scan::Lean),
            "centre" => Ok(Scan::Centre),
            "along" => Ok(Scan::Along),
            _ => anyhow::bail!("scan `{s}`: expected lean, centre or along"),
        }
    }
}

/// How to locate nodules in an R2 record.
#[derive(Debug, Clone)]
pub struct LocalizeOptions {
    /// Rolling depth of the record (mm).
    pub rd: f64,
    pub scan: Scan,
    /// Nodules to locate (1 to 8).
    pub nodules: usize,
    /// Training and held-out FE scans (`None`: the scan's defaults).
    pub design: Option<usize>,
    pub holdout: Option<usize>,
    pub seed: u64,
    pub sampler: LocSampler,
    /// The surrogates' cache folder.
    pub cache: PathBuf,
}

impl LocalizeOptions {
    /// Three nodules at `rd` with the lean model, NUTS, seed 1, cached in
    /// `cache`.
    pub fn new(rd: f64, cache: PathBuf) -> Self {
        LocalizeOptions {
            rd,
            scan: Scan::Lean,
            nodules: 3,
            design: None,
            holdout: None,
            seed: 1,
            sampler: LocSampler::Nuts,
            cache,
        }
    }

    /// The model's setup, or the field at fault and why
    /// ([`LocSetup::check`]'s names).
    pub fn setup(&self) -> Result<LocSetup, (String, String)> {
        let mut setup = match self.scan {
            Scan::Along => LocSetup::r2_along(self.rd),
            Scan::Lean => LocSetup::r2_lean(self.rd),
            Scan::Centre => LocSetup::r2(self.rd),
        };
        if let Some(n) = self.design {
            setup.training = n;
        }
        if let Some(n) = self.holdout {
            setup.holdout = n;
        }
        setup.check()?;
        if !(1..=8).contains(&self.nodules) {
            return Err(("--nodules".into(), "give 1 to 8 nodules".into()));
        }
        Ok(setup)
    }
}

/// A localisation with its model and record.
pub struct Localized {
    pub model: LocModel,
    pub record: Record,
    pub run: LocRun,
    /// Wall time until the model was ready (built or read from the cache, s).
    pub model_ready_s: f64,
}

/// Locates nodules in the R2 record `data` (CSV with position_mm,force_N):
/// the model of `options.rd` (built once and cached in `options.cache`,
/// progress bars while FE scans run), then the posterior.
pub fn localize(data: &Path, options: &LocalizeOptions) -> anyhow::Result<Localized> {
    let setup = options
        .setup()
        .map_err(|(f, r)| anyhow::anyhow!("{}: {r}", f.trim_start_matches("--")))?;
    let record = Record::read(data, (setup.template.press_x, setup.template.roll_to))?;
    let t0 = std::time::Instant::now();
    let model = LocModel::load_or_build(&setup, &options.cache)?;
    let model_ready_s = t0.elapsed().as_secs_f64();
    let o = LocOptions {
        nodules: options.nodules,
        seed: options.seed,
        sampler: options.sampler,
        ..Default::default()
    };
    let run = sample_localisation(&model, &record.positions, &record.force, &o, None)?;
    Ok(Localized {
        model,
        record,
        run,
        model_ready_s,
    })
}

/// An observer that shows nothing.
pub struct Silent;

impl RunObserver for Silent {
    fn message(&self, _: &str) {}
}

impl Observer for Silent {
    fn message(&self, _: &str) {}
}

/// Runs the study `manifest` into its run folder (or one shard of it),
/// progress to `observer` ([`Silent`]: none).
pub fn run_study(
    manifest: &Path,
    options: &RunOptions,
    observer: &dyn RunObserver,
) -> anyhow::Result<RunSummary> {
    run_study_counted(manifest, options, observer)
}

/// What [`check_study`] read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StudyCheck {
    pub data_sets: usize,
    pub rows: usize,
    pub models: usize,
    pub steps: usize,
}

/// Checks the study `manifest` (fields, references) and reads every data
/// file it names, without running it. The errors name the file, line and
/// column, and the data set.
pub fn check_study(manifest: &Path) -> anyhow::Result<StudyCheck> {
    use crate::records::TestKind;
    let m = crate::study::manifest::Manifest::read(manifest)?.validate(manifest)?;
    let dir = manifest.parent().unwrap_or(Path::new("."));
    let mut rows = 0;
    for (name, spec) in &m.data {
        let kind = TestKind::parse(&spec.test)
            .map_err(|e| anyhow::anyhow!("{}: data.{name}.test: {e}", manifest.display()))?;
        let options = spec
            .read_options()
            .map_err(|e| anyhow::anyhow!("{}: data.{name}: {e:#}", manifest.display()))?;
        let d = TestData::read_with(name, kind, &dir.join(&spec.file), options)
            .map_err(|e| anyhow::anyhow!("{}: data.{name}: {e:#}", manifest.display()))?;
        rows += d.observed.len();
    }
    Ok(StudyCheck {
        data_sets: m.data.len(),
        rows,
        models: m.models.len(),
        steps: m.steps.len(),
    })
}
