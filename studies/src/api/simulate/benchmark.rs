//! The FE run of a benchmark (N1, N3, C1, Q1): its loading (depth, step,
//! the ramp-and-hold of a timed run), the mesh chosen for an accuracy, the
//! solve with its progress, and the error estimate.

use anyhow::{anyhow, bail};
use indicatif::ProgressBar;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::Simulation;
use palpate_material::Law;

use super::{law_params, progress_bar, volumetric, Curve, NotConverged, SimulateOptions};
use crate::api::estimate::estimate;
use crate::api::Observer;
use crate::model::{Model, Q1_STOP_HINT};

/// `--accuracy`: the N1 or N3 model at the level of its mesh family that
/// meets the target (`palpate_fe::accuracy::choose`, cached in the user's
/// cache directory), and the line stating it.
fn choose_mesh(
    o: &SimulateOptions,
    model: &Model,
    target: f64,
    theta: &[f64],
    loading: &Loading,
    observer: &dyn Observer,
) -> anyhow::Result<(Model, String)> {
    use palpate_fe::accuracy::{choose, AccuracyOptions, Refinable};
    if let Some(mesh) = &o.mesh {
        bail!(
            "--accuracy {target} with --mesh {mesh}: --accuracy chooses the mesh; give one of them"
        );
    }
    let mut opts = AccuracyOptions::new(target);
    opts.cache_dir = crate::run::surrogate::mesh_cache_dir();
    let bar = if observer.bars() {
        ProgressBar::new_spinner()
    } else {
        ProgressBar::hidden()
    };
    bar.set_message(format!(
        "choosing the mesh for {} % accuracy",
        100.0 * target
    ));
    let result = match model {
        Model::N1Needle(m) => choose(m, loading, &opts, |m, l| m.predict(theta, l))
            .map(|c| (Model::N1Needle(m.at_level(c.level)), c)),
        Model::N3Needle(m) => choose(m, loading, &opts, |m, l| m.predict(theta, l))
            .map(|c| (Model::N3Needle(m.at_level(c.level)), c)),
        _ => bail!(
            "--accuracy: N1 and N3 choose their mesh for an accuracy; --benchmark {} takes --mesh",
            o.benchmark()
        ),
    };
    bar.finish_and_clear();
    let (m, choice) = result.map_err(|e| anyhow!("--accuracy {target}: {e}"))?;
    let line = choice.line();
    observer.message(&line);
    Ok((m, line))
}

/// The sample times of a viscoelastic (`--prony`) run or of any Q1 run
/// (ramp-and-hold, docs/benchmarks.md): the drive samples spread over `--ramp`
/// seconds, then `--hold` seconds at `depth` in 200 samples appended to
/// `drive`; `None` for an elastic C1 or N1 run.
fn timed_history(
    o: &SimulateOptions,
    depth: f64,
    drive: &mut Vec<f64>,
) -> anyhow::Result<Option<Vec<f64>>> {
    let q1 = o.is_q1();
    if o.prony.is_none() && !q1 {
        if o.ramp.is_some() || o.hold.is_some() {
            bail!("--ramp and --hold time a viscoelastic run: they need --prony");
        }
        return Ok(None);
    }
    if !(o.benchmark().eq_ignore_ascii_case("c1") || o.benchmark().eq_ignore_ascii_case("n1") || q1)
    {
        bail!("--prony: only N1, C1 and Q1 have the viscoelastic material so far");
    }
    // N1: the needle's 0.4 mm/s (docs/benchmarks.md), C1: 1 s, Q1: 0.5 s
    let ramp = o.ramp.unwrap_or(if q1 {
        0.5
    } else if o.benchmark().eq_ignore_ascii_case("n1") {
        depth / 0.4
    } else {
        1.0
    });
    let hold = o.hold.unwrap_or(if q1 { 60.0 } else { 0.0 });
    if !(ramp > 0.0 && ramp.is_finite()) {
        bail!("--ramp {ramp}: must be a positive duration in s");
    }
    if !(hold >= 0.0 && hold.is_finite()) {
        bail!("--hold {hold}: must be a duration in s, zero or more");
    }
    // one ramp sample lasts ramp x step / depth: a shorter hold is a typo
    let one_step = ramp * (drive.get(1).copied().unwrap_or(depth)) / depth;
    if hold > 0.0 && hold < one_step {
        bail!(
            "--hold {hold}: shorter than one step of the ramp ({one_step} s); give 0 for no hold or at least {one_step} s"
        );
    }
    let mut time: Vec<f64> = drive.iter().map(|d| ramp * d / depth).collect();
    if hold > 0.0 {
        const HOLD_SAMPLES: usize = 200;
        for k in 1..=HOLD_SAMPLES {
            time.push(ramp + hold * k as f64 / HOLD_SAMPLES as f64);
            drive.push(depth);
        }
    }
    Ok(Some(time))
}

/// The FE run of `palpate simulate` for a validated N1, N3, C1 or Q1 model:
/// its curve and the solved system (for `--vtu`).
pub(super) fn compute(
    o: &SimulateOptions,
    model: Model,
    observer: &dyn Observer,
) -> anyhow::Result<(Curve, palpate_fe::system::System)> {
    let law_text = o.law.clone().unwrap_or_default();
    let law: Law = law_text
        .parse()
        .map_err(|e| anyhow!("--law `{law_text}`: {e}"))?;
    let theta = law_params(&law, &o.params)?;
    // needle benchmarks (N1, N3): 10 mm every 0.25 mm
    let n1 = o.benchmark().eq_ignore_ascii_case("n1") || o.benchmark().eq_ignore_ascii_case("n3");
    let q1 = o.is_q1();
    let depth = o.depth.unwrap_or(if n1 {
        10.0
    } else if q1 {
        5.0
    } else {
        2.0
    });
    // Q1: at least 100 samples in the ramp (docs/benchmarks.md)
    let step = o.step.unwrap_or(if n1 {
        0.25
    } else if q1 {
        depth / 100.0
    } else {
        0.1
    });
    if !(depth > 0.0 && depth.is_finite() && step > 0.0 && step.is_finite()) {
        bail!("--depth and --step must be positive (got {depth} and {step})");
    }
    if let Some(p) = o.order {
        if !(p > 0.0 && p.is_finite()) {
            bail!("--order {p}: must be a positive order of convergence");
        }
    }
    // Each sample keeps its drive, time, force and estimate, and a solve.
    let n = crate::run::limits::check_count(
        &format!(
            "--depth {} / --step {}",
            crate::run::limits::fmt_value(depth),
            crate::run::limits::fmt_value(step)
        ),
        (depth / step).ceil() + 1.0,
        "samples",
        256.0,
    )? - 1;
    crate::run::checks::check_travel("--depth", depth, &model)?;
    crate::run::checks::check_tool(
        &format!("--tool {}", o.tool.as_deref().unwrap_or("needle")),
        &model,
    )?;
    let mut drive: Vec<f64> = (0..=n).map(|k| (k as f64 * step).min(depth)).collect();
    let time = timed_history(o, depth, &mut drive)?;
    if let Some(end) = time.as_ref().and_then(|t| t.last()) {
        crate::run::checks::check_increments(&model, *end)?;
    }
    let loading = match &time {
        Some(t) => Loading::timed(Drive::DisplacementMm, t.clone(), drive.clone()),
        None => Loading::quasi_static(Drive::DisplacementMm, drive.clone()),
    };

    let chosen = match o.accuracy {
        Some(target) => Some(choose_mesh(o, &model, target, &theta, &loading, observer)?),
        None => None,
    };
    let (model, chosen_line) = match chosen {
        Some((m, line)) => (m, Some(line)),
        None => (model, None),
    };

    let (bar, mut cb) = progress_bar(drive.len(), "", observer.bars());
    let (title, bulk, result) = match &model {
        Model::N1Needle(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        Model::N3Needle(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        Model::C1Fe(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        Model::Q1(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        _ => bail!("--benchmark {}: expected N1, N3, C1 or Q1", o.benchmark()),
    };
    drop(cb);
    bar.finish_and_clear();
    let mut comments = vec![
        format!("palpate simulate: {title}"),
        format!("volumetric: {}", volumetric(bulk)),
    ];
    comments.extend(chosen_line);
    let (sim, solver): (Simulation, _) = match result {
        Ok(r) => r,
        Err(palpate_core::ForwardError::NotConverged {
            sample,
            drive: d,
            cuts,
            reason,
            completed,
        }) => {
            comments.push(format!(
                "did not converge at sample {sample} (drive {d} mm): partial curve, no error estimate"
            ));
            let hint = if o.is_q1() && d > 0.0 {
                format!("\nhint: {Q1_STOP_HINT}")
            } else {
                String::new()
            };
            let k = completed.len();
            return Err(NotConverged {
                message: format!("{title}: did not converge at sample {sample} (drive {d} mm) after {cuts} step cuts: {reason}{hint}"),
                partial: Curve {
                    title: title.to_string(),
                    comments,
                    time_s: time.as_ref().map(|t| t[..k].to_vec()),
                    displacement_mm: drive[..k].to_vec(),
                    force_n: completed,
                    error_estimate_n: None,
                },
            }
            .into());
        }
        Err(e) => bail!("{title}: {e}"),
    };
    observer.message(&format!(
        "{title}: {} elements, {} unknowns, {} increments, {} Newton iterations ({} factorisations), F({depth} mm) = {:.6} N",
        solver.mesh.cell_count(),
        solver.equations(),
        sim.stats.increments,
        sim.stats.iterations,
        sim.stats.factorisations,
        sim.forces.last().copied().unwrap_or(0.0)
    ));
    if sim.stats.loose > 0 {
        observer.message(&format!(
            "warning: {} increments were accepted at the looser stagnation tolerance (SolverOptions::stagnation_tolerance), not the full one",
            sim.stats.loose
        ));
    }
    observer.message(&format!("volumetric: {}", volumetric(bulk)));
    let errors = if o.error_estimate {
        let est = estimate(
            &model,
            &theta,
            &loading,
            o.order,
            &sim.forces,
            observer.bars(),
        )?;
        observer.message(&est.line);
        comments.push(est.line);
        if est.errors.is_some() {
            comments.push(
                "error_estimate_N: force_N minus the estimated converged force, per sample".into(),
            );
        }
        est.errors
    } else {
        comments.push("discretisation error: not estimated (--error-estimate off)".into());
        None
    };
    Ok((
        Curve {
            title: title.to_string(),
            comments,
            time_s: time,
            displacement_mm: drive,
            force_n: sim.forces,
            error_estimate_n: errors,
        },
        solver,
    ))
}
