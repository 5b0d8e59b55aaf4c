//! The discretisation error estimate of a simulation ([`super::simulate`]): the model's
//! coarser companion solved once more and Richardson extrapolation with
//! the model's documented order of convergence
//! (`palpate_fe::discretisation`), as one line for the user and, when the
//! coarse solve covered every sample, an error per sample.

use anyhow::{anyhow, bail};
use palpate_core::Loading;
use palpate_fe::discretisation::{richardson, Coarser};

use super::simulate::progress_bar;
use crate::model::Model;

/// The discretisation error estimate: one line for the user and, when the
/// coarse solve covered every sample, the error per sample.
pub(crate) struct Estimate {
    pub line: String,
    pub errors: Option<Vec<f64>>,
}

/// Solves the model's coarser companion and extrapolates (Richardson).
/// Progress bars when `show`. A coarse solve that fails is reported in the line, not as an error: the
/// fine curve stands on its own.
pub(crate) fn estimate(
    model: &Model,
    theta: &[f64],
    loading: &Loading,
    order: Option<f64>,
    fine: &[f64],
    show: bool,
) -> anyhow::Result<Estimate> {
    if let (Model::N1Needle(m), None) = (model, order) {
        if let Some((levels, run)) = m.own_levels() {
            return own_levels(m, levels, run, theta, loading, fine, show);
        }
    }
    let (bar, mut cb) = progress_bar(loading.len(), "coarse mesh for the error estimate: ", show);
    // (element-size ratio, coarse mesh, documented order, coarse result)
    let (ratio, mesh, documented, result) = match model {
        Model::N1Needle(m) => {
            let Coarser { model, ratio, mesh } = m.coarser();
            let r = model.simulate(theta, loading, Some(&mut cb));
            (ratio, mesh, m.convergence_order(), r)
        }
        Model::N3Needle(m) => {
            let Coarser { model, ratio, mesh } = m.coarser();
            let r = model.simulate(theta, loading, Some(&mut cb));
            (ratio, mesh, m.convergence_order(), r)
        }
        Model::C1Fe(m) => {
            let Coarser { model, ratio, mesh } = m
                .coarser()
                .map_err(|e| anyhow!("--error-estimate: {e} (use --error-estimate off)"))?;
            let r = model.simulate(theta, loading, Some(&mut cb));
            (ratio, mesh, m.convergence_order(), r)
        }
        Model::Q1(m) => {
            let Coarser { model, ratio, mesh } = m.coarser();
            let r = model.simulate(theta, loading, Some(&mut cb));
            (ratio, mesh, m.convergence_order(), r)
        }
        _ => bail!("no error estimate for this model"),
    };
    drop(cb);
    bar.finish_and_clear();
    let (p, source) = match order {
        Some(p) => (p, "--order".to_string()),
        None => (documented.order, documented.source),
    };
    let head =
        format!("discretisation error (Richardson, order {p} from {source}, coarse mesh {mesh})");
    let (coarse, stopped) = match result {
        Ok((sim, _)) => (sim.forces, None),
        Err(palpate_core::ForwardError::NotConverged {
            drive, completed, ..
        }) => (
            completed,
            Some(format!("the coarse solve stopped at {drive} mm")),
        ),
        Err(e) => {
            return Ok(Estimate {
                line: format!("{head}: not estimated, the coarse solve failed: {e}"),
                errors: None,
            })
        }
    };
    let est = richardson(fine, &coarse, ratio, p).map_err(|e| anyhow!("{e}"))?;
    let Some(k) = est.len().checked_sub(1).filter(|&k| k > 0) else {
        return Ok(Estimate {
            line: format!(
                "{head}: not estimated, {}",
                stopped.unwrap_or_else(|| "no samples".into())
            ),
            errors: None,
        });
    };
    let e = est[k];
    let d = loading.drive[k];
    let at = match e.relative {
        _ if e.error == 0.0 => format!("0 at {d} mm (the two meshes agree to round-off)"),
        Some(r) => format!("{:+.2} % at {d} mm", 100.0 * r),
        None => format!("{:+.3e} N at {d} mm", e.error),
    };
    let mut line = format!(
        "{head}: {at} (estimated converged force {:.6} N)",
        e.converged
    );
    if let Some(s) = stopped {
        line.push_str(&format!("; {s}, no estimate beyond"));
    }
    let errors = (est.len() == fine.len()).then(|| est.iter().map(|e| e.error).collect());
    Ok(Estimate { line, errors })
}

/// The estimate of a model with its own levels
/// (`palpate_fe::cylinder::Cylinder::own_levels`, a cylinder between
/// platens): the other two levels solved, the error per sample from the
/// three (`palpate_fe::accuracy::from_levels`).
fn own_levels(
    m: &palpate_fe::N1Needle,
    levels: [f64; 3],
    run: usize,
    theta: &[f64],
    loading: &Loading,
    fine: &[f64],
    show: bool,
) -> anyhow::Result<Estimate> {
    let mut forces: [Vec<f64>; 3] = Default::default();
    for (i, &level) in levels.iter().enumerate() {
        if i == run {
            forces[i] = fine.to_vec();
            continue;
        }
        let (bar, mut cb) = progress_bar(
            loading.len(),
            &format!("mesh level {level} for the error estimate: "),
            show,
        );
        let r = m.with_level(level).simulate(theta, loading, Some(&mut cb));
        drop(cb);
        bar.finish_and_clear();
        forces[i] = match r {
            Ok((sim, _)) => sim.forces,
            Err(palpate_core::ForwardError::NotConverged { completed, .. }) => completed,
            Err(e) => {
                return Ok(Estimate {
                    line: format!(
                        "discretisation error: not estimated, the solve at mesh level {level} failed: {e}"
                    ),
                    errors: None,
                })
            }
        };
    }
    let errors = palpate_fe::accuracy::from_levels([&forces[0], &forces[1], &forces[2]], run)
        .map_err(|e| anyhow!("{e}"))?;
    let line = palpate_fe::accuracy::levels_line(levels, &loading.drive, fine, &errors);
    let per_sample = (errors.len() == fine.len()).then(|| errors.iter().map(|e| e.error).collect());
    Ok(Estimate {
        line,
        errors: per_sample,
    })
}
