//! `palpate sample`: the Bayesian posterior of a law's parameters by MCMC,
//! with diagnostics, a Laplace approximation beside it, chains, a corner plot
//! and posterior-predictive bands. The sampling is [`crate::api::sample`];
//! this module reads the options into [`SampleOptions`], prints the table
//! and writes the outputs (`--hierarchical`: the replicates' population,
//! [`crate::steps::replicates::hierarchical`]).

use crate::api::{self, sample::SampleOptions};
use crate::cli::calibrate::read_data_opts;
use crate::run::output::{write_atomic, write_json};
use serde_json::json;
use std::path::PathBuf;

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

/// Runs `palpate sample`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.hierarchical {
        return hierarchical(&args);
    }
    draw(&args)
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
    let law = super::parse_law(args.law.as_deref())?;
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

/// The options of `palpate sample` as the library API takes them
/// ([`crate::api::sample::SampleOptions`]).
pub fn options(args: &Args) -> anyhow::Result<SampleOptions> {
    Ok(SampleOptions {
        law: args.law.clone(),
        experiment: args.experiment.clone(),
        benchmark: args.benchmark.clone(),
        data: args.data.clone(),
        reading: args.reading.defaults()?,
        boxes: args.boxes.clone(),
        mesh: args.mesh.clone(),
        bulk: args.bulk.clone(),
        friction: args.friction,
        prony: args.prony.clone(),
        edge_radius: args.edge_radius,
        design: args.design,
        holdout: args.holdout,
        cache: args.cache.clone(),
        sampler: args.sampler.parse()?,
        draws: args.draws,
        max_draws: args.max_draws,
        tune: args.tune,
        parallel: args.chains,
        seed: args.seed,
        sigma: args.sigma,
        ar1: args.ar1,
        priors: args.prior.clone(),
        evidence: args.evidence,
    })
}

/// Samples ([`crate::api::sample`]), prints the table and the warnings, and
/// writes the outputs asked for (checked against the records first).
fn draw(args: &Args) -> anyhow::Result<()> {
    let prepared = api::sample::prepare(&options(args)?, &[])?;
    let outputs =
        crate::run::output::given(&[("--json", &args.json), ("--chains", &args.chains_out)]);
    let output_dirs = crate::run::output::given(&[("--plot", &args.plot)]);
    crate::run::output::check_outputs_and_dirs(&prepared.files(), &outputs, &output_dirs)?;
    let mut s = api::sample::run(prepared, &api::Stderr)?;
    print!("{}", s.table);
    for w in &s.warnings {
        eprintln!("{w}");
    }
    if args.evidence {
        print!("{}", api::sample::add_evidence(&mut s, &api::Stderr)?);
    }
    if let Some(path) = &args.json {
        write_json(path, &s.report)?;
        eprintln!("wrote {}", path.display());
    }
    let x = &s.chains;
    if let Some(path) = &args.chains_out {
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            write_json(
                path,
                &json!({ "names": s.names, "n_chains": x.n_chains, "n_draws": x.n_draws, "values": x.values }),
            )?;
        } else {
            write_atomic(path, x.to_csv(&s.names).as_bytes())?;
        }
        eprintln!("wrote {}", path.display());
    }
    if let Some(dir) = &args.plot {
        for (file, svg) in crate::report::posterior_plots(&s.posterior, x, args.seed)? {
            write_atomic(&dir.join(file), svg.as_bytes())?;
        }
        eprintln!("wrote plots into {}", dir.display());
    }
    Ok(())
}

#[cfg(test)]
#[path = "sample_tests.rs"]
mod tests;
