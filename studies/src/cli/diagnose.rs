//! `palpate diagnose`: the sim-to-real gap of a calibrated base model —
//! where the misfit lies, which unmodelled effect causes it, how far it
//! shrinks once that effect is added (GAP.md).

use crate::calibration::{TestData, TestKind};
use crate::output::{write_atomic, write_json};
use crate::plot::{grid_svg, Band, Plot, Series};
use anyhow::Context;
use palpate_core::{Effect, ForwardModel};
use palpate_material::Law;
use palpate_uq::gap::{diagnose, GapOptions, GapReport};
use std::path::{Path, PathBuf};

/// Diagnose the gap between a base model and a measured force record.
///
/// The base model (e.g. incompressible neo-Hookean C1 compression) is
/// calibrated to the record; the misfit is located on the experiment's axis
/// (time, or displacement for untimed records) against the noise estimated
/// from the data; each candidate effect the model offers (material_form,
/// viscoelasticity, zero_offset, compressibility, tool_compliance for C1;
/// friction, boundary_condition, material_form, zero_offset for N1) is
/// scored, refitted and cross-validated on held-out blocks; the verdict is
/// the effect that earns its parameters, `none` when none does, and
/// confounded effects are reported as such.
///
/// Example: palpate diagnose --benchmark C1 --data record.csv --base neo-hookean --json gap.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Benchmark the record comes from: C1 (analytic compression, seconds) or
    /// N1 (FE needle indentation on the coarse mesh, frictionless needle,
    /// bonded base; candidates friction, boundary_condition, material_form,
    /// zero_offset; some 100 FE runs, a few minutes on 2 cores for a 10 mm record).
    #[arg(long, default_value = "C1")]
    pub benchmark: String,
    /// The record: CSV with displacement_mm, force_N and (for rate effects) time_s.
    #[arg(long)]
    pub data: PathBuf,
    /// Base material law (neo-hookean, mooney-rivlin, reduced-polynomial:N, ...).
    #[arg(long, default_value = "neo-hookean")]
    pub base: String,
    /// Candidate effects, comma separated. Default: for C1 every effect the
    /// model offers; for N1 the GAP.md N1 effects `friction` and
    /// `boundary_condition` (add `material_form` and `zero_offset` here: on a
    /// single force-depth curve friction and a stiffening law cannot be told
    /// apart, and the report then says so).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Family-wise significance level of the tests.
    #[arg(long, default_value_t = GapOptions::default().alpha)]
    pub alpha: f64,
    /// Contiguous blocks for the blocked cross-validation.
    #[arg(long, default_value_t = GapOptions::default().folds)]
    pub folds: usize,
    /// Write the diagnosis as JSON (GAP.md contract).
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Write a readable markdown report.
    #[arg(long, value_name = "OUT.md")]
    pub report: Option<PathBuf>,
    /// Draw data, base fit, enriched fit and residuals with the flagged windows (SVG).
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
}

/// The base forward model of a benchmark: C1 (analytic, lubricated
/// platens) or N1 (axisymmetric FE needle indentation with a frictionless
/// needle on the coarse mesh, so that `friction` and `boundary_condition`
/// are effects to find).
pub fn base_model(benchmark: &str, law: Law) -> anyhow::Result<Box<dyn ForwardModel>> {
    if benchmark.eq_ignore_ascii_case("c1") {
        Ok(Box::new(palpate_analytic::C1Compression::new(law)))
    } else if benchmark.eq_ignore_ascii_case("n1") {
        let mut m = palpate_fe::N1Needle::new(law);
        m.friction = 0.0;
        m.mesh = palpate_fe::MeshDensity::COARSE;
        Ok(Box::new(m))
    } else {
        anyhow::bail!("--benchmark {benchmark}: the gap diagnosis supports C1 (analytic) and N1 (finite elements)")
    }
}

/// The default candidate effects of a benchmark (`None`: every effect the
/// base model offers). N1: GAP.md's `friction` and `boundary_condition`;
/// the N1 model also offers `material_form` and `zero_offset`, but on one
/// force-depth curve friction and a stiffening law are confounded
/// (docs/gap-diagnosis.md), so they are candidates on request only.
pub fn default_effects(benchmark: &str) -> Option<Vec<Effect>> {
    benchmark
        .eq_ignore_ascii_case("n1")
        .then(|| vec![Effect::Friction, Effect::BoundaryCondition])
}

/// Effect names (GAP.md) parsed, the error naming the bad one.
pub fn parse_effects(names: &[String]) -> anyhow::Result<Vec<Effect>> {
    names
        .iter()
        .map(|e| e.parse::<Effect>().map_err(|m| anyhow::anyhow!("{m}")))
        .collect()
}

/// Diagnoses one record (shared with the manifest step).
pub fn diagnose_file(
    benchmark: &str,
    base: &str,
    data: &Path,
    options: &GapOptions,
) -> anyhow::Result<GapReport> {
    let law: Law = base
        .parse()
        .map_err(|e| anyhow::anyhow!("base law `{base}`: {e}"))?;
    let model = base_model(benchmark, law)?;
    // C1 and N1 records share the columns displacement_mm, force_N[, time_s].
    let record = TestData::read("record", TestKind::C1, data)?;
    let mut options = options.clone();
    if options.effects.is_none() {
        options.effects = default_effects(benchmark);
    }
    diagnose(model.as_ref(), &record.loading, &record.observed, &options)
        .with_context(|| format!("diagnosing {}", data.display()))
}

/// Runs `palpate diagnose`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut options = GapOptions {
        alpha: args.alpha,
        folds: args.folds,
        ..GapOptions::default()
    };
    if !args.effects.is_empty() {
        options.effects = Some(parse_effects(&args.effects).context("--effects")?);
    }
    let report = diagnose_file(&args.benchmark, &args.base, &args.data, &options)?;
    println!("{}", summary(&report));
    if let Some(p) = &args.json {
        write_json(p, &report)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &args.report {
        write_atomic(p, report.to_markdown().as_bytes())?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &args.plot {
        write_atomic(
            p,
            gap_svg(&report, &args.data.display().to_string()).as_bytes(),
        )?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// A few lines for the terminal.
pub fn summary(r: &GapReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "verdict: {}", r.verdict);
    if !r.confounded.is_empty() {
        let _ = writeln!(s, "cannot be told apart from: {}", r.confounded.join(", "));
    }
    let _ = writeln!(
        s,
        "noise SD {:.4} (estimated from the data); base misfit RMS {:.4}, held-out {:.4}",
        r.noise_sd, r.base.misfit, r.base.heldout
    );
    for w in &r.where_ {
        let _ = writeln!(
            s,
            "  misfit window {} {:.3} .. {:.3}: RMS {:.4}",
            w.axis, w.from, w.to, w.misfit_rms
        );
    }
    let _ = writeln!(
        s,
        "{:<18} {:>10} {:>10} {:>10} {:>10}  identifiable",
        "effect", "fit before", "after", "held-out", "after"
    );
    for e in &r.ranking {
        let _ = writeln!(
            s,
            "{:<18} {:>10.4} {:>10.4} {:>10.4} {:>10.4}  {}",
            e.effect,
            e.misfit_before,
            e.misfit_after,
            e.heldout_before,
            e.heldout_after,
            e.identifiable
        );
    }
    let _ = write!(s, "{}", r.explanation);
    s
}

/// Two panels: data with base and enriched fits; residuals with the
/// discrepancy band and the flagged windows.
pub fn gap_svg(r: &GapReport, title: &str) -> String {
    let p = &r.plot;
    let windows: Vec<(f64, f64)> = r.where_.iter().map(|w| (w.from, w.to)).collect();
    let mut top = Plot::new("data and fits", &p.axis, "force (N)");
    top.width = 760.0;
    top.windows = windows.clone();
    top.push(Series::markers("data", &p.x, &p.observed).color("#888888"));
    top.push(Series::line("base fit", &p.x, &p.base_fit).color("#d62728"));
    if let (Some(e), Some(f)) = (&p.enriched_effect, &p.enriched_fit) {
        top.push(Series::line(format!("base + {e}"), &p.x, f).color("#2ca02c"));
    }
    let mut bottom = Plot::new(
        "residuals (flagged windows shaded)",
        &p.axis,
        "residual (N)",
    );
    bottom.width = 760.0;
    bottom.windows = windows;
    bottom.hlines = vec![0.0];
    bottom.bands.push(Band {
        label: "running mean +- 2 sigma/sqrt(w)".into(),
        x: p.x.clone(),
        lower: p.band_lower.clone(),
        upper: p.band_upper.clone(),
        color: "#1f77b4".into(),
    });
    bottom.push(Series::markers("base residual", &p.x, &p.base_residual).color("#d62728"));
    if let (Some(e), Some(res)) = (&p.enriched_effect, &p.enriched_residual) {
        bottom.push(Series::markers(format!("base + {e} residual"), &p.x, res).color("#2ca02c"));
    }
    grid_svg(
        &[Some(top), Some(bottom)],
        1,
        &format!("gap diagnosis of {title}: verdict {}", r.verdict),
    )
}
