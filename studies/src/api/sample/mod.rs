//! The Bayesian posterior of a law's (or an experiment's) parameters by
//! MCMC, with diagnostics, a Laplace approximation beside it and the
//! summary `palpate sample --json` writes. The draws are extended until
//! converged (`palpate_uq::mcmc::sample_until_converged`); finite-element
//! records (N1, N3, Q1, an experiment) are sampled through a cached
//! surrogate of their model ([`fe`]).
//!
//! Two steps, so that a caller can check its outputs against the records
//! before any work: [`prepare`] checks the options and reads the records,
//! [`run`] samples ([`sample`] does both). Nothing is printed: lines and
//! progress bars go to the [`Observer`]; the summary table and the
//! warnings are in the result ([`Sampled::table`], [`Sampled::warnings`]).
//! The errors name the command line's options (`--draws`, `--prior`, ...),
//! which the Python keywords mirror.

pub mod fe;
mod report;

use std::path::{Path, PathBuf};

use anyhow::Context;
use palpate_material::Law;
use palpate_uq::likelihood::{
    fit_and_laplace, thermodynamic_integration, Correlation, DataSet, NoiseModel, NoiseSd,
    Posterior, Prior,
};
use palpate_uq::mcmc::{
    correlation, sample_until_converged, summarize, Chains, Convergence, DemcSettings,
    EnsembleSettings, NutsSettings, ParamSummary, Sampler,
};
use serde_json::{json, Value};

use super::Observer;
use crate::model::ExperimentSpec;
use crate::records::arrays::ArrayRecord;
use crate::records::{ReadOptions, TestData};
pub use fe::{fe_benchmark, FE_BENCHMARKS};

/// The MCMC sampler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SamplerKind {
    /// The affine-invariant ensemble (stretch move).
    Ensemble,
    /// DE-MCz.
    Demc,
    /// NUTS.
    #[default]
    Nuts,
}

impl SamplerKind {
    /// The name the command line takes and the progress lines show.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Ensemble => "ensemble",
            SamplerKind::Demc => "demc",
            SamplerKind::Nuts => "nuts",
        }
    }
}

impl std::str::FromStr for SamplerKind {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Self> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "ensemble" | "emcee" | "stretch" => SamplerKind::Ensemble,
            "demc" | "de-mc" | "demcz" | "dream" => SamplerKind::Demc,
            "nuts" => SamplerKind::Nuts,
            other => anyhow::bail!("--sampler {other}: expected ensemble, demc or nuts"),
        })
    }
}

/// What to sample and how. `None` is the default `palpate sample --help`
/// gives; an option of another kind of record (an FE option without an FE
/// benchmark, a model option with an experiment) is refused by name.
#[derive(Debug, Clone, Default)]
pub struct SampleOptions {
    /// The material law (not with `experiment`, whose description names its laws).
    pub law: Option<String>,
    /// A lab's own experiment (a file, a preset's name or JSON text),
    /// sampled through a surrogate of its FE model.
    pub experiment: Option<String>,
    /// C1 (analytic), or N1, N3, Q1 (finite elements, through a surrogate).
    pub benchmark: Option<String>,
    /// The records: `TEST=FILE` (homogeneous tests), `FILE` with a
    /// benchmark or an experiment; `<array:K>` for the K-th record given
    /// as arrays.
    pub data: Vec<String>,
    /// The reading options every homogeneous or C1 file starts from.
    pub reading: ReadOptions,
    /// FE: the surrogate's box, `NAME=LO,HI` for every parameter.
    pub boxes: Vec<String>,
    /// FE benchmarks: coarse, medium, fine or a level (default coarse).
    pub mesh: Option<String>,
    /// FE benchmarks: exact or a ratio K/mu.
    pub bulk: Option<String>,
    /// N1, N3: Coulomb friction.
    pub friction: Option<f64>,
    /// Q1: the Prony series held fixed, `g1=..,tau1=..`.
    pub prony: Option<String>,
    /// Q1: radius of the punch's rounded edge (mm).
    pub edge_radius: Option<f64>,
    /// FE: training and held-out runs of the surrogate.
    pub design: Option<usize>,
    pub holdout: Option<usize>,
    /// FE: the surrogates' cache folder (default: [`crate::run::surrogate::default_cache_dir`]).
    pub cache: Option<PathBuf>,
    pub sampler: SamplerKind,
    /// Stored draws per chain of the first run, the cap when extending, warm-up.
    pub draws: Option<usize>,
    pub max_draws: Option<usize>,
    pub tune: Option<usize>,
    /// NUTS chains, ensembles or DE-MCz populations.
    pub parallel: Option<usize>,
    pub seed: u64,
    /// Known noise SD of every data set (inferred when `None`).
    pub sigma: Option<f64>,
    /// Infer an AR(1) correlation of successive residuals per data set.
    pub ar1: bool,
    /// Priors, `NAME=SPEC` (flat, uniform:L,U, normal:M,S, lognormal:MU,SIGMA,
    /// halfnormal:S, loguniform:L,U); flat inside the bounds otherwise.
    pub priors: Vec<String>,
    /// Also the evidence by thermodynamic integration.
    pub evidence: bool,
}

impl SampleOptions {
    /// `law` on the records `data` by NUTS, every other option at its default.
    pub fn new(law: &str, data: Vec<String>) -> Self {
        SampleOptions {
            law: Some(law.to_string()),
            data,
            reading: ReadOptions::default(),
            ..Default::default()
        }
    }

    fn sampler(&self) -> Sampler {
        match self.sampler {
            SamplerKind::Ensemble => {
                let mut s = EnsembleSettings::default();
                s.draws = self.draws.unwrap_or(s.draws);
                s.tune = self.tune.unwrap_or(s.tune);
                s.ensembles = self.parallel.unwrap_or(s.ensembles);
                Sampler::Ensemble(s)
            }
            SamplerKind::Demc => {
                let mut s = DemcSettings::default();
                s.draws = self.draws.unwrap_or(s.draws);
                s.tune = self.tune.unwrap_or(s.tune);
                s.populations = self.parallel.unwrap_or(s.populations);
                Sampler::Demc(s)
            }
            SamplerKind::Nuts => {
                let mut s = NutsSettings::default();
                s.draws = self.draws.unwrap_or(s.draws);
                s.tune = self.tune.unwrap_or(s.tune);
                s.chains = self.parallel.unwrap_or(s.chains);
                Sampler::Nuts(s)
            }
        }
    }

    /// The cap of the draws per chain: `max_draws`, else 16 x the first run's.
    fn max_draws(&self, draws: usize) -> usize {
        self.max_draws.unwrap_or(draws.saturating_mul(16))
    }

    fn law(&self) -> anyhow::Result<Law> {
        let text = self.law.as_deref().ok_or_else(|| {
            anyhow::anyhow!("--law: give the material law (e.g. --law neo-hookean)")
        })?;
        text.parse()
            .map_err(|e| anyhow::anyhow!("--law {text}: {e}"))
    }
}

/// The stored draws (units x chains per unit x draws, `dim` numbers each)
/// must fit in memory and the iteration count in a counter, checked before
/// anything is allocated; `dim` is an upper bound of the sampled dimension.
fn check_sizes(o: &SampleOptions, sampler: &Sampler, dim: usize) -> anyhow::Result<()> {
    let (units, per_unit, tune, draws, thin) = match sampler {
        Sampler::Ensemble(s) => (
            s.ensembles,
            if s.walkers == 0 {
                (4 * dim).max(16)
            } else {
                s.walkers
            },
            s.tune,
            s.draws,
            s.thin,
        ),
        Sampler::Demc(s) => (s.populations, s.chains, s.tune, s.draws, s.thin),
        Sampler::Nuts(s) => (s.chains, 1, s.tune, s.draws, 1),
    };
    anyhow::ensure!(
        draws >= 4,
        "--draws {draws}: at least 4 draws per chain are needed for the diagnostics"
    );
    anyhow::ensure!(
        units >= 1 && per_unit >= 1,
        "--parallel {units}: at least 1 parallel unit is needed"
    );
    let what = format!(
        "--draws {draws} x --parallel {units} ({} chains each)",
        per_unit
    );
    crate::run::limits::check_count(
        &what,
        draws as f64 * units as f64 * per_unit as f64,
        "stored draws",
        8.0 * (dim as f64 + 2.0),
    )?;
    let cap = o.max_draws(draws);
    anyhow::ensure!(
        cap >= draws,
        "--max-draws {cap}: below the {draws} draws per chain of the first run (--draws)"
    );
    crate::run::limits::check_count(
        &format!("--max-draws {cap} x --parallel {units} ({per_unit} chains each)"),
        cap as f64 * units as f64 * per_unit as f64,
        "stored draws",
        8.0 * (dim as f64 + 2.0),
    )?;
    let iterations = units as f64 * (tune as f64 + cap as f64 * thin as f64);
    anyhow::ensure!(
        iterations <= 2f64.powi(53),
        "--tune {} / --draws {} (--max-draws {cap}): {iterations:.3e} iterations, more than can be counted (2^53)",
        o.tune.unwrap_or(tune),
        draws
    );
    Ok(())
}

/// The records and the model they are sampled with.
enum Records {
    /// Homogeneous tests or C1 records, each with its test's model of `law`.
    Law(Law, Vec<TestData>),
    /// The record of an FE benchmark (N1, N3, Q1).
    Fe(&'static str, TestData),
    /// The force record of an experiment.
    Experiment(ExperimentSpec, TestData),
}

/// Checked options and the records read: what [`run`] samples.
pub struct Prepared {
    options: SampleOptions,
    sampler: Sampler,
    records: Records,
}

impl Prepared {
    /// The files the records were read from (for a caller's check that no
    /// output overwrites one).
    pub fn files(&self) -> Vec<&Path> {
        match &self.records {
            Records::Law(_, data) => data.iter().map(|d| Path::new(&d.file)).collect(),
            Records::Fe(_, d) | Records::Experiment(_, d) => vec![Path::new(&d.file)],
        }
    }
}

/// Checks the options (sizes, options of another record kind, the noise
/// SD) and reads the records, `<array:K>` taking `arrays[K]`
/// ([`crate::records::arrays`]).
pub fn prepare(options: &SampleOptions, arrays: &[ArrayRecord]) -> anyhow::Result<Prepared> {
    let o = options;
    let experiment = o
        .experiment
        .as_deref()
        .map(ExperimentSpec::from_option)
        .transpose()?;
    let law = match &experiment {
        Some(_) => None,
        None => Some(o.law()?),
    };
    let sampler = o.sampler();
    let dim = match (&experiment, law) {
        (Some(e), _) => e
            .experiment
            .param_space()
            .map_err(|err| anyhow::anyhow!("{}: {err}", e.source))?
            .len(),
        (None, Some(l)) => l.params().len(),
        (None, None) => 0,
    };
    check_sizes(o, &sampler, dim + 2 * o.data.len())?;
    fe::check_options(o)?;
    if let Some(s) = o.sigma {
        anyhow::ensure!(
            s.is_finite() && s > 0.0,
            "--sigma {s}: must be a positive number"
        );
    }
    let records = if let Some(spec) = experiment {
        anyhow::ensure!(
            !o.ar1,
            "--ar1: the surrogate's error variance is added to independent noise only; leave out --ar1 with --experiment"
        );
        anyhow::ensure!(
            o.data.len() == 1,
            "--experiment: give one record (--data FILE), got {}",
            o.data.len()
        );
        let data = super::diagnose::read_force_record(&o.data[0], arrays)?;
        Records::Experiment(spec, data)
    } else if let Some(kind) = fe_benchmark(o.benchmark.as_deref()) {
        anyhow::ensure!(
            !o.ar1,
            "--ar1: the surrogate's error variance is added to independent noise only; leave out --ar1 with --benchmark {kind}"
        );
        Records::Fe(kind, fe::read_record(kind, &o.data, arrays)?)
    } else {
        let data = crate::records::data_option::read_data_opts(
            &o.data,
            o.benchmark.as_deref(),
            arrays,
            &o.reading,
        )?;
        let law = law.ok_or_else(|| {
            anyhow::anyhow!("--law: give the material law (e.g. --law neo-hookean)")
        })?;
        Records::Law(law, data)
    };
    Ok(Prepared {
        options: o.clone(),
        sampler,
        records,
    })
}

/// A posterior sampled: the draws, their diagnostics and the report.
pub struct Sampled {
    /// The sampled parameters (the law's, then the noise parameters).
    pub names: Vec<String>,
    /// Every draw in physical units (chain-major: `values[(c * n_draws +
    /// d) * dim + k]` is parameter k of draw d of chain c).
    pub chains: Chains,
    /// Per parameter: mean, sd, HDI, R-hat, ESS.
    pub summary: Vec<ParamSummary>,
    /// The Laplace approximation's mean and SD per parameter.
    pub laplace_mean: Vec<f64>,
    pub laplace_sd: Vec<f64>,
    /// The posterior correlation matrix.
    pub correlation: Vec<Vec<f64>>,
    /// Whether every R-hat < 1.01 and bulk ESS >= 400 within the cap.
    pub converged: bool,
    /// The summary as `palpate sample --json` writes it.
    pub report: Value,
    /// The summary as the command line prints it (the table, the AR(1)
    /// coefficients, the correlation, the log evidence).
    pub table: String,
    /// Warnings the command line prints after the table (not converged,
    /// a posterior truncated by the surrogate's box).
    pub warnings: Vec<String>,
    /// The posterior sampled (for plots: [`crate::report::posterior_plots`]).
    pub posterior: Posterior,
    /// The Laplace approximation's mode (unbounded coordinates) and its
    /// estimate of the log evidence.
    pub laplace_mode: Vec<f64>,
    pub laplace_log_evidence: f64,
    /// The seed of the random streams.
    pub seed: u64,
}

/// [`prepare`], [`run`] and, when `options.evidence`, [`add_evidence`].
pub fn sample(
    options: &SampleOptions,
    arrays: &[ArrayRecord],
    observer: &dyn Observer,
) -> anyhow::Result<Sampled> {
    let mut s = run(prepare(options, arrays)?, observer)?;
    if options.evidence {
        add_evidence(&mut s, observer)?;
    }
    Ok(s)
}

/// The noise model of a data set: the SD known or inferred (half-normal
/// with the record's peak as scale), independent or AR(1).
fn noise_of(o: &SampleOptions, observed: &[f64]) -> NoiseModel {
    let peak = observed
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-12);
    NoiseModel {
        sd: match o.sigma {
            Some(s) => NoiseSd::Known(s),
            None => NoiseSd::Inferred(Prior::HalfNormal { sd: peak }),
        },
        correlation: if o.ar1 {
            Correlation::Ar1Inferred(Prior::Uniform {
                lower: -1.0,
                upper: 1.0,
            })
        } else {
            Correlation::Independent
        },
    }
}

/// The priors of `--prior NAME=SPEC`, flat for the others.
fn priors(o: &SampleOptions, space: &palpate_core::ParamSpace) -> anyhow::Result<Vec<Prior>> {
    let mut priors = vec![Prior::Flat; space.len()];
    for (i, p) in o.priors.iter().enumerate() {
        let (name, spec) =
            crate::records::data_option::split_pair(p, "NAME=SPEC, e.g. C10=lognormal:-7,1")
                .map_err(|_| {
                    anyhow::anyhow!(
                        "--prior {p}: expected NAME=SPEC, e.g. C10=lognormal:-7,1 (SPEC: flat, uniform:L,U, normal:M,S, lognormal:MU,SIGMA, halfnormal:S or loguniform:L,U)"
                    )
                })?;
        if o.priors[..i]
            .iter()
            .any(|q| q.split_once('=').map(|x| x.0) == Some(name))
        {
            anyhow::bail!(
                "--prior {p}: a prior for {name} is given twice; give each parameter one prior"
            );
        }
        let k = space.index_of(name).ok_or_else(|| {
            anyhow::anyhow!(
                "--prior {p}: unknown parameter `{name}` (the law has {})",
                space.names().join(", ")
            )
        })?;
        let prior: Prior = spec
            .parse()
            .map_err(|e| anyhow::anyhow!("--prior {p}: {e}"))?;
        // The prior must give the parameter's own range some mass.
        let (lo, hi) = prior.support();
        let b = &space.params[k];
        if lo.max(b.lower) >= hi.min(b.upper) {
            anyhow::bail!(
                "--prior {p}: the prior lives on [{lo}, {hi}], outside the range of {name}, ({}, {}) {}: no value of {name} would be possible",
                b.lower,
                b.upper,
                b.unit
            );
        }
        priors[k] = prior;
    }
    Ok(priors)
}

/// Samples the posterior of the prepared records: the FE surrogate built
/// or loaded first (N1, N3, Q1, an experiment), the chains started from
/// the least-squares fit's Laplace approximation and extended until
/// converged or capped. The evidence, if asked, is [`add_evidence`]'s.
pub fn run(prepared: Prepared, observer: &dyn Observer) -> anyhow::Result<Sampled> {
    let Prepared {
        options: o,
        sampler,
        records,
    } = prepared;
    let (sets, fe) = match records {
        Records::Law(law, data) => {
            let sets: Vec<DataSet> = data
                .iter()
                .map(|t| -> anyhow::Result<DataSet> {
                    Ok(DataSet {
                        name: t.name.clone(),
                        model: crate::model::test_model(t.test, law)?,
                        loading: t.loading.clone(),
                        observed: t.observed.clone(),
                        noise: noise_of(&o, &t.observed),
                    })
                })
                .collect::<anyhow::Result<_>>()?;
            (sets, None)
        }
        Records::Fe(kind, data) => {
            let spec = fe::model_spec(kind, &o)?;
            let fe = fe::surrogate(data, spec, &o, observer)?;
            let set = DataSet {
                name: kind.to_string(),
                model: fe.surrogate.clone(),
                loading: fe.data.loading.clone(),
                observed: fe.data.observed.clone(),
                noise: noise_of(&o, &fe.data.observed),
            };
            (vec![set], Some(fe))
        }
        Records::Experiment(spec, data) => {
            let spec = crate::steps::diagnose::experiment_base(spec, None, &data)?;
            let fe = fe::surrogate(data, spec, &o, observer)?;
            let set = DataSet {
                name: "force".to_string(),
                model: fe.surrogate.clone(),
                loading: fe.data.loading.clone(),
                observed: fe.data.observed.clone(),
                noise: noise_of(&o, &fe.data.observed),
            };
            (vec![set], Some(fe))
        }
    };
    let space = sets[0].model.space().clone();
    let priors = priors(&o, &space)?;
    let mut post = Posterior::new(sets, priors)?;
    if let Some(fe) = &fe {
        post = post.with_model_error(0, fe.surrogate.error_variance(0))?;
    }
    anyhow::ensure!(
        !o.evidence || post.priors_proper(),
        "--evidence needs a proper prior on every parameter (give --prior NAME=SPEC for each law parameter)"
    );
    let names = post.names();

    observer.message("least-squares fit and Laplace approximation ...");
    let start = fit_and_laplace(&post).context("finding the start of the chains")?;
    let (lap_mean, lap_sd) = start.laplace_physical(&post);

    let first_draws = palpate_uq::mcmc::converge::draws_of(&sampler);
    let convergence = Convergence {
        max_draws: o.max_draws(first_draws),
        ..Default::default()
    };
    let label = o.sampler.name();
    let bar = std::sync::RwLock::new(None::<crate::run::limits::Progress>);
    let template = "{msg} [{bar:40}] {pos}/{len} iterations ({eta})";
    let tick = |n: u64| {
        if let Ok(b) = bar.read() {
            if let Some(b) = b.as_ref() {
                b.inc(n);
            }
        }
    };
    let show = observer.bars();
    let to_physical = |z: &[f64]| post.space().from_unbounded(z);
    let converged = sample_until_converged(
        &sampler,
        &post,
        &start.start,
        o.seed,
        &convergence,
        &to_physical,
        Some(&tick),
        &mut |total| {
            if let Ok(mut b) = bar.write() {
                if let Some(old) = b.take() {
                    old.finish();
                }
                if show {
                    *b = Some(crate::run::limits::Progress::new(total, label, template));
                }
            }
        },
        &mut |w, next| {
            observer.message(&format!(
                "{label}: after {} draws per chain max R-hat = {:.4} ({}), min bulk ESS = {:.0} ({}): not yet R-hat < {} and ESS >= {}; extending to {next} draws per chain (cap {}, --max-draws)",
                w.draws,
                w.rhat_max,
                names[w.rhat_param],
                w.ess_bulk_min,
                names[w.ess_param],
                convergence.rhat_below,
                convergence.ess_bulk_at_least,
                convergence.max_draws
            ));
        },
    )?;
    if let Ok(mut b) = bar.write() {
        if let Some(old) = b.take() {
            old.finish();
        }
    }
    let run = &converged.run;
    let x = run.chains.map(|z| post.space().from_unbounded(z));
    let summary = summarize(&x, &names);
    let corr = correlation(&x);

    let table = report::table(&report::TableInput {
        options: &o,
        post: &post,
        converged: &converged,
        chains: &x,
        summary: &summary,
        correlation: &corr,
        laplace_mean: &lap_mean,
        laplace_sd: &lap_sd,
    });
    let mut warnings = Vec::new();
    let w = &converged.worst;
    if !converged.converged {
        warnings.push(format!(
            "warning: not converged at the cap of {} draws per chain: max R-hat = {:.4} ({}), min bulk ESS = {:.0} ({}), wanted R-hat < {} and ESS >= {}; do not trust the summary yet: raise --max-draws (or try another --sampler)",
            convergence.max_draws,
            w.rhat_max,
            names[w.rhat_param],
            w.ess_bulk_min,
            names[w.ess_param],
            convergence.rhat_below,
            convergence.ess_bulk_at_least
        ));
    }
    if let Some(fe) = &fe {
        let cut = fe::truncated(fe.surrogate.bounds(), &summary);
        if !cut.is_empty() {
            warnings.push(format!(
                "warning: the posterior of {} reaches the edge of the surrogate's box (--box): the box truncates it; widen --box for those parameters",
                cut.join(", ")
            ));
        }
    }

    let mut v = report::json(&o, &post, run, &summary, &corr, &lap_mean, &lap_sd, &start);
    v["evaluations"] = json!(converged.evaluations);
    v["wall_time_s"] = json!(converged.wall_time_s);
    v["convergence"] = json!({
        "converged": converged.converged,
        "rhat_max": w.rhat_max,
        "ess_bulk_min": w.ess_bulk_min,
        "rhat_below": convergence.rhat_below,
        "ess_bulk_at_least": convergence.ess_bulk_at_least,
        "max_draws": convergence.max_draws,
        "draws_tried": converged.history.iter().map(|h| h.draws).collect::<Vec<_>>(),
    });
    if let Some(fe) = &fe {
        v["surrogate"] = fe::report(fe, &summary);
    }
    Ok(Sampled {
        names,
        chains: x,
        summary,
        laplace_mean: lap_mean,
        laplace_sd: lap_sd,
        correlation: corr,
        converged: converged.converged,
        report: v,
        table,
        warnings,
        posterior: post,
        laplace_mode: start.laplace.mode.clone(),
        laplace_log_evidence: start.laplace.log_evidence,
        seed: o.seed,
    })
}

/// The evidence by thermodynamic integration (20 rungs of DE-MCz from the
/// Laplace mode), added to the report (`thermodynamic_integration`) and
/// the table; returns the table's line. [`sample`] calls it when the
/// options ask for the evidence; a caller of [`run`] calls it itself
/// (after printing the table and warnings, as the command line does).
pub fn add_evidence(s: &mut Sampled, observer: &dyn Observer) -> anyhow::Result<String> {
    observer.message("thermodynamic integration (20 rungs) ...");
    let sampler = Sampler::Demc(DemcSettings {
        tune: 500,
        draws: 1500,
        ..Default::default()
    });
    let ti = thermodynamic_integration(&s.posterior, &s.laplace_mode, 20, &sampler, s.seed)?;
    let line = format!(
        "log evidence: thermodynamic integration {:.3}, Laplace {:.3}\n",
        ti.log_evidence, s.laplace_log_evidence
    );
    s.table.push_str(&line);
    s.report["thermodynamic_integration"] = json!({
        "log_evidence": ti.log_evidence,
        "rungs": ti.betas.len() - 1,
        "evaluations": ti.evaluations,
    });
    Ok(line)
}

#[cfg(test)]
mod tests;
