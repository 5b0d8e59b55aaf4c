//! `palpate anova`: analysis of variance of a table with one row per run
//! (factor columns hold level names), with residual checks, a JSON record
//! and SVG plots.

use crate::report::anova::plots;
use crate::run::checks::check_alpha;
use crate::run::output::{write_atomic, write_json};
use anyhow::Context;
use palpate_uq::anova::{analyse, Analysis, AnovaOptions, RunsTable};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// ANOVA of a table with one row per run (factor columns hold level names)
///
/// The table has one row per run; factor columns hold level names (text),
/// the response column numbers. Prints the ANOVA table (sequential SS, equal
/// to Type III on balanced designs), R^2, the Ryan-Joiner and Anderson-Darling
/// normality tests of the residuals and Bartlett's and Levene's
/// (Brown-Forsythe, median-centred) tests of equal variances across cells.
///
/// Example: palpate anova --data table1.csv --response r2 --factors material,space --json anova.json --plot plots
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// CSV file, one row per run.
    #[arg(long)]
    pub data: PathBuf,
    /// Name of the response column.
    #[arg(long)]
    pub response: String,
    /// Factor columns, comma-separated (A,B[,C...]).
    #[arg(long, value_delimiter = ',', required = true)]
    pub factors: Vec<String>,
    /// Highest interaction order in the model (default: all).
    #[arg(long, value_parser = crate::run::limits::parse_count::<usize>)]
    pub max_order: Option<usize>,
    /// Significance level of the Pareto reference line and Lenth's margins.
    #[arg(long, default_value_t = 0.05)]
    pub alpha: f64,
    /// Write the full analysis as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write SVG plots (Pareto, main effects, interactions, normal
    /// probability plot and residuals vs fits) into this directory.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// Runs `palpate anova`.
pub fn run(args: Args) -> anyhow::Result<()> {
    crate::run::output::check_outputs_and_dirs(
        &[&args.data],
        &crate::run::output::given(&[("--json", &args.json)]),
        &crate::run::output::given(&[("--plot", &args.plot)]),
    )?;
    check_alpha("--alpha", args.alpha)?;
    if let Some(f) = args.factors.iter().find(|f| f.trim() == args.response) {
        anyhow::bail!(
            "--factors {}: `{f}` is the response (--response {}); a column cannot explain itself",
            args.factors.join(","),
            args.response
        );
    }
    let table = RunsTable::read(&args.data)?;
    let factors = args
        .factors
        .iter()
        .map(|f| table.factor(f.trim()))
        .collect::<Result<Vec<_>, _>>()?;
    let y = table.numeric(&args.response)?;
    crate::run::limits::check_anova("--max-order", args.max_order, factors.len(), y.len())?;
    let options = AnovaOptions {
        max_order: args.max_order,
        alpha: args.alpha,
        ..Default::default()
    };
    let analysis = analyse(&args.response, &factors, &y, &options)
        .with_context(|| format!("ANOVA of `{}` in {}", args.response, args.data.display()))?;
    print!("{}", format_analysis(&analysis));
    write_outputs(&analysis, args.json.as_deref(), args.plot.as_deref())
}

/// Writes the JSON record and the plots where asked.
pub fn write_outputs(
    analysis: &Analysis,
    json: Option<&Path>,
    plot_dir: Option<&Path>,
) -> anyhow::Result<()> {
    if let Some(path) = json {
        write_json(path, analysis)?;
        println!("wrote {}", path.display());
    }
    if let Some(dir) = plot_dir {
        for (name, svg) in plots(analysis) {
            let path = dir.join(name);
            write_atomic(&path, svg.as_bytes())?;
        }
        println!("wrote plots in {}", dir.display());
    }
    Ok(())
}

fn opt(v: Option<f64>, width: usize, prec: usize) -> String {
    match v {
        Some(v) => format!("{v:>width$.prec$}"),
        None => format!("{:>width$}", "-"),
    }
}

fn sci(v: Option<f64>) -> String {
    match v {
        Some(v) => format!("{v:>12.6e}"),
        None => format!("{:>12}", "-"),
    }
}

fn pfmt(p: Option<f64>) -> String {
    match p {
        Some(p) if p < 0.0005 => format!("{:>8}", "<0.001"),
        Some(p) => format!("{p:>8.3}"),
        None => format!("{:>8}", "-"),
    }
}

/// The readable report: ANOVA table, model summary and residual checks.
pub fn format_analysis(a: &Analysis) -> String {
    let t = &a.table;
    let mut s = String::new();
    let w = t
        .terms
        .iter()
        .map(|r| r.name.len())
        .max()
        .unwrap_or(6)
        .max(8);
    let _ = writeln!(
        s,
        "Analysis of variance of `{}` ({} runs{})",
        t.response,
        t.total.df + 1,
        if t.balanced {
            ", balanced"
        } else {
            ", unbalanced: sequential SS"
        }
    );
    let _ = writeln!(
        s,
        "{:<w$} {:>3} {:>12} {:>12} {:>10} {:>8} {:>7} {:>9}",
        "Source", "DF", "SS", "MS", "F", "P", "eta^2", "p.eta^2"
    );
    for r in &t.terms {
        let _ = writeln!(
            s,
            "{:<w$} {:>3} {:>12.6e} {} {} {} {:>7.3} {}",
            r.name,
            r.df,
            r.ss,
            sci(r.ms),
            opt(r.f, 10, 3),
            pfmt(r.p),
            r.eta_sq,
            opt(r.partial_eta_sq, 9, 3)
        );
    }
    let _ = writeln!(
        s,
        "{:<w$} {:>3} {:>12.6e} {}",
        "Error",
        t.residual.df,
        t.residual.ss,
        sci(t.residual.ms)
    );
    let _ = writeln!(s, "{:<w$} {:>3} {:>12.6e}", "Total", t.total.df, t.total.ss);
    let _ = writeln!(
        s,
        "R-sq = {:.2} %   R-sq(adj) = {}",
        100.0 * t.r2,
        t.adj_r2
            .map(|v| format!("{:.2} %", 100.0 * v))
            .unwrap_or_else(|| "-".into())
    );
    if let Some(rj) = &a.ryan_joiner {
        let _ = writeln!(
            s,
            "Ryan-Joiner (residuals): R = {:.4}, p {}",
            rj.r,
            rj.p_text()
        );
    }
    if let Some(ad) = &a.anderson_darling {
        let _ = writeln!(
            s,
            "Anderson-Darling (residuals): A^2 = {:.4}, p = {:.3}",
            ad.a2, ad.p
        );
    }
    if let Some(b) = &a.bartlett {
        let _ = writeln!(
            s,
            "Bartlett (equal variances): statistic = {:.4}, p = {:.3}",
            b.statistic, b.p
        );
    }
    if let Some(l) = &a.levene {
        let _ = writeln!(
            s,
            "Levene (Brown-Forsythe, median): statistic = {:.4}, p = {:.3}",
            l.statistic, l.p
        );
    }
    if let Some(p) = &a.pareto {
        if let Some(l) = &p.lenth {
            let _ = writeln!(
                s,
                "Lenth: PSE = {:.4}, ME = {:.4}, SME = {:.4} (alpha = {})",
                l.pse, l.me, l.sme, l.alpha
            );
        }
    }
    for n in &a.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}
