//! `palpate localize --benchmark R2 --rd RD --data RECORD.csv`: the
//! posterior of each nodule's position and depth from a rolled force
//! record (`crate::apps::localize`), on a surrogate of the FE model trained once
//! per RD and cached on disk.

use std::path::PathBuf;

use clap::Parser;

use crate::api::{LocalizeOptions, Localized};
pub use crate::apps::localize::plot::plot_svg;
use crate::apps::localize::posterior::LocRun;
use crate::apps::localize::record::Record;
use crate::apps::localize::LocModel;
use crate::run::output::{check_outputs, given, write_atomic, write_json};
use crate::run::surrogate::default_cache_dir;

/// Locate nodules (x, depth, 94 % intervals) from an R2 rolled force record
///
/// The force along the rolled pass is modelled as s [F0(x) + sum over the
/// nodules of E(x - x_n; d_n, x_n)], with E from a surrogate of the FE model
/// (FE scans past one nodule at training depths, at the block's centre with
/// E assumed independent of x_n, or along the block with --scan along;
/// trained once per --rd and cached), the
/// tissue-modulus scale s free and the noise inferred; the posterior of each
/// nodule's position and depth is sampled by MCMC and reported with 94 %
/// credible intervals. The surrogate's held-out error is printed and added
/// to the likelihood.
///
/// Example: palpate localize --benchmark R2 --rd 6 --data r2.csv --nodules 3 --json loc.json --plot loc.svg
#[derive(Debug, Parser)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// The benchmark (R2: the rolled block of docs/benchmarks.md).
    #[arg(long, value_parser = ["R2", "r2"])]
    pub benchmark: String,
    /// Rolling depth of the record (mm); one surrogate per RD.
    #[arg(long, value_name = "RD")]
    pub rd: f64,
    /// The record: CSV with position_mm,force_N (as `palpate simulate --benchmark R2 --csv` writes).
    #[arg(long, value_name = "RECORD.csv")]
    pub data: PathBuf,
    /// Number of nodules to locate.
    #[arg(long, default_value_t = 3)]
    pub nodules: usize,
    /// Write the result as JSON.
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Plot the record, the fit and the nodules' posteriors (SVG).
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
    /// Write a Markdown report.
    #[arg(long, value_name = "OUT.md")]
    pub report: Option<PathBuf>,
    /// Write the posterior draws (CSV).
    #[arg(long, value_name = "OUT.csv")]
    pub draws: Option<PathBuf>,
    /// Surrogate cache folder (default: $PALPATE_CACHE or ~/.cache/palpate/surrogates).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Training FE scans of the surrogate (default 6 at the centre, 16
    /// along the block).
    #[arg(long)]
    pub design: Option<usize>,
    /// Held-out FE scans (default 2 at the centre, 4 along the block).
    #[arg(long)]
    pub holdout: Option<usize>,
    /// Random seed of the sampler.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// MCMC sampler: nuts (4 chains, default) or ensemble (the
    /// affine-invariant ensemble; slower to reach R-hat < 1.01 here).
    #[arg(long, default_value = "nuts", value_parser = ["nuts", "ensemble"])]
    pub sampler: String,
    /// The surrogate's scan: lean (default: the centre model with the
    /// excess shifted by the end lean measured on 16 short FE scans near
    /// the end, one shift per nodule position and depth), centre (depth
    /// only, one nodule at the block's centre, translation invariance
    /// assumed: shallow nodules near an end read towards it) or along
    /// (depth and position of the nodule, 20 FE scans instead of 8: removes
    /// most of that bias, but its surrogate error is larger). Coverage,
    /// bias and build times of the three: docs/validation/r2-localisation.md.
    #[arg(long, default_value = "lean", value_parser = ["lean", "centre", "along"])]
    pub scan: String,
}

/// Runs `palpate localize` ([`crate::api::localize`]).
pub fn run(a: Args) -> anyhow::Result<()> {
    let options = LocalizeOptions {
        rd: a.rd,
        scan: a.scan.parse()?,
        nodules: a.nodules,
        design: a.design,
        holdout: a.holdout,
        seed: a.seed,
        sampler: a
            .sampler
            .parse()
            .map_err(|e: String| anyhow::anyhow!("--sampler: {e}"))?,
        cache: a.cache.clone().unwrap_or_else(default_cache_dir),
    };
    if let Err((f, r)) = options.setup() {
        if f == "--nodules" {
            anyhow::bail!("--nodules {}: {r}", a.nodules);
        }
        anyhow::bail!("{f} {}: {r}", option_value(&f, &a));
    }
    check_outputs(
        &[a.data.as_path()],
        &given(&[
            ("--json", &a.json),
            ("--plot", &a.plot),
            ("--report", &a.report),
            ("--draws", &a.draws),
        ]),
    )?;
    let Localized {
        model,
        record,
        run,
        model_ready_s,
    } = crate::api::localize(&a.data, &options)?;
    report_model(&model, model_ready_s);
    let text = summary_text(&model, &record, &run);
    print!("{text}");
    if let Some(p) = &a.json {
        write_json(p, &run.result)?;
    }
    if let Some(p) = &a.draws {
        write_atomic(p, run.chains.to_csv(&run.names).as_bytes())?;
    }
    if let Some(p) = &a.plot {
        write_atomic(p, plot_svg(&model, &record, &run, None).as_bytes())?;
    }
    if let Some(p) = &a.report {
        write_atomic(p, report_md(&model, &record, &run).as_bytes())?;
    }
    Ok(())
}

fn option_value(field: &str, a: &Args) -> String {
    match field {
        "--rd" => a.rd.to_string(),
        "--design" => format!(
            "{}/--holdout {}",
            a.design.unwrap_or(6),
            a.holdout.unwrap_or(2)
        ),
        _ => String::new(),
    }
}

/// Prints where the surrogate came from and its error (stderr).
pub fn report_model(model: &LocModel, elapsed: f64) {
    let v = model.scan.validation();
    if let Some(s) = &model.scan_status {
        eprintln!(
            "R2 scan surrogate ({}, {}): {} FE scans, built in {:.1} s wall{}; ready in {elapsed:.1} s",
            s.word(),
            s.path().display(),
            model.scan.fe_runs,
            model.scan.build_time_s,
            model
                .scan
                .build_cpu_s
                .map(|c| format!(" ({c:.1} s CPU)"))
                .unwrap_or_default()
        );
    }
    if let Some(c) = &model.centre_model {
        let cv = c.scan.validation();
        eprintln!(
            "centre scan surrogate error on {} held-out FE scans: max {:.3e} of the peak force; \
             correction along the block on {} held-out FE scans: max {:.3e} N \
             ({:.3e} of the deepest nodule's peak excess); both added to the likelihood as variances",
            cv.points,
            cv.max_relative_error,
            v.points,
            v.max_abs_error.iter().fold(0.0f64, |a, b| a.max(*b)),
            model.max_rel_error()
        );
        return;
    }
    eprintln!(
        "surrogate error on {} held-out FE scans: max {:.3e}, RMS {:.3e} of the peak force ({} basis vectors); added to the likelihood as a variance",
        v.points,
        v.max_relative_error,
        v.rms_relative_error,
        model.scan.basis_size()
    );
    if let Some(l) = &model.lean {
        eprintln!(
            "end lean (mm, + towards the nearer end) from FE scans, by distance from the end (rows) and depth {:?} mm:",
            l.depth
        );
        for (e, row) in l.distance.iter().zip(&l.shift) {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:+.3}")).collect();
            eprintln!("  {e:>5.1} mm: {}", cells.join("  "));
        }
    }
}

fn fmt_iv(i: &crate::apps::localize::posterior::Interval) -> String {
    format!(
        "{:.2} +- {:.2} [{:.2}, {:.2}]",
        i.mean, i.sd, i.hdi_3, i.hdi_97
    )
}

/// The table printed on stdout.
pub fn summary_text(model: &LocModel, record: &Record, run: &LocRun) -> String {
    let r = &run.result;
    let mut s = format!(
        "# R2 localisation, RD {} mm, {} ({} positions), {} nodule(s)\n",
        model.rd,
        record.file.display(),
        record.positions.len(),
        r.nodules.len()
    );
    s.push_str(
        "nodule | x mm: mean +- sd [94 % HDI] | depth mm: mean +- sd [94 % HDI] | identifiable\n",
    );
    for (k, n) in r.nodules.iter().enumerate() {
        s.push_str(&format!(
            "{} | {} | {} | {}\n",
            k + 1,
            fmt_iv(&n.x_mm),
            fmt_iv(&n.depth_mm),
            if n.identifiable { "yes" } else { "NI" }
        ));
    }
    s.push_str(&format!(
        "modulus scale {}; noise SD {:.4} N; surrogate {} FE runs, max rel. error {:.2e}\nR-hat max {:.4}, bulk ESS min {:.0}{}; posterior in {:.2} s ({} log-density evaluations)\n",
        fmt_iv(&run.scale),
        r.noise_sd,
        r.surrogate.fe_runs,
        r.surrogate.max_rel_error,
        r.rhat_max,
        r.ess_bulk_min,
        if run.converged { "" } else { " (NOT converged at the draw cap)" },
        run.wall_s,
        run.evaluations
    ));
    s
}

/// The Markdown report.
pub fn report_md(model: &LocModel, record: &Record, run: &LocRun) -> String {
    let mut s = String::from("# R2 tumour localisation\n\n");
    s.push_str(&format!(
        "Record `{}`, RD {} mm. Model: F(p) = s [F0(p) + sum_n E(|p - x_n|; d_n)] on a surrogate of the FE scan of one nodule (studies/src/apps/localize); depth box {:?} mm.\n\n```\n{}```\n",
        record.file.display(),
        model.rd,
        model.depth_box,
        summary_text(model, record, run)
    ));
    s
}
