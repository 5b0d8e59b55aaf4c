//! The run of a lab's own experiment description: its parameters by
//! name, the solve, and the error estimate of a cylinder model.

use anyhow::{anyhow, bail};
use palpate_core::{ForwardModel, Loading};
use palpate_fe::experiment::ExperimentModel;

use super::{progress_bar, volumetric, Curve, SimulateOptions};
use crate::api::estimate::estimate;
use crate::api::Observer;
use crate::model::{ExperimentSpec, Model, ModelSpec};

/// The parameter values of a run: the description's starts (and fixed
/// values), each given (name, value) replacing one by name.
fn theta(model: &dyn ForwardModel, given: &[(String, f64)]) -> anyhow::Result<Vec<f64>> {
    let space = model.space();
    let mut theta: Vec<f64> = space.params.iter().map(|s| s.initial).collect();
    let names = space.names();
    for (n, v) in given {
        let (n, v) = (n.as_str(), *v);
        let g = format!("{n}={v}");
        let k = names.iter().position(|m| m == n).ok_or_else(|| {
            anyhow!(
                "--param {g}: the experiment has no parameter `{n}`; its parameters: {}",
                names.join(", ")
            )
        })?;
        if !v.is_finite() {
            bail!("--param {g}: `{v}` is not a finite number");
        }
        let s = &space.params[k];
        if !(v >= s.lower && v <= s.upper) {
            bail!(
                "--param {g}: outside {n}'s bounds [{}, {}]",
                s.lower,
                s.upper
            );
        }
        theta[k] = v;
    }
    Ok(theta)
}

/// The curve of an experiment description `arg` (and its solved system
/// when the model has one to write as a `.vtu`).
pub(super) fn experiment(
    o: &SimulateOptions,
    arg: &str,
    observer: &dyn Observer,
) -> anyhow::Result<(Curve, Option<palpate_fe::system::System>)> {
    let spec = ExperimentSpec::from_option(arg)?;
    let source = spec.source.to_string();

    let Model::Experiment(built) = ModelSpec::Experiment(spec)
        .validate()
        .map_err(|e| anyhow!("--experiment {source}: {}", e.expected))?
    else {
        bail!("--experiment {source}: not an experiment model");
    };
    if let Some(p) = o.order {
        if !(p > 0.0 && p.is_finite()) {
            bail!("--order {p}: must be a positive order of convergence");
        }
    }
    let loading: Loading = built.model.loading().ok_or_else(|| {
        anyhow!(
            "--experiment {source}: its protocol is a record's; give the record with --data, or protocol.segments (e.g. [{{ ramp_to = 2.0 }}])"
        )
    })?;
    let model = built.model;
    let theta = theta(model.as_forward(), &o.params)?;
    let title = model.as_forward().name();
    let mut comments = vec![
        format!("palpate simulate: {title}"),
        format!("experiment: {source}"),
    ];
    let (bar, mut cb) = progress_bar(loading.len(), "", observer.bars());
    #[allow(unreachable_patterns)]
    let (forces, solver, as_model) = match &model {
        ExperimentModel::Cylinder(m) => {
            let (sim, solver) = m
                .simulate(&theta, &loading, Some(&mut cb))
                .map_err(|e| anyhow!("{title}: {e}"))?;
            comments.push(format!(
                "mesh: level {}, {:?} elements ({} cells, {} unknowns)",
                m.sizing.map_or(m.mesh.level as f64, |s| s.level),
                m.element,
                solver.mesh.cell_count(),
                solver.equations()
            ));
            comments.push(format!("volumetric: {}", volumetric(m.bulk)));
            (
                sim.forces,
                Some(solver),
                Some(Model::N1Needle(m.model().clone())),
            )
        }
        other => {
            let f = other
                .as_forward()
                .predict(&theta, &loading)
                .map_err(|e| anyhow!("{title}: {e}"))?;
            (f, None, None)
        }
    };
    drop(cb);
    bar.finish_and_clear();
    for c in &comments[2..] {
        observer.message(c);
    }
    let errors = match (&as_model, o.error_estimate) {
        (_, false) => {
            comments.push("discretisation error: not estimated (--error-estimate off)".into());
            None
        }
        (Some(m), true) => {
            let est = estimate(m, &theta, &loading, o.order, &forces, observer.bars())?;
            observer.message(&est.line);
            comments.push(est.line);
            if est.errors.is_some() {
                comments.push(
                    "error_estimate_N: force_N minus the estimated converged force, per sample"
                        .into(),
                );
            }
            est.errors
        }
        (None, true) => {
            comments.push("discretisation error: no estimate for this model".into());
            None
        }
    };
    Ok((
        Curve {
            title,
            comments,
            time_s: loading.time.clone(),
            displacement_mm: loading.drive.clone(),
            force_n: forces,
            error_estimate_n: errors,
        },
        solver,
    ))
}
