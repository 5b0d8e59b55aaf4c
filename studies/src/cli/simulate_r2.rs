//! `palpate simulate --benchmark R2`: the wheel pressed to RD at x = 10 mm
//! (the pressing phase, written to `OUT.press.csv`) and rolled to x = 140 mm
//! (the rolled pass, `OUT.csv`: `position_mm,force_N,force_x_N`), with the
//! discretisation error estimate of the rolled force from the same pass on
//! elements twice as large. The frictionless pass is solved in two segments
//! in parallel (the state depends on the wheel position alone,
//! `R2Rolling::rolled_pass`).

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use palpate_core::{Drive, ForwardError, Loading};
use palpate_fe::discretisation::{richardson, Coarser};
use palpate_fe::{R2Rolling, System};
use palpate_material::Law;

use super::simulate::{parse_params, progress_bar, volumetric, Args};
use crate::report::plot::{Plot, Series};
use crate::run::limits::Progress;
use crate::run::output::write_atomic;

/// The parameters of one law: docs/benchmarks.md's when the law is Arruda-Boyce
/// and none is given (`rtv6166-ab` or `rubber-ab`), else every one named.
fn law_params(
    law: &Law,
    given: &[String],
    default: &[f64],
    option: &str,
) -> anyhow::Result<Vec<f64>> {
    if given.is_empty() && *law == Law::ArrudaBoyce {
        return Ok(default.to_vec());
    }
    parse_params(law, given).map_err(|e| anyhow!("{}", e.to_string().replace("--param", option)))
}

/// Where the pressing phase goes: `OUT.csv` -> `OUT.press.csv`.
fn press_path(csv: &Path) -> PathBuf {
    let stem = csv
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "r2".into());
    csv.with_file_name(format!("{stem}.press.csv"))
}

/// The number of parallel segments of a frictionless pass.
fn segments() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(2)
}

/// Runs the R2 benchmark for the checked `model`.
pub fn run(args: &Args, model: R2Rolling) -> anyhow::Result<()> {
    let p = R2Rolling::BENCHMARK_PARAMS;
    let mut theta = law_params(model.law(), &args.params, &p[..2], "--param")?;
    theta.extend(law_params(
        model.nodule_law(),
        &args.nodule_params,
        &p[2..],
        "--nodule-param",
    )?);
    let press_csv = args.csv.as_deref().map(press_path);
    crate::run::output::check_outputs(
        &[],
        &crate::run::output::given(&[
            ("--csv", &args.csv),
            ("--csv (pressing phase)", &press_csv),
            ("--vtu", &args.vtu),
            ("--plot", &args.plot),
        ]),
    )?;
    if let Some(p) = args.order {
        if !(p > 0.0 && p.is_finite()) {
            bail!("--order {p}: must be a positive order of convergence");
        }
    }
    let step = args.step.unwrap_or(0.5);
    if !(step > 0.0 && step.is_finite()) {
        bail!("--step {step}: must be a positive spacing of wheel positions in mm");
    }
    let span = model.roll_to - model.press_x;
    crate::run::limits::check_count(
        &format!("--step {}", crate::run::limits::fmt_value(step)),
        (span / step).ceil() + 1.0,
        "positions",
        256.0,
    )?;
    let positions = model.pass_positions(step);
    let title = palpate_core::ForwardModel::name(&model);
    let mut comments = vec![
        format!("palpate simulate: {title}"),
        format!("volumetric: {} (plane stress)", volumetric(model.bulk)),
        format!(
            "force_N: vertical force of the wheel on the {} mm thick block, positive in compression; force_x_N: its force along +x (rolling direction)",
            model.thickness
        ),
    ];

    // pressing phase at press_x, every 0.25 mm
    let n = (model.rd / 0.25).ceil().max(1.0) as usize;
    let depths: Vec<f64> = (1..=n).map(|k| model.rd * k as f64 / n as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths.clone());
    let (bar, mut cb) = progress_bar(depths.len(), "pressing: ");
    let press = model.simulate(&theta, &loading, Some(&mut cb));
    drop(cb);
    bar.finish_and_clear();
    let press = match press {
        Ok((sim, _)) => sim.outputs,
        Err(e) => bail!(
            "{title}: the pressing phase at x = {} mm: {e}",
            model.press_x
        ),
    };
    eprintln!(
        "pressed to {} mm at x = {} mm: F = {:.6} N",
        model.rd,
        model.press_x,
        press.last().map_or(0.0, |o| o[0])
    );
    if let Some(path) = &press_csv {
        let mut s = String::new();
        for c in &comments {
            s.push_str(&format!("# {c}\n"));
        }
        s.push_str(&format!(
            "# pressing phase: wheel at x = {} mm\ndisplacement_mm,force_N,force_x_N\n0.000000,0,0\n",
            model.press_x
        ));
        for (d, o) in depths.iter().zip(&press) {
            s.push_str(&format!("{d:.6},{:.9e},{:.9e}\n", o[0], o[1]));
        }
        write_atomic(path, s.as_bytes())?;
    }

    // the rolled pass
    let progress = Progress::new(
        positions.len() as u64,
        "R2 rolled pass",
        "{bar:40} {pos}/{len} positions  {msg}  [{elapsed_precise}]",
    );
    let tick = || progress.inc(1);
    let t0 = std::time::Instant::now();
    let result = model.rolled_pass(&theta, &positions, segments(), Some(&tick));
    progress.finish();
    let (rows, sys): (Vec<[f64; 2]>, Option<System>) = match result {
        Ok(r) => r,
        Err(ForwardError::NotConverged {
            sample,
            cuts,
            reason,
            completed,
            ..
        }) => {
            let done: Vec<[f64; 2]> = completed.chunks(2).map(|c| [c[0], c[1]]).collect();
            if let Some(path) = &args.csv {
                comments.push(format!(
                    "did not converge at position {} mm: partial pass, no error estimate",
                    positions[sample.min(positions.len() - 1)]
                ));
                write_pass(path, &comments, &positions[..done.len()], &done, None)?;
                eprintln!(
                    "wrote the {} converged positions to {}",
                    done.len(),
                    path.display()
                );
            }
            bail!(
                "{title}: did not converge at position {} mm after {cuts} step cuts: {reason}",
                positions[sample.min(positions.len() - 1)]
            );
        }
        Err(e) => bail!("{title}: {e}"),
    };
    let forces: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    eprintln!(
        "{title}: {} positions in {:.1} s; peak F = {:.6} N",
        rows.len(),
        t0.elapsed().as_secs_f64(),
        forces.iter().cloned().fold(0.0, f64::max)
    );
    if let Some(s) = &sys {
        eprintln!(
            "mesh: {} nine-node elements, {} unknowns",
            s.mesh.cell_count(),
            s.equations()
        );
    }
    let errors = if args.error_estimate == "on" {
        let Coarser {
            model: coarse,
            ratio,
            mesh,
        } = model.coarser();
        let documented = model.convergence_order();
        let (p, source) = match args.order {
            Some(p) => (p, "--order".to_string()),
            None => (documented.order, documented.source),
        };
        let progress = Progress::new(
            positions.len() as u64,
            "coarse mesh for the error estimate",
            "{bar:40} {pos}/{len} positions  {msg}  [{elapsed_precise}]",
        );
        let tick = || progress.inc(1);
        let coarse_pass = coarse.rolled_pass(&theta, &positions, segments(), Some(&tick));
        progress.finish();
        let head = format!(
            "discretisation error (Richardson, order {p} from {source}, coarse mesh {mesh})"
        );
        match coarse_pass {
            Ok((c, _)) => {
                let cf: Vec<f64> = c.iter().map(|r| r[0]).collect();
                let est = richardson(&forces, &cf, ratio, p).map_err(|e| anyhow!("{e}"))?;
                let (k, worst) = est
                    .iter()
                    .enumerate()
                    .filter_map(|(k, e)| e.relative.map(|r| (k, r)))
                    .fold(
                        (0, 0.0f64),
                        |a, (k, r)| if r.abs() > a.1.abs() { (k, r) } else { a },
                    );
                let line = format!(
                    "{head}: largest {:+.2} % at x = {} mm",
                    100.0 * worst,
                    positions[k]
                );
                eprintln!("{line}");
                comments.push(line);
                comments.push(
                    "error_estimate_N: force_N minus the estimated converged force, per position"
                        .into(),
                );
                Some(est.iter().map(|e| e.error).collect::<Vec<f64>>())
            }
            Err(e) => {
                let line = format!("{head}: not estimated, the coarse pass failed: {e}");
                eprintln!("{line}");
                comments.push(line);
                None
            }
        }
    } else {
        comments.push("discretisation error: not estimated (--error-estimate off)".into());
        None
    };
    if let Some(path) = &args.csv {
        write_pass(path, &comments, &positions, &rows, errors.as_deref())?;
    }
    if let (Some(path), Some(s)) = (&args.vtu, &sys) {
        let vtu = palpate_fe::vtu::to_vtu(s).map_err(|e| anyhow!("{e}"))?;
        write_atomic(path, vtu.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let fx: Vec<f64> = rows.iter().map(|r| r[1]).collect();
        let mut plot = Plot::new(&title, "wheel position x (mm)", "force (N)")
            .with(Series::line("vertical force", &positions, &forces))
            .with(Series::dashed("horizontal force", &positions, &fx));
        if !model.nodules.is_empty() {
            let xs: Vec<f64> = model.nodules.iter().map(|n| n.x).collect();
            let ys = vec![0.0; xs.len()];
            plot = plot.with(Series::markers("nodules (x)", &xs, &ys));
        }
        write_atomic(path, plot.to_svg().as_bytes())
            .with_context(|| format!("plot {}", path.display()))?;
    }
    if args.csv.is_none() {
        print!(
            "{}",
            pass_text(&comments, &positions, &rows, errors.as_deref())
        );
    }
    Ok(())
}

fn pass_text(comments: &[String], x: &[f64], rows: &[[f64; 2]], errors: Option<&[f64]>) -> String {
    let mut s = String::new();
    for c in comments {
        s.push_str(&format!("# {c}\n"));
    }
    s.push_str("position_mm,force_N,force_x_N");
    s.push_str(if errors.is_some() {
        ",error_estimate_N\n"
    } else {
        "\n"
    });
    for (k, (x, r)) in x.iter().zip(rows).enumerate() {
        s.push_str(&format!("{x:.6},{:.9e},{:.9e}", r[0], r[1]));
        if let Some(e) = errors {
            s.push_str(&format!(",{:.9e}", e[k]));
        }
        s.push('\n');
    }
    s
}

fn write_pass(
    path: &Path,
    comments: &[String],
    x: &[f64],
    rows: &[[f64; 2]],
    errors: Option<&[f64]>,
) -> anyhow::Result<()> {
    write_atomic(path, pass_text(comments, x, rows, errors).as_bytes())
}
