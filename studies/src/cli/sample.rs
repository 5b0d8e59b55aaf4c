//! `palpate sample`: the Bayesian posterior of a law's parameters by MCMC,
//! with diagnostics, a Laplace approximation beside it, chains, a corner plot
//! and posterior-predictive bands. The draws are extended until converged
//! (`palpate_uq::mcmc::sample_until_converged`); finite-element benchmarks
//! are sampled through a cached surrogate ([`super::sample_fe`]).

use crate::cli::calibrate::read_data_opts;
use crate::run::output::{write_atomic, write_json};
use anyhow::Context;
use palpate_material::Law;
use palpate_uq::likelihood::{
    fit_and_laplace, thermodynamic_integration, Correlation, DataSet, NoiseModel, NoiseSd,
    Posterior, Prior,
};
use palpate_uq::mcmc::{
    correlation, sample_until_converged, summarize, Chains, Convergence, DemcSettings,
    EnsembleSettings, NutsSettings, SampleRun, Sampler,
};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// Sample the Bayesian posterior of a law's parameters by MCMC, with diagnostics
///
/// Data as for `palpate calibrate`: `--data TEST=FILE` for homogeneous tests
/// (TEST = uniaxial, biaxial, planar; columns stretch,stress_MPa) or
/// `--benchmark C1 --data FILE` (columns displacement_mm,force_N).
///
/// Finite-element benchmarks, `--benchmark N1|N3|Q1 --data FILE` (columns
/// displacement_mm,force_N; Q1 also time_s), are sampled through a surrogate
/// of the FE model (reduced basis + Gaussian processes) trained once on a
/// Halton design of FE runs inside --box (required for every law parameter:
/// the posterior's support) on the record's own loading history, and cached
/// (--cache) under a hash of the model, mesh, code version, record, box and
/// design, so a second run reuses it. Its error on held-out FE runs is
/// printed and added to the likelihood as a variance per sample. The FE model
/// is the docs/benchmarks.md set-up on the coarse mesh unless --mesh.
/// A lab's own experiment (--experiment FILE, docs/guide/experiment.md) is
/// sampled the same way, its model the description's (meshed for the
/// record's deepest displacement when its protocol is the record's).
///
/// Convergence: the draws per chain are doubled (the run repeated from the
/// same seed and continued) until every R-hat < 1.01 and every bulk ESS >=
/// 400, up to --max-draws; a line on stderr reports each extension, and a
/// warning says so when the cap is reached before convergence.
///
/// Likelihood: Gaussian; the noise SD of each data set is inferred (prior
/// half-normal with scale = the set's peak |observation|) unless --sigma is
/// given; --ar1 adds an AR(1) residual correlation per data set. Priors on
/// the law's parameters are flat inside its bounds unless --prior is given.
/// The chains start from the least-squares fit's Laplace approximation.
///
/// Example: palpate sample --benchmark C1 --law reduced-polynomial:2 --data c1.csv --sampler nuts --json post.json --plot figs
/// Example: palpate sample --benchmark N1 --law neo-hookean --data n1.csv --box C10=0.0005,0.002 --json post.json
/// Example: palpate sample --experiment gel-disc.toml --data force=indent.csv --box C10=0.001,0.01 --json post.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// Material law: neo-hookean, mooney-rivlin, reduced-polynomial:N, yeoh, arruda-boyce, ogden:N,
    /// gent, veronda-westmann, humphrey. Not with --experiment, whose description names its laws.
    #[arg(
        long,
        required_unless_present = "experiment",
        conflicts_with = "experiment"
    )]
    pub law: Option<String>,
    /// Data: TEST=FILE for homogeneous tests, or FILE with --benchmark C1. Repeatable.
    #[arg(long = "data", required = true, value_name = "TEST=FILE")]
    pub data: Vec<String>,
    #[command(flatten)]
    pub reading: crate::cli::reading::ReadingArgs,
    /// Benchmark whose force record the data are: C1 (analytic), or N1, N3, Q1 (finite elements, through a surrogate).
    #[arg(long, value_name = "ID", conflicts_with = "experiment")]
    pub benchmark: Option<String>,
    /// A lab's own experiment (an experiment file, a preset's name or the description as JSON): its FE model, sampled through a surrogate as the FE benchmarks are (--box for each of its parameters; --design, --holdout, --cache apply; the model's settings are the description's).
    #[arg(long, value_name = "FILE|PRESET")]
    pub experiment: Option<String>,
    /// N1, N3, Q1: the box the surrogate is trained in and the posterior lives in, NAME=LO,HI for every law parameter (physical units). Repeatable.
    #[arg(long = "box", value_name = "NAME=LO,HI")]
    pub boxes: Vec<String>,
    /// N1, N3, Q1: mesh of the FE model: coarse, medium, fine or a level N [default: coarse].
    #[arg(long)]
    pub mesh: Option<String>,
    /// N1, N3, Q1: incompressibility, exact or a ratio K/mu [default: exact].
    #[arg(long)]
    pub bulk: Option<String>,
    /// N1, N3: Coulomb friction between needle and material [default: 0.8].
    #[arg(long)]
    pub friction: Option<f64>,
    /// Q1: the Prony series g1=..,tau1=.. held fixed (the law's parameters are sampled).
    #[arg(long, value_name = "g1=..,tau1=..")]
    pub prony: Option<String>,
    /// Q1: radius of the punch's rounded edge, mm [default: 0.2; as palpate simulate --edge-radius].
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub edge_radius: Option<f64>,
    /// N1, N3, Q1: FE runs of the surrogate's training design [default: max(30, 15 x parameters)].
    #[arg(long, value_name = "N")]
    pub design: Option<usize>,
    /// N1, N3, Q1: held-out FE runs measuring the surrogate's error [default: max(8, 3 x parameters)].
    #[arg(long, value_name = "N")]
    pub holdout: Option<usize>,
    /// N1, N3, Q1: folder of cached surrogates [default: $PALPATE_CACHE, else $XDG_CACHE_HOME/palpate/surrogates, else ~/.cache/palpate/surrogates].
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Sampler: ensemble (affine-invariant stretch move), demc (DE-MCz) or nuts.
    #[arg(long, default_value = "nuts")]
    pub sampler: String,
    /// Stored draws per chain of the first run (default: ensemble 2000 per walker, demc 5000, nuts 1000); doubled until converged.
    #[arg(long, value_parser = crate::run::limits::parse_count::<usize>)]
    pub draws: Option<usize>,
    /// Cap of the stored draws per chain when extending until R-hat < 1.01 and bulk ESS >= 400 [default: 16 x --draws]; equal to --draws: no extension.
    #[arg(long, value_name = "N", value_parser = crate::run::limits::parse_count::<usize>)]
    pub max_draws: Option<usize>,
    /// Warm-up iterations (default: ensemble 1000, demc 2000, nuts 1000).
    #[arg(long, value_parser = crate::run::limits::parse_count::<usize>)]
    pub tune: Option<usize>,
    /// Parallel units: NUTS chains (4), ensembles (2) or DE-MCz populations (2).
    #[arg(long = "parallel", value_parser = crate::run::limits::parse_count::<usize>)]
    pub chains: Option<usize>,
    /// Seed of the random streams (results are identical for a seed whatever the thread count).
    #[arg(long, default_value_t = 0, value_parser = crate::run::limits::parse_count::<u64>)]
    pub seed: u64,
    /// Known noise SD of every data set (observable unit: N or MPa); inferred when absent.
    #[arg(long)]
    pub sigma: Option<f64>,
    /// Infer an AR(1) correlation of successive residuals per data set (uniform prior on (-1, 1)).
    #[arg(long)]
    pub ar1: bool,
    /// Prior of a parameter: NAME=flat|uniform:L,U|normal:M,S|lognormal:MU,SIGMA|halfnormal:S|loguniform:L,U. Repeatable.
    #[arg(long = "prior", value_name = "NAME=SPEC")]
    pub prior: Vec<String>,
    /// Write the summary as JSON (params by name: mean, sd, hdi_3, hdi_97, rhat, ess_bulk, ess_tail, mcse_mean).
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Write every draw (physical units): OUT.csv with columns chain,draw,<params>,
    /// or OUT.json with names, n_chains, n_draws and values (chain-major).
    #[arg(long = "chains", value_name = "OUT.csv|OUT.json")]
    pub chains_out: Option<PathBuf>,
    /// Also estimate the evidence by thermodynamic integration (20 rungs of
    /// DE-MCz; needs --prior on every law parameter).
    #[arg(long)]
    pub evidence: bool,
    /// Write corner.svg and predictive_<data>.svg into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// The --data files are replicates of one material (a FILE with wildcards,
    /// or several --data): sample the hierarchical posterior of each
    /// parameter, its population mean and between-test SD, from each
    /// record's own fit (NUTS until R-hat < 1.01; --seed, --max-draws and
    /// --json apply).
    #[arg(long)]
    pub hierarchical: bool,
}

fn sampler_from(args: &Args) -> anyhow::Result<Sampler> {
    Ok(match args.sampler.to_ascii_lowercase().as_str() {
        "ensemble" | "emcee" | "stretch" => {
            let mut s = EnsembleSettings::default();
            s.draws = args.draws.unwrap_or(s.draws);
            s.tune = args.tune.unwrap_or(s.tune);
            s.ensembles = args.chains.unwrap_or(s.ensembles);
            Sampler::Ensemble(s)
        }
        "demc" | "de-mc" | "demcz" | "dream" => {
            let mut s = DemcSettings::default();
            s.draws = args.draws.unwrap_or(s.draws);
            s.tune = args.tune.unwrap_or(s.tune);
            s.populations = args.chains.unwrap_or(s.populations);
            Sampler::Demc(s)
        }
        "nuts" => {
            let mut s = NutsSettings::default();
            s.draws = args.draws.unwrap_or(s.draws);
            s.tune = args.tune.unwrap_or(s.tune);
            s.chains = args.chains.unwrap_or(s.chains);
            Sampler::Nuts(s)
        }
        other => anyhow::bail!("--sampler {other}: expected ensemble, demc or nuts"),
    })
}

/// The stored draws (units x chains per unit x draws, `dim` numbers each)
/// must fit in memory and the iteration count in a counter, checked before
/// anything is allocated; `dim` is an upper bound of the sampled dimension.
fn check_sizes(args: &Args, sampler: &Sampler, dim: usize) -> anyhow::Result<()> {
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
    let cap = max_draws(args, draws);
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
        args.tune.unwrap_or(tune),
        draws
    );
    Ok(())
}

/// The parsed `--law`.
fn law_of(args: &Args) -> anyhow::Result<Law> {
    super::parse_law(args.law.as_deref())
}

/// The cap of the draws per chain: --max-draws, else 16 x the first run's.
fn max_draws(args: &Args, draws: usize) -> usize {
    args.max_draws.unwrap_or(draws.saturating_mul(16))
}

/// The outcome of `palpate sample`: what `--chains OUT.json` and `--json`
/// write, held in memory.
#[derive(Debug, Clone)]
pub struct Sampled {
    /// The sampled parameters (the law's, then the noise parameters).
    pub names: Vec<String>,
    /// Every draw in physical units (chain-major: `values[(c * n_draws +
    /// d) * dim + k]` is parameter k of draw d of chain c).
    pub chains: Chains,
    /// The summary `--json` writes.
    pub summary: Value,
}

/// Runs `palpate sample`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.hierarchical {
        return hierarchical(&args);
    }
    draw(&args, &[]).map(|_| ())
}

/// `palpate sample --hierarchical`: the population of replicates.
fn hierarchical(args: &Args) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.benchmark.is_none() && args.sigma.is_none() && !args.ar1 && args.prior.is_empty() && !args.evidence,
        "--hierarchical: the records' own fits make the test level; not with --benchmark, --sigma, --ar1, --prior or --evidence"
    );
    anyhow::ensure!(
        args.experiment.is_none(),
        "--hierarchical: not with --experiment (the records' own fits are those of a law)"
    );
    let law = law_of(args)?;
    let records = read_data_opts(&args.data, None, &[], &args.reading.defaults()?)?;
    anyhow::ensure!(
        records.len() >= 2,
        "--hierarchical: {} record; give replicates (a --data FILE with wildcards, or several --data)",
        records.len()
    );
    let cap = args.max_draws.unwrap_or(16_000);
    let (reps, post) = crate::steps::replicates::hierarchical(law, &records, args.seed, cap)?;
    print!("{}", reps.table());
    print!(
        "{}",
        crate::steps::replicates::hierarchical_table(law, &post)
    );
    if let Some(p) = &args.json {
        write_json(
            p,
            &json!({ "law": law.to_string(), "replicates": reps, "hierarchical": post }),
        )?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// Runs `palpate sample` (printing its table and writing the outputs it is
/// given) and returns the draws and the summary, for callers that want
/// them in memory (the Python package). `--data TEST=<array:K>` takes the
/// record `arrays[K]` ([`crate::records::arrays`]; not with the FE benchmarks N1,
/// N3, Q1, whose record is read from a file).
pub fn draw(
    args: &Args,
    arrays: &[crate::records::arrays::ArrayRecord],
) -> anyhow::Result<Sampled> {
    let experiment = args
        .experiment
        .as_deref()
        .map(crate::model::ExperimentSpec::from_option)
        .transpose()?;
    let law = match &experiment {
        Some(_) => None,
        None => Some(law_of(args)?),
    };
    let sampler = sampler_from(args)?;
    let dim = match (&experiment, law) {
        (Some(e), _) => e
            .experiment
            .param_space()
            .map_err(|err| anyhow::anyhow!("{}: {err}", e.source))?
            .len(),
        (None, Some(l)) => l.params().len(),
        (None, None) => 0,
    };
    check_sizes(args, &sampler, dim + 2 * args.data.len())?;
    super::sample_fe::check_options(args)?;
    let fe_kind = super::sample_fe::fe_benchmark(args.benchmark.as_deref());
    if let Some(s) = args.sigma {
        anyhow::ensure!(
            s.is_finite() && s > 0.0,
            "--sigma {s}: must be a positive number"
        );
    }
    let noise_of = |observed: &[f64]| {
        let peak = observed
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-12);
        NoiseModel {
            sd: match args.sigma {
                Some(s) => NoiseSd::Known(s),
                None => NoiseSd::Inferred(Prior::HalfNormal { sd: peak }),
            },
            correlation: if args.ar1 {
                Correlation::Ar1Inferred(Prior::Uniform {
                    lower: -1.0,
                    upper: 1.0,
                })
            } else {
                Correlation::Independent
            },
        }
    };
    let outputs =
        crate::run::output::given(&[("--json", &args.json), ("--chains", &args.chains_out)]);
    let output_dirs = crate::run::output::given(&[("--plot", &args.plot)]);
    let (sets, fe) = if let Some(spec) = experiment {
        anyhow::ensure!(
            arrays.is_empty(),
            "--experiment: the record is read from a file (--data FILE), not from arrays"
        );
        anyhow::ensure!(
            !args.ar1,
            "--ar1: the surrogate's error variance is added to independent noise only; leave out --ar1 with --experiment"
        );
        for d in &args.data {
            let p = d.split_once('=').map_or(d.as_str(), |x| x.1);
            crate::run::output::check_outputs_and_dirs(&[Path::new(p)], &outputs, &output_dirs)?;
        }
        let fe = super::sample_fe::setup_experiment(spec, args)?;
        let set = DataSet {
            name: "force".to_string(),
            model: fe.surrogate.clone(),
            loading: fe.data.loading.clone(),
            observed: fe.data.observed.clone(),
            noise: noise_of(&fe.data.observed),
        };
        (vec![set], Some(fe))
    } else if let Some(kind) = fe_kind {
        anyhow::ensure!(
            arrays.is_empty(),
            "--benchmark {kind}: the record is read from a file (--data FILE), not from arrays"
        );
        anyhow::ensure!(
            !args.ar1,
            "--ar1: the surrogate's error variance is added to independent noise only; leave out --ar1 with --benchmark {kind}"
        );
        for d in &args.data {
            let p = d.split_once('=').map_or(d.as_str(), |x| x.1);
            crate::run::output::check_outputs_and_dirs(&[Path::new(p)], &outputs, &output_dirs)?;
        }
        let fe = super::sample_fe::setup(kind, args)?;
        let set = DataSet {
            name: kind.to_string(),
            model: fe.surrogate.clone(),
            loading: fe.data.loading.clone(),
            observed: fe.data.observed.clone(),
            noise: noise_of(&fe.data.observed),
        };
        (vec![set], Some(fe))
    } else {
        let data = read_data_opts(
            &args.data,
            args.benchmark.as_deref(),
            arrays,
            &args.reading.defaults()?,
        )?;
        let inputs: Vec<&Path> = data.iter().map(|d| Path::new(&d.file)).collect();
        crate::run::output::check_outputs_and_dirs(&inputs, &outputs, &output_dirs)?;
        let sets: Vec<DataSet> = data
            .iter()
            .map(|t| -> anyhow::Result<DataSet> {
                Ok(DataSet {
                    name: t.name.clone(),
                    model: crate::model::test_model(t.test, law_of(args)?)?,
                    loading: t.loading.clone(),
                    observed: t.observed.clone(),
                    noise: noise_of(&t.observed),
                })
            })
            .collect::<anyhow::Result<_>>()?;
        (sets, None)
    };
    let space = sets[0].model.space().clone();
    let mut priors = vec![Prior::Flat; space.len()];
    for p in &args.prior {
        let (name, spec) =
            crate::cli::calibrate::split_pair(p, "NAME=SPEC, e.g. C10=lognormal:-7,1")
                .map_err(|_| {
                    anyhow::anyhow!(
                        "--prior {p}: expected NAME=SPEC, e.g. C10=lognormal:-7,1 (SPEC: flat, uniform:L,U, normal:M,S, lognormal:MU,SIGMA, halfnormal:S or loguniform:L,U)"
                    )
                })?;
        if args
            .prior
            .iter()
            .take_while(|q| !std::ptr::eq(*q, p))
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
    let mut post = Posterior::new(sets, priors)?;
    if let Some(fe) = &fe {
        post = post.with_model_error(0, fe.surrogate.error_variance(0))?;
    }
    anyhow::ensure!(
        !args.evidence || post.priors_proper(),
        "--evidence needs a proper prior on every parameter (give --prior NAME=SPEC for each law parameter)"
    );
    let names = post.names();

    eprintln!("least-squares fit and Laplace approximation ...");
    let start = fit_and_laplace(&post).context("finding the start of the chains")?;
    let (lap_mean, lap_sd) = start.laplace_physical(&post);

    let first_draws = palpate_uq::mcmc::converge::draws_of(&sampler);
    let convergence = Convergence {
        max_draws: max_draws(args, first_draws),
        ..Default::default()
    };
    let bar = std::sync::RwLock::new(None::<crate::run::limits::Progress>);
    let template = "{msg} [{bar:40}] {pos}/{len} iterations ({eta})";
    let tick = |n: u64| {
        if let Ok(b) = bar.read() {
            if let Some(b) = b.as_ref() {
                b.inc(n);
            }
        }
    };
    let to_physical = |z: &[f64]| post.space().from_unbounded(z);
    let converged = sample_until_converged(
        &sampler,
        &post,
        &start.start,
        args.seed,
        &convergence,
        &to_physical,
        Some(&tick),
        &mut |total| {
            if let Ok(mut b) = bar.write() {
                if let Some(old) = b.take() {
                    old.finish();
                }
                *b = Some(crate::run::limits::Progress::new(
                    total,
                    &args.sampler,
                    template,
                ));
            }
        },
        &mut |w, next| {
            eprintln!(
                "{}: after {} draws per chain max R-hat = {:.4} ({}), min bulk ESS = {:.0} ({}): not yet R-hat < {} and ESS >= {}; extending to {next} draws per chain (cap {}, --max-draws)",
                args.sampler,
                w.draws,
                w.rhat_max,
                names[w.rhat_param],
                w.ess_bulk_min,
                names[w.ess_param],
                convergence.rhat_below,
                convergence.ess_bulk_at_least,
                convergence.max_draws
            );
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

    println!(
        "{} on {} ({} chains x {} draws, {} evaluations, {:.2} s{})",
        run.sampler,
        post.datasets()[0].model.name(),
        x.n_chains,
        x.n_draws,
        converged.evaluations,
        converged.wall_time_s,
        if converged.history.len() > 1 {
            format!(", {} runs to converge", converged.history.len())
        } else {
            String::new()
        }
    );
    println!(
        "{:<10} {:>12} {:>11} {:>12} {:>12} {:>7} {:>8} {:>8} {:>12} {:>11}",
        "param",
        "mean",
        "sd",
        "hdi_3%",
        "hdi_97%",
        "r_hat",
        "ess_bulk",
        "ess_tail",
        "laplace",
        "laplace_sd"
    );
    for (k, s) in summary.iter().enumerate() {
        println!(
            "{:<10} {:>12.5e} {:>11.3e} {:>12.5e} {:>12.5e} {:>7.4} {:>8.0} {:>8.0} {:>12.5e} {:>11.3e}",
            s.name, s.mean, s.sd, s.hdi_3, s.hdi_97, s.rhat, s.ess_bulk, s.ess_tail, lap_mean[k], lap_sd[k]
        );
    }
    if args.ar1 {
        // The AR(1) coefficient of each data set: the correlation of
        // successive residuals, and the SD of the innovations it leaves.
        for (k, s) in summary.iter().enumerate() {
            let Some(set) = s.name.strip_prefix("phi") else {
                continue;
            };
            let set = set.strip_prefix('_').unwrap_or(&post.datasets()[0].name);
            let sigma = names
                .iter()
                .position(|n| n == &format!("sigma{}", &s.name[3..]))
                .map(|j| lap_mean[j])
                .or(args.sigma);
            // Near 1, the distance to 1 is what tells values apart.
            let shown = |v: f64| {
                if v > 0.999 {
                    format!("1 - {:.3e}", 1.0 - v)
                } else {
                    format!("{v:.4}")
                }
            };
            let phi = lap_mean[k];
            println!(
                "between-sample correlation of `{set}` (AR(1) phi): {} [{}, {}]{}",
                shown(s.mean),
                shown(s.hdi_3),
                shown(s.hdi_97),
                match sigma {
                    Some(sd) => format!(
                        "; innovation SD sigma sqrt(1 - phi^2) {} at the Laplace mode",
                        crate::steps::replicates::sig4(sd * (1.0 - phi * phi).max(0.0).sqrt())
                    ),
                    None => String::new(),
                }
            );
        }
    }
    if names.len() > 1 {
        println!("posterior correlation:");
        for (i, row) in corr.iter().enumerate() {
            let cells: Vec<String> = row.iter().map(|c| format!("{c:>7.3}")).collect();
            println!("  {:<10}{}", names[i], cells.join(" "));
        }
    }
    let w = &converged.worst;
    if !converged.converged {
        eprintln!(
            "warning: not converged at the cap of {} draws per chain: max R-hat = {:.4} ({}), min bulk ESS = {:.0} ({}), wanted R-hat < {} and ESS >= {}; do not trust the summary yet: raise --max-draws (or try another --sampler)",
            convergence.max_draws,
            w.rhat_max,
            names[w.rhat_param],
            w.ess_bulk_min,
            names[w.ess_param],
            convergence.rhat_below,
            convergence.ess_bulk_at_least
        );
    }
    if let Some(fe) = &fe {
        let cut = super::sample_fe::truncated(fe.surrogate.bounds(), &summary);
        if !cut.is_empty() {
            eprintln!(
                "warning: the posterior of {} reaches the edge of the surrogate's box (--box): the box truncates it; widen --box for those parameters",
                cut.join(", ")
            );
        }
    }

    let ti = if args.evidence {
        eprintln!("thermodynamic integration (20 rungs) ...");
        let s = Sampler::Demc(DemcSettings {
            tune: 500,
            draws: 1500,
            ..Default::default()
        });
        let ti = thermodynamic_integration(&post, &start.laplace.mode, 20, &s, args.seed)?;
        println!(
            "log evidence: thermodynamic integration {:.3}, Laplace {:.3}",
            ti.log_evidence, start.laplace.log_evidence
        );
        Some(ti)
    } else {
        None
    };
    let summary_json = {
        let mut v = report(
            args, &post, run, &summary, &corr, &lap_mean, &lap_sd, &start,
        );
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
            let s = &fe.surrogate;
            let val = s.validation();
            let b = s.bounds();
            v["surrogate"] = json!({
                "model": format!("{:?}", fe.spec),
                "fe_runs": s.fe_runs,
                "training_runs": s.options().training_runs,
                "held_out_runs": val.points,
                "failed_runs": s.failed.len(),
                "basis_size": s.basis_size(),
                "max_rel_error": val.max_relative_error,
                "rms_rel_error": val.rms_relative_error,
                "max_abs_error_N": val.max_abs_error.first(),
                "box": (0..b.len()).map(|k| json!({"name": b.names[k], "lower": b.lower[k], "upper": b.upper[k]})).collect::<Vec<_>>(),
                "box_truncates": super::sample_fe::truncated(b, &summary),
                "build_time_s": s.build_time_s,
                "build_cpu_s": s.build_cpu_s,
                "cache": fe.status.word(),
                "cache_file": fe.status.path().display().to_string(),
                "key": s.key(),
            });
        }
        if let Some(ti) = &ti {
            v["thermodynamic_integration"] = json!({
                "log_evidence": ti.log_evidence,
                "rungs": ti.betas.len() - 1,
                "evaluations": ti.evaluations,
            });
        }
        v
    };
    if let Some(path) = &args.json {
        write_json(path, &summary_json)?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.chains_out {
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            write_json(
                path,
                &json!({ "names": names, "n_chains": x.n_chains, "n_draws": x.n_draws, "values": x.values }),
            )?;
        } else {
            write_atomic(path, x.to_csv(&names).as_bytes())?;
        }
        eprintln!("wrote {}", path.display());
    }
    if let Some(dir) = &args.plot {
        plots(dir, &post, &x, args.seed)?;
        eprintln!("wrote plots into {}", dir.display());
    }
    Ok(Sampled {
        names,
        chains: x,
        summary: summary_json,
    })
}

#[allow(clippy::too_many_arguments)]
fn report(
    args: &Args,
    post: &Posterior,
    run: &SampleRun,
    summary: &[palpate_uq::mcmc::ParamSummary],
    corr: &[Vec<f64>],
    lap_mean: &[f64],
    lap_sd: &[f64],
    start: &palpate_uq::likelihood::PosteriorStart,
) -> Value {
    let mut params = Map::new();
    let x = run.chains.map(|z| post.space().from_unbounded(z));
    for (k, s) in summary.iter().enumerate() {
        let spec = &post.space().params[k];
        let iat = palpate_uq::mcmc::diagnostics::integrated_autocorrelation_time(&x.param(k));
        params.insert(
            s.name.clone(),
            json!({
                "unit": spec.unit,
                "prior": post.priors()[k].to_string(),
                "mean": s.mean, "sd": s.sd, "hdi_3": s.hdi_3, "hdi_97": s.hdi_97,
                "rhat": s.rhat, "ess_bulk": s.ess_bulk, "ess_tail": s.ess_tail, "mcse_mean": s.mcse_mean,
                "laplace_mean": lap_mean[k], "laplace_sd": lap_sd[k],
                "autocorrelation_time": iat,
            }),
        );
    }
    json!({
        "law": args.law,
        "experiment": args.experiment,
        "model": post.datasets()[0].model.name(),
        "data": args.data,
        "sampler": run.sampler,
        "seed": args.seed,
        "chains": run.chains.n_chains,
        "draws_per_chain": run.chains.n_draws,
        "params": params,
        "correlation": { "names": post.names(), "matrix": corr },
        "evaluations": run.evaluations,
        "wall_time_s": run.wall_time_s,
        "acceptance_mean": run.acceptance.iter().sum::<f64>() / run.acceptance.len().max(1) as f64,
        "acceptance": run.acceptance,
        "divergences": run.divergences,
        "step_size": run.step_size,
        "laplace": {
            "log_evidence": start.laplace.log_evidence,
            "evidence_meaningful": post.priors_proper(),
            "note": "Laplace estimate of log p(data); comparable between models only with proper priors on every parameter",
        },
        "least_squares": start.fit.parameters.iter().map(|p| json!({
            "name": p.name, "value": p.value, "standard_error": p.standard_error,
        })).collect::<Vec<_>>(),
    })
}

/// Writes the posterior's corner plot and predictive plots
/// ([`crate::report::posterior_plots`]) into `dir`.
fn plots(dir: &Path, post: &Posterior, x: &Chains, seed: u64) -> anyhow::Result<()> {
    for (file, svg) in crate::report::posterior_plots(post, x, seed)? {
        write_atomic(&dir.join(file), svg.as_bytes())?;
    }
    Ok(())
}

#[cfg(test)]
#[path = "sample_tests.rs"]
mod tests;
