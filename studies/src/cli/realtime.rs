//! `palpate surrogate build|query`: the real-time surrogate of the Q1 (or
//! N1) force response (`palpate_uq::surrogate::realtime`): built once from
//! FE runs (an elastic ramp for the force curve, training histories for its
//! memory kernel, random held-out histories for its error table) with a
//! progress bar, stored as a JSON file, queried on a CSV of depths.

use crate::limits::Progress;
use crate::output::{check_outputs, given, write_atomic};
use anyhow::{anyhow, bail, Context};
use palpate_core::ForwardModel;
use palpate_fe::{N1Needle, Prony, Q1Punch};
use palpate_material::Law;
use palpate_uq::surrogate::realtime::{RealTimeRequest, RealTimeSurrogate};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Build (from FE runs) or query the real-time force surrogate of Q1 or N1
///
/// `build` runs the FE model of the benchmark (an elastic ramp to
/// --depth-max for the force curve, --train histories its memory is fitted
/// to, and random held-out histories of ramps, holds and unloadings for its
/// error table) for one material (--law, --param, --prony) and stores the
/// surrogate as JSON; `query` answers any depth history, sample by sample,
/// in about a microsecond per sample.
/// The surrogate is valid only for that material, benchmark and depth range.
///
/// Examples:
///   palpate surrogate build --benchmark Q1 --law neo-hookean --param C10=0.0016 --prony g1=0.3,tau1=0.5 --depth-max 1 --out q1-rt.json
///   palpate surrogate query --surrogate q1-rt.json --csv depths.csv --out forces.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(subcommand)]
    pub command: Sub,
}

/// The surrogate subcommands (their help is their `Args` doc comment).
#[derive(Debug, clap::Subcommand)]
pub enum Sub {
    // Build from FE runs and store it (BuildArgs).
    Build(BuildArgs),
    // Answer a depth history (QueryArgs).
    Query(QueryArgs),
}

/// Build the surrogate from FE runs and store it
///
/// Runs the benchmark's FE model for the material given (--law, --param,
/// --prony): one elastic ramp to --depth-max; --train histories (a ramp and
/// hold, then random ones) to which the surrogate's memory is fitted (a
/// relaxation read through the present depth, with the contact form and
/// optional stop operators (a rate-independent hysteresis) chosen by
/// cross-validation; 0: plain QLV on the force curve with the material's
/// terms); then --holdout other random histories
/// of --segments ramps, holds and unloadings, whose FE forces are compared
/// with the surrogate's (and plain QLV's) in a printed error table (max
/// error at the segment ends and 16 points inside each ramp, 12 inside each
/// hold, as a percentage of the history's peak force).
///
/// Example: palpate surrogate build --benchmark Q1 --law neo-hookean --param C10=0.0016
///   --prony g1=0.3,tau1=0.5,g2=0.2,tau2=10 --depth-max 1 --out q1-rt.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct BuildArgs {
    /// Q1 (flat punch) or N1 (needle, friction 0.8 unless --friction).
    #[arg(long)]
    pub benchmark: String,
    /// N1: the needle's Coulomb friction [default: 0.8]. The fitted memory's
    /// worst held-out error (of the peak) on N1: 0.97 % to 4 mm frictionless, 2.2-2.3 % to
    /// 3-4 mm at 0.8; to 10 mm 2.2 % frictionless, 2.9 % at 0.8; plain QLV 1.2-13.5 %
    /// (docs/guide.md).
    #[arg(long)]
    pub friction: Option<f64>,
    /// Material law: neo-hookean, mooney-rivlin, reduced-polynomial:N, yeoh, arruda-boyce, ogden:N.
    #[arg(long)]
    pub law: String,
    /// A law parameter, e.g. --param C10=0.0016 (MPa); repeat for each.
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// The material's Prony series g1=..,tau1=..,...
    #[arg(long)]
    pub prony: String,
    /// The deepest depth it answers for (mm). Q1's FE runs to 5 mm with the default edge; past about 2 mm its force is good to a few per cent (mesh 2 against 3), and mesh 1 is stiff there (+8 % at 5 mm).
    #[arg(long, value_name = "MM")]
    pub depth_max: f64,
    /// Q1: radius of the punch's rounded edge in mm [default: 0.2], as `palpate simulate --edge-radius`: a larger edge is a rounded punch, no longer the flat one.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub edge_radius: Option<f64>,
    /// Mesh level of the FE runs (default 1).
    #[arg(long, default_value_t = 1)]
    pub mesh: usize,
    /// FE training histories for the fitted memory (default 12; 0: plain
    /// QLV, no training runs; otherwise at least 5).
    #[arg(long, default_value_t = 12)]
    pub train: usize,
    /// Held-out random histories run by FE for the error table (default 4).
    #[arg(long, default_value_t = 4)]
    pub holdout: usize,
    /// Segments (ramps, holds, unloadings) per held-out history (default 6).
    #[arg(long, default_value_t = 6)]
    pub segments: usize,
    /// The error the surrogate is meant to keep on held-out histories, as
    /// the largest station error over the history's peak force, in per cent
    /// [default: 2, issue 13's target]. A build that misses it is still
    /// stored, with a warning naming the histories over it.
    #[arg(long, value_name = "PCT", default_value_t = 2.0)]
    pub target: f64,
    /// Where to store the surrogate (JSON).
    #[arg(long, value_name = "OUT.json")]
    pub out: PathBuf,
}

/// Answer a depth history (CSV time_s,displacement_mm) sample by sample
///
/// Writes time_s,displacement_mm,force_N; a depth beyond the surrogate's
/// --depth-max is refused, naming its row (it does not extrapolate).
///
/// Example: palpate surrogate query --surrogate q1-rt.json --csv depths.csv --out forces.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct QueryArgs {
    /// The surrogate written by `palpate surrogate build`.
    #[arg(long, value_name = "FILE.json")]
    pub surrogate: PathBuf,
    /// Columns time_s,displacement_mm (header line; # comments).
    #[arg(long, value_name = "FILE.csv")]
    pub csv: PathBuf,
    /// Output CSV time_s,displacement_mm,force_N (default: standard output).
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
}

/// Runs `palpate surrogate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    match args.command {
        Sub::Build(a) => build(a),
        Sub::Query(a) => query(a),
    }
}

fn build(a: BuildArgs) -> anyhow::Result<()> {
    let law: Law = a.law.parse().map_err(|e| anyhow!("--law {}: {e}", a.law))?;
    let theta = super::simulate::parse_params(&law, &a.params)?;
    let prony: Prony = a
        .prony
        .parse()
        .map_err(|e| anyhow!("--prony {}: {e}", a.prony))?;
    if !(a.depth_max > 0.0 && a.depth_max.is_finite() && a.depth_max <= 20.0) {
        bail!(
            "--depth-max {}: give a depth in mm, > 0 and <= 20",
            a.depth_max
        );
    }
    if !(1..=6).contains(&a.mesh) {
        bail!("--mesh {}: give a level 1..6", a.mesh);
    }
    if a.train != 0 && !(5..=64).contains(&a.train) {
        bail!(
            "--train {}: give 0 (plain QLV) or 5..64 FE training histories",
            a.train
        );
    }
    if !(1..=64).contains(&a.holdout) || !(1..=50).contains(&a.segments) {
        bail!(
            "--holdout {} / --segments {}: give 1..64 histories of 1..50 segments",
            a.holdout,
            a.segments
        );
    }
    if !(a.target > 0.0 && a.target.is_finite()) {
        bail!("--target {}: give a per cent > 0", a.target);
    }
    check_outputs(&[], &given(&[("--out", &Some(a.out.clone()))]))?;
    if a.friction.is_some() && !a.benchmark.eq_ignore_ascii_case("N1") {
        bail!("--friction applies to --benchmark N1 only (Q1's punch is frictionless)");
    }
    if a.edge_radius.is_some() && !a.benchmark.eq_ignore_ascii_case("Q1") {
        bail!("--edge-radius applies to --benchmark Q1 only (the flat punch's edge)");
    }
    let (elastic, visco): (Box<dyn ForwardModel>, Box<dyn ForwardModel>) =
        match a.benchmark.to_ascii_uppercase().as_str() {
            "Q1" => {
                let mut e = Q1Punch::new(law);
                e.level = a.mesh;
                if let Some(rho) = a.edge_radius {
                    e.set_edge_radius(rho)
                        .map_err(|why| anyhow::anyhow!("--edge-radius {rho}: {why}"))?;
                }
                let mut v = e.clone();
                v.prony = Some(prony.clone());
                (Box::new(e), Box::new(v))
            }
            "N1" => {
                let mut e = N1Needle::new(law);
                e.mesh.level = a.mesh;
                if let Some(mu) = a.friction {
                    if !(mu >= 0.0 && mu.is_finite()) {
                        bail!("--friction {mu}: give a coefficient >= 0");
                    }
                    e.friction = mu;
                }
                let mut v = e.clone();
                v.prony = Some(prony.clone());
                (Box::new(e), Box::new(v))
            }
            b => bail!("--benchmark {b}: the real-time surrogate is built for Q1 or N1"),
        };
    let extra = |m: &dyn ForwardModel| -> Vec<f64> {
        let mut t = theta.clone();
        t.extend(m.space().params[theta.len()..].iter().map(|p| p.initial));
        t
    };
    let (te, tv) = (extra(elastic.as_ref()), extra(visco.as_ref()));
    let req = RealTimeRequest {
        elastic: elastic.as_ref(),
        elastic_theta: &te,
        viscoelastic: visco.as_ref(),
        viscoelastic_theta: &tv,
        prony: prony.terms().to_vec(),
        depth_max: a.depth_max,
        knots: 20,
        validation_histories: a.holdout,
        segments: a.segments,
        training_histories: a.train,
        kernel_knots: 10,
    };
    if a.benchmark.eq_ignore_ascii_case("Q1")
        && a.mesh <= 1
        && a.depth_max > 2.0
        && a.edge_radius.is_none_or(|r| r < 0.5)
    {
        eprintln!(
            "note: on mesh {} the Q1 force past 2 mm is stiff (+8 % at 5 mm against mesh 3) and drops by up to 4 % where the surface snaps round the punch's edge; the surrogate follows this mesh's FE (--mesh 2: within 4.2 %, about 9 x the FE time; docs/guide.md)",
            a.mesh
        );
    }
    let total = (1 + a.train + a.holdout) as u64;
    let bar = Progress::new(
        total,
        "real-time surrogate",
        "{msg} [{bar:40}] {pos}/{len} FE runs ({elapsed}, eta {eta})",
    );
    let tick = |_d: usize, _t: usize| bar.inc(1);
    let built = RealTimeSurrogate::build(&req, Some(&tick));
    bar.finish();
    let s = built.map_err(|e| anyhow!("building the surrogate of {}: {e}", visco.name()))?;
    write_atomic(&a.out, s.to_json().as_bytes())?;
    println!("{}", error_table(&s));
    if let Some(w) = target_warning(&s, a.target) {
        eprintln!("{w}");
    }
    eprintln!(
        "built from {} FE runs in {:.1} s, stored in {}",
        s.fe_runs,
        s.build_time_s,
        a.out.display()
    );
    Ok(())
}

/// A warning naming the held-out histories whose largest error over their
/// peak is above `target` per cent (with the RMS error, which says whether
/// the history is off or a few stations are); none if all are within it.
pub fn target_warning(s: &RealTimeSurrogate, target: f64) -> Option<String> {
    let over: Vec<String> = s
        .validation
        .iter()
        .filter(|h| 100.0 * h.max_relative_error > target)
        .map(|h| {
            let at = h
                .worst_at
                .map_or(String::new(), |(t, d)| format!(" at {t:.2} s, {d:.2} mm"));
            let rms = h
                .rms_relative_error
                .map_or(String::new(), |e| format!(", RMS {:.2} %", 100.0 * e));
            format!(
                "{} {:.2} %{at}{rms}",
                h.history,
                100.0 * h.max_relative_error
            )
        })
        .collect();
    if over.is_empty() {
        return None;
    }
    Some(format!(
        "warning: {} of {} held-out histories above the {target} % target (largest error over the peak): {}. The surrogate is stored; at depth the largest errors sit where the contact ends or starts again (docs/guide.md, the real-time surrogate)",
        over.len(),
        s.validation.len(),
        over.join("; ")
    ))
}

/// How the fitted memory meets the punch, in words.
pub fn contact_words(k: &palpate_uq::surrogate::memory_kernel::MemoryKernel) -> String {
    let [g, a] = k.soft_contact;
    let contact = if !k.lift_off {
        "follows the punch".into()
    } else if g == 0.0 {
        "follows the free surface".into()
    } else {
        format!(
            "follows a surface that lets go over a gap of {g:.3} mm (compliant contact, press {a:.3e} N)"
        )
    };
    if k.stops.is_empty() {
        contact
    } else {
        let r: Vec<String> = k.stops.iter().map(|r| format!("{r:.3}")).collect();
        format!(
            "{contact}, with stop operators (hysteresis) of {} mm",
            r.join(", ")
        )
    }
}

/// The held-out error table (Markdown), with plain QLV's error beside the
/// fitted memory's when the surrogate has one.
pub fn error_table(s: &RealTimeSurrogate) -> String {
    let with_qlv = s.qlv_validation.len() == s.validation.len() && s.kernel.is_some();
    let mut r = String::new();
    if let Some(k) = &s.kernel {
        let _ = write!(
            r,
            "memory fitted to {} FE training histories ({} stations, RMS {:.3e} N); on loss of contact it {}",
            k.training.histories,
            k.training.stations,
            k.training.rms_n,
            contact_words(k),
        );
        if let Some([without, with]) = k.training.cv_max_relative_error {
            let _ = write!(
                r,
                " (cross-validated mean max error {:.2} % following the punch, {:.2} % the best loss of contact",
                100.0 * without,
                100.0 * with
            );
            for ([g, a], e) in &k.training.cv_contacts {
                let _ = if *g == 0.0 {
                    write!(r, "; hard {:.2} %", 100.0 * e)
                } else {
                    write!(r, "; gap {g} D, press {a} peak {:.2} %", 100.0 * e)
                };
            }
            if !k.training.cv_stops.is_empty() {
                let e: Vec<String> = k
                    .training
                    .cv_stops
                    .iter()
                    .map(|e| format!("{:.2}", 100.0 * e))
                    .collect();
                let _ = write!(
                    r,
                    "; with stop operators, the same forms in order: {} %",
                    e.join(" / ")
                );
            }
            r.push(')');
        }
        r.push_str("\n\n");
    }
    for f in &s.training_failures {
        let _ = writeln!(r, "left out of the fit: {f}\n");
    }
    for f in &s.validation_failures {
        let _ = writeln!(r, "not in the error table: {f}\n");
    }
    r.push_str(
        "| held-out FE history | stations | peak force (N) | max error (N) | max error / peak | where (s, mm) | RMS error / peak |",
    );
    r.push_str(if with_qlv {
        " plain QLV: max error / peak |\n|---|---|---|---|---|---|---|---|\n"
    } else {
        "\n|---|---|---|---|---|---|---|\n"
    });
    for (j, h) in s.validation.iter().enumerate() {
        let _ = write!(
            r,
            "| {} | {} | {:.4e} | {:.3e} | {:.2} % | {} | {} |",
            h.history,
            h.samples,
            h.peak_force_n,
            h.max_abs_error_n,
            100.0 * h.max_relative_error,
            h.worst_at
                .map_or("-".to_string(), |(t, d)| format!("{t:.2}, {d:.2}")),
            h.rms_relative_error
                .map_or("-".to_string(), |e| format!("{:.2} %", 100.0 * e))
        );
        if with_qlv {
            let _ = write!(
                r,
                " {:.2} % |",
                100.0 * s.qlv_validation[j].max_relative_error
            );
        }
        r.push('\n');
    }
    r
}

fn query(a: QueryArgs) -> anyhow::Result<()> {
    let outputs = given(&[("--out", &a.out)]);
    check_outputs(&[a.surrogate.as_path(), a.csv.as_path()], &outputs)?;
    let text = std::fs::read_to_string(&a.surrogate)
        .with_context(|| format!("--surrogate {}", a.surrogate.display()))?;
    let mut s = RealTimeSurrogate::from_json(&text).map_err(|e| {
        anyhow!(
            "--surrogate {}: not a real-time surrogate: {e}",
            a.surrogate.display()
        )
    })?;
    let (time, depth) = read_depths(&a.csv)?;
    let mut out = String::from("time_s,displacement_mm,force_N\n");
    let mut prev = 0.0;
    for (k, (&t, &d)) in time.iter().zip(&depth).enumerate() {
        let f = s
            .force(d, t - prev)
            .map_err(|e| anyhow!("{}: row {} (time_s {t}): {e}", a.csv.display(), k + 2))?;
        prev = t;
        let _ = writeln!(out, "{t},{d},{f:.8e}");
    }
    match &a.out {
        Some(p) => {
            write_atomic(p, out.as_bytes())?;
            eprintln!("wrote {}", p.display());
        }
        None => print!("{out}"),
    }
    Ok(())
}

/// Reads `time_s,displacement_mm`; errors name the file and line.
fn read_depths(path: &Path) -> anyhow::Result<(Vec<f64>, Vec<f64>)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("--csv {}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| {
        anyhow!(
            "{}: empty; expected a header time_s,displacement_mm",
            path.display()
        )
    })?;
    let cols: Vec<&str> = header
        .trim_start_matches('\u{feff}')
        .split(',')
        .map(str::trim)
        .collect();
    let it = cols.iter().position(|c| *c == "time_s");
    let id = cols.iter().position(|c| *c == "displacement_mm");
    let (Some(it), Some(id)) = (it, id) else {
        bail!(
            "{}: the header must name time_s and displacement_mm (found {header})",
            path.display()
        );
    };
    let (mut time, mut depth) = (Vec::new(), Vec::new());
    for (i, l) in lines {
        let f: Vec<&str> = l.split(',').map(str::trim).collect();
        let num = |j: usize, name: &str| -> anyhow::Result<f64> {
            f.get(j)
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow!(
                        "{}: line {}: {name} is not a finite number",
                        path.display(),
                        i + 1
                    )
                })
        };
        let t = num(it, "time_s")?;
        if let Some(&p) = time.last() {
            if t < p {
                bail!(
                    "{}: line {}: time_s {t} goes back (previous {p})",
                    path.display(),
                    i + 1
                );
            }
        }
        time.push(t);
        depth.push(num(id, "displacement_mm")?);
    }
    if time.is_empty() {
        bail!("{}: no rows after the header", path.display());
    }
    Ok((time, depth))
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_uq::surrogate::realtime::{HistoryError, MonotoneCubic};

    fn row(name: &str, max: f64, rms: Option<f64>) -> HistoryError {
        HistoryError {
            history: name.into(),
            samples: 20,
            peak_force_n: 0.1,
            max_abs_error_n: 0.1 * max,
            max_relative_error: max,
            rms_relative_error: rms,
            worst_at: Some((13.8, 1.61)),
        }
    }

    /// The warning names exactly the held-out histories over the target,
    /// with where and the RMS; none when all are within it.
    #[test]
    fn the_build_warns_of_the_histories_over_the_target() {
        let curve = MonotoneCubic::new(vec![0.0, 0.5, 1.0], vec![0.0, 0.01, 0.03]).unwrap();
        let mut s = RealTimeSurrogate::new("test".into(), curve, vec![(0.3, 0.5)]).unwrap();
        s.validation = vec![
            row("random 1", 0.012, Some(0.004)),
            row("random 3", 0.0381, Some(0.0103)),
            row("random 4", 0.025, None),
        ];
        let w = target_warning(&s, 2.0).expect("two over 2 %");
        assert!(
            w.starts_with("warning: 2 of 3 held-out histories above the 2 % target"),
            "{w}"
        );
        assert!(
            w.contains("random 3 3.81 % at 13.80 s, 1.61 mm, RMS 1.03 %"),
            "{w}"
        );
        assert!(w.contains("random 4 2.50 % at 13.80 s, 1.61 mm"), "{w}");
        assert!(!w.contains("random 1"), "{w}");
        assert_eq!(target_warning(&s, 4.0), None);
    }
}
