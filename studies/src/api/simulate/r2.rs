//! The R2 scan: the wheel pressed to RD at x = 10 mm (the pressing phase)
//! and rolled to x = 140 mm (the rolled pass: vertical and horizontal
//! force per wheel position), with the discretisation error estimate of
//! the rolled force from the same pass on elements twice as large. The
//! frictionless pass is solved in two segments in parallel (the state
//! depends on the wheel position alone, `R2Rolling::rolled_pass`).

use anyhow::{anyhow, bail};
use palpate_core::{Drive, ForwardError, Loading};
use palpate_fe::discretisation::{richardson, Coarser};
use palpate_fe::{R2Rolling, System};
use palpate_material::Law;

use super::{law_params as named_params, progress_bar, volumetric, SimulateOptions};
use crate::api::Observer;
use crate::model::Model;
use crate::run::limits::Progress;

/// An R2 scan, at full precision.
#[derive(Debug, Clone)]
pub struct Scan {
    pub title: String,
    /// The lines the pressing phase's CSV starts with (model, volumetric
    /// treatment, the forces' meaning).
    pub press_comments: Vec<String>,
    /// The wheel's position during the pressing phase (mm).
    pub press_x: f64,
    /// The pressing phase: depth (mm) and the vertical and horizontal force (N).
    pub press_depth_mm: Vec<f64>,
    pub press_force_n: Vec<f64>,
    pub press_force_x_n: Vec<f64>,
    /// The lines the rolled pass's CSV starts with (those of the pressing
    /// phase, then the error estimate or where the pass stopped).
    pub comments: Vec<String>,
    /// The rolled pass: wheel position (mm), vertical force (N, positive
    /// in compression) and force along +x (N).
    pub position_mm: Vec<f64>,
    pub force_n: Vec<f64>,
    pub force_x_n: Vec<f64>,
    /// `force_N` minus the estimated converged force, per position.
    pub error_estimate_n: Option<Vec<f64>>,
    /// The nodules' centres along the block (mm).
    pub nodules_x: Vec<f64>,
}

/// A scan and the solved system at the end of its pass (for a `.vtu`).
pub struct Scanned {
    pub scan: Scan,
    pub system: Option<System>,
}

/// A rolled pass that stopped before its last position, with the scan of
/// the positions that converged (its comments say so; no error estimate).
#[derive(Debug)]
pub struct ScanNotConverged {
    pub message: String,
    pub partial: Box<Scan>,
}

impl std::fmt::Display for ScanNotConverged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for ScanNotConverged {}

/// The parameters of one law: docs/benchmarks.md's when the law is Arruda-Boyce
/// and none is given (`rtv6166-ab` or `rubber-ab`), else every one named;
/// the errors name `option`.
fn law_params(
    law: &Law,
    given: &[(String, f64)],
    default: &[f64],
    option: &str,
) -> anyhow::Result<Vec<f64>> {
    if given.is_empty() && *law == Law::ArrudaBoyce {
        return Ok(default.to_vec());
    }
    named_params(law, given).map_err(|e| anyhow!("{}", e.to_string().replace("--param", option)))
}

/// The number of parallel segments of a frictionless pass.
fn segments() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(2)
}

/// A progress report of `len` wheel positions on standard error, or none.
fn positions_progress(len: usize, label: &str, show: bool) -> Option<Progress> {
    show.then(|| {
        Progress::new(
            len as u64,
            label,
            "{bar:40} {pos}/{len} positions  {msg}  [{elapsed_precise}]",
        )
    })
}

/// Runs the R2 scan of `options` (`benchmark` R2, `rd`, the nodules, the
/// tissue's and nodules' laws); lines and progress to `observer`. A pass
/// that stops early is a [`ScanNotConverged`] error holding what converged.
pub fn scan(options: &SimulateOptions, observer: &dyn Observer) -> anyhow::Result<Scanned> {
    let model = match super::model_spec(options)?
        .validate()
        .map_err(|e| anyhow!("{}", e.as_option()))?
    {
        Model::R2(m) => m,
        _ => bail!(
            "--benchmark {}: the scan is R2's; the other benchmarks give a force curve",
            options.benchmark()
        ),
    };
    let p = R2Rolling::BENCHMARK_PARAMS;
    let mut theta = law_params(model.law(), &options.params, &p[..2], "--param")?;
    theta.extend(law_params(
        model.nodule_law(),
        &options.nodule_params,
        &p[2..],
        "--nodule-param",
    )?);
    if let Some(p) = options.order {
        if !(p > 0.0 && p.is_finite()) {
            bail!("--order {p}: must be a positive order of convergence");
        }
    }
    let step = options.step.unwrap_or(0.5);
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
    run(&model, &theta, step, options, observer)
}

fn run(
    model: &R2Rolling,
    theta: &[f64],
    step: f64,
    options: &SimulateOptions,
    observer: &dyn Observer,
) -> anyhow::Result<Scanned> {
    let show = observer.bars();
    let positions = model.pass_positions(step);
    let title = palpate_core::ForwardModel::name(model);
    let mut comments = vec![
        format!("palpate simulate: {title}"),
        format!("volumetric: {} (plane stress)", volumetric(model.bulk)),
        format!(
            "force_N: vertical force of the wheel on the {} mm thick block, positive in compression; force_x_N: its force along +x (rolling direction)",
            model.thickness
        ),
    ];
    let press_comments = comments.clone();

    // pressing phase at press_x, every 0.25 mm
    let n = (model.rd / 0.25).ceil().max(1.0) as usize;
    let depths: Vec<f64> = (1..=n).map(|k| model.rd * k as f64 / n as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths.clone());
    let (bar, mut cb) = progress_bar(depths.len(), "pressing: ", show);
    let press = model.simulate(theta, &loading, Some(&mut cb));
    drop(cb);
    bar.finish_and_clear();
    let press = match press {
        Ok((sim, _)) => sim.outputs,
        Err(e) => bail!(
            "{title}: the pressing phase at x = {} mm: {e}",
            model.press_x
        ),
    };
    observer.message(&format!(
        "pressed to {} mm at x = {} mm: F = {:.6} N",
        model.rd,
        model.press_x,
        press.last().map_or(0.0, |o| o[0])
    ));
    let press_force_n: Vec<f64> = press.iter().map(|o| o[0]).collect();
    let press_force_x_n: Vec<f64> = press.iter().map(|o| o[1]).collect();

    // the rolled pass
    let progress = positions_progress(positions.len(), "R2 rolled pass", show);
    let tick = || {
        if let Some(p) = &progress {
            p.inc(1)
        }
    };
    let t0 = std::time::Instant::now();
    let result = model.rolled_pass(theta, &positions, segments(), Some(&tick));
    if let Some(p) = &progress {
        p.finish();
    }
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
            let at = positions[sample.min(positions.len() - 1)];
            comments.push(format!(
                "did not converge at position {at} mm: partial pass, no error estimate"
            ));
            return Err(ScanNotConverged {
                message: format!(
                    "{title}: did not converge at position {at} mm after {cuts} step cuts: {reason}"
                ),
                partial: Box::new(Scan {
                    title,
                    press_comments,
                    press_x: model.press_x,
                    press_depth_mm: depths,
                    press_force_n,
                    press_force_x_n,
                    comments,
                    position_mm: positions[..done.len()].to_vec(),
                    force_n: done.iter().map(|r| r[0]).collect(),
                    force_x_n: done.iter().map(|r| r[1]).collect(),
                    error_estimate_n: None,
                    nodules_x: model.nodules.iter().map(|n| n.x).collect(),
                }),
            }
            .into());
        }
        Err(e) => bail!("{title}: {e}"),
    };
    let forces: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    observer.message(&format!(
        "{title}: {} positions in {:.1} s; peak F = {:.6} N",
        rows.len(),
        t0.elapsed().as_secs_f64(),
        forces.iter().cloned().fold(0.0, f64::max)
    ));
    if let Some(s) = &sys {
        observer.message(&format!(
            "mesh: {} nine-node elements, {} unknowns",
            s.mesh.cell_count(),
            s.equations()
        ));
    }
    let errors = if options.error_estimate {
        let (line, errors) = estimate(model, theta, &positions, &forces, options.order, show)?;
        observer.message(&line);
        comments.push(line);
        if errors.is_some() {
            comments.push(
                "error_estimate_N: force_N minus the estimated converged force, per position"
                    .into(),
            );
        }
        errors
    } else {
        comments.push("discretisation error: not estimated (--error-estimate off)".into());
        None
    };
    let scan = Scan {
        title,
        press_comments,
        press_x: model.press_x,
        press_depth_mm: depths,
        press_force_n,
        press_force_x_n,
        comments,
        position_mm: positions,
        force_x_n: rows.iter().map(|r| r[1]).collect(),
        force_n: forces,
        error_estimate_n: errors,
        nodules_x: model.nodules.iter().map(|n| n.x).collect(),
    };
    Ok(Scanned { scan, system: sys })
}

/// The error estimate of the rolled force: the same pass on elements twice
/// as large, Richardson with the model's order (or `order`); a coarse pass
/// that fails is said in the line, not an error.
fn estimate(
    model: &R2Rolling,
    theta: &[f64],
    positions: &[f64],
    forces: &[f64],
    order: Option<f64>,
    show: bool,
) -> anyhow::Result<(String, Option<Vec<f64>>)> {
    let Coarser {
        model: coarse,
        ratio,
        mesh,
    } = model.coarser();
    let documented = model.convergence_order();
    let (p, source) = match order {
        Some(p) => (p, "--order".to_string()),
        None => (documented.order, documented.source),
    };
    let progress = positions_progress(positions.len(), "coarse mesh for the error estimate", show);
    let tick = || {
        if let Some(p) = &progress {
            p.inc(1)
        }
    };
    let coarse_pass = coarse.rolled_pass(theta, positions, segments(), Some(&tick));
    if let Some(p) = &progress {
        p.finish();
    }
    let head =
        format!("discretisation error (Richardson, order {p} from {source}, coarse mesh {mesh})");
    Ok(match coarse_pass {
        Ok((c, _)) => {
            let cf: Vec<f64> = c.iter().map(|r| r[0]).collect();
            let est = richardson(forces, &cf, ratio, p).map_err(|e| anyhow!("{e}"))?;
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
            (line, Some(est.iter().map(|e| e.error).collect()))
        }
        Err(e) => (
            format!("{head}: not estimated, the coarse pass failed: {e}"),
            None,
        ),
    })
}

/// The rolled pass as the CSV of `palpate simulate --benchmark R2` writes
/// it (`position_mm,force_N,force_x_N[,error_estimate_N]`).
pub fn pass_text(
    comments: &[String],
    x: &[f64],
    fz: &[f64],
    fx: &[f64],
    errors: Option<&[f64]>,
) -> String {
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
    for k in 0..x.len() {
        s.push_str(&format!("{:.6},{:.9e},{:.9e}", x[k], fz[k], fx[k]));
        if let Some(e) = errors {
            s.push_str(&format!(",{:.9e}", e[k]));
        }
        s.push('\n');
    }
    s
}

/// The pressing phase as the CSV `OUT.press.csv` holds it.
pub fn press_text(comments: &[String], press_x: f64, d: &[f64], fz: &[f64], fx: &[f64]) -> String {
    let mut s = String::new();
    for c in comments {
        s.push_str(&format!("# {c}\n"));
    }
    s.push_str(&format!(
        "# pressing phase: wheel at x = {press_x} mm\ndisplacement_mm,force_N,force_x_N\n0.000000,0,0\n"
    ));
    for k in 0..d.len() {
        s.push_str(&format!("{:.6},{:.9e},{:.9e}\n", d[k], fz[k], fx[k]));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::Silent;

    #[test]
    fn options_are_checked_before_any_solve() {
        let e = |o: SimulateOptions| scan(&o, &Silent).err().unwrap().to_string();
        let r2 = SimulateOptions {
            benchmark: Some("R2".into()),
            rd: Some(1.0),
            ..Default::default()
        };
        let m = e(SimulateOptions {
            rd: None,
            ..r2.clone()
        });
        assert!(m.starts_with("--benchmark R2 needs --rd"), "{m}");
        let m = e(SimulateOptions {
            step: Some(0.0),
            ..r2.clone()
        });
        assert!(m.starts_with("--step 0: must be a positive spacing"), "{m}");
        let m = e(SimulateOptions {
            nodule_params: vec![("mu".into(), 0.07)],
            ..r2.clone()
        });
        assert!(m.starts_with("missing --nodule-param for lambda_m"), "{m}");
        let m = e(SimulateOptions {
            benchmark: Some("C1".into()),
            law: Some("neo-hookean".into()),
            rd: None,
            ..r2
        });
        assert!(m.contains("the scan is R2's"), "{m}");
    }

    /// The scan of a nodule-free block at RD 1 mm, three wheel positions:
    /// the forces `palpate simulate --benchmark R2 --rd 1 --nodules none
    /// --step 65 --error-estimate off` wrote before the scan moved into the
    /// library (to its CSV's 10 digits).
    #[test]
    #[ignore = "three R2 positions: about 30 s of CPU; cargo test -p palpate-studies --lib api::simulate::r2 -- --ignored"]
    fn a_short_scan_gives_the_command_lines_forces() {
        let o = SimulateOptions {
            benchmark: Some("R2".into()),
            rd: Some(1.0),
            nodules: Some("none".into()),
            step: Some(65.0),
            ..Default::default()
        };
        let s = scan(&o, &Silent).unwrap().scan;
        assert_eq!(s.position_mm, [10.0, 75.0, 140.0]);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-3);
        for (f, want) in s
            .force_n
            .iter()
            .zip([8.445524130e-1, 9.686254227e-1, 8.445524130e-1])
        {
            assert!(close(*f, want), "{f} vs {want}");
        }
        assert!(
            close(s.press_force_n[3], 8.445523794e-1),
            "{:?}",
            s.press_force_n
        );
        assert!(s.error_estimate_n.is_none() && s.nodules_x.is_empty());
    }

    #[test]
    fn the_texts_are_the_csv_files() {
        let c = vec!["palpate simulate: R2".to_string()];
        let pass = pass_text(
            &c,
            &[10.0, 75.0],
            &[0.5, 0.75],
            &[0.01, -0.01],
            Some(&[1e-3, 2e-3]),
        );
        assert_eq!(
            pass,
            "# palpate simulate: R2\nposition_mm,force_N,force_x_N,error_estimate_N\n\
             10.000000,5.000000000e-1,1.000000000e-2,1.000000000e-3\n\
             75.000000,7.500000000e-1,-1.000000000e-2,2.000000000e-3\n"
        );
        let press = press_text(&c, 10.0, &[0.5], &[0.25], &[0.0]);
        assert_eq!(
            press,
            "# palpate simulate: R2\n# pressing phase: wheel at x = 10 mm\n\
             displacement_mm,force_N,force_x_N\n0.000000,0,0\n0.500000,2.500000000e-1,0.000000000e0\n"
        );
    }
}
