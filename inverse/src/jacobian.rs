//! Jacobians of the residual vector with respect to the free unbounded
//! parameters: finite differences in parallel over columns, or exact when
//! every data set provides [`crate::Sensitivities`].

use crate::{InverseError, Objective};
use nalgebra::DMatrix;
use palpate_core::fd::{fd_column, FdRule, FdScheme};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Finite-difference settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FdOptions {
    /// Step `h_j = relative_step * max(|z_j|, 1)` in the unbounded space
    /// (the rule of `palpate_core::fd`). Default `eps^(1/3) ~ 6e-6`, the
    /// optimum for central differences.
    pub relative_step: f64,
    /// Central (2 evaluations per column, error O(h^2)) or forward
    /// (1 per column, error O(h)) differences.
    pub central: bool,
    /// Compute columns in parallel with rayon. Each column is computed by the
    /// same arithmetic whatever the thread that runs it, so the Jacobian is
    /// bit-identical to the serial one.
    pub parallel: bool,
}

impl Default for FdOptions {
    fn default() -> Self {
        FdOptions {
            relative_step: FdRule::default().relative_step,
            central: true,
            parallel: true,
        }
    }
}

/// A Jacobian and the number of objective evaluations it cost.
#[derive(Debug, Clone)]
pub struct JacobianEval {
    /// `m x q`: d r_i / d z_j.
    pub matrix: DMatrix<f64>,
    /// Objective evaluations (each = one prediction per data set).
    pub evaluations: usize,
}

/// d r / d z at `z` (free unbounded parameters). `r0` (the residuals at `z`)
/// is needed for forward differences only. With exact sensitivities, from
/// them, or by finite differences where the run with sensitivities fails
/// (an FE run that converges, but whose differentiation inverts an element
/// at a perturbed state); the failed run counts as an evaluation.
pub fn jacobian_unbounded(
    objective: &Objective,
    z: &[f64],
    r0: Option<&[f64]>,
    options: &FdOptions,
) -> Result<JacobianEval, InverseError> {
    if objective.has_exact_sensitivities() {
        return match exact_jacobian(objective, z) {
            Err(InverseError::Forward { .. }) => {
                let mut j = finite_difference_jacobian(objective, z, r0, options)?;
                j.evaluations += 1;
                Ok(j)
            }
            done => done,
        };
    }
    finite_difference_jacobian(objective, z, r0, options)
}

/// d r / d z at `z` by finite differences of the objective, whether or not
/// the data sets have exact sensitivities.
pub fn finite_difference_jacobian(
    objective: &Objective,
    z: &[f64],
    r0: Option<&[f64]>,
    options: &FdOptions,
) -> Result<JacobianEval, InverseError> {
    if !(options.relative_step > 0.0 && options.relative_step < 1.0) {
        return Err(InverseError::InvalidOption {
            option: "relative_step",
            reason: format!("{} must lie in (0, 1)", options.relative_step),
        });
    }
    let q = z.len();
    let m = objective.n_residuals();
    let base_evaluations = usize::from(!options.central && r0.is_none());
    let owned_r0;
    let r0 = match (options.central, r0) {
        (true, _) => None,
        (false, Some(r)) => Some(r),
        (false, None) => {
            owned_r0 = objective.residuals(
                &mut objective.evaluators(),
                z,
                "finite-difference base point",
            )?;
            Some(owned_r0.as_slice())
        }
    };
    // One column and the evaluations it cost, by palpate-core's finite
    // differences (step `relative_step * max(|z_j|, 1)`, no bounds in the
    // unbounded space). When one side of a central difference fails (e.g. the
    // step leaves the law's admissible domain), the other side is used as a
    // one-sided difference.
    let rule = FdRule {
        relative_step: options.relative_step,
        scheme: if options.central {
            FdScheme::Central
        } else {
            FdScheme::Forward
        },
    };
    let column =
        |evs: &mut crate::Evaluators<'_>, j: usize| -> Result<(Vec<f64>, usize), InverseError> {
            let mut f = |zz: &[f64], out: &mut [f64]| -> Result<(), InverseError> {
                out.copy_from_slice(&objective.residuals(evs, zz, "finite-difference step")?);
                Ok(())
            };
            let mut col = vec![0.0; m];
            let n = fd_column(&mut f, z, j, rule.unbounded_step(z[j]), r0, &mut col)?;
            Ok((col, n))
        };
    let columns: Vec<(Vec<f64>, usize)> = if options.parallel {
        (0..q)
            .into_par_iter()
            .map_init(|| objective.evaluators(), column)
            .collect::<Result<_, _>>()?
    } else {
        let mut evs = objective.evaluators();
        (0..q)
            .map(|j| column(&mut evs, j))
            .collect::<Result<_, _>>()?
    };
    let evaluations = base_evaluations + columns.iter().map(|c| c.1).sum::<usize>();
    let columns: Vec<Vec<f64>> = columns.into_iter().map(|c| c.0).collect();
    let mut matrix = DMatrix::zeros(m, q);
    for (j, col) in columns.iter().enumerate() {
        matrix.column_mut(j).copy_from_slice(col);
    }
    Ok(JacobianEval {
        matrix,
        evaluations,
    })
}

/// d r / d z from the sets' exact sensitivities:
/// `d r_i / d z_j = (w s_i) * d f_i / d theta_k * dx_k / dz_j` for free `k`.
fn exact_jacobian(objective: &Objective, z: &[f64]) -> Result<JacobianEval, InverseError> {
    Ok(residuals_and_exact_jacobian(objective, z, "exact sensitivities")?.2)
}

/// Predictions (one vector per set), residuals and the exact Jacobian at
/// one point ([`residuals_and_exact_jacobian`]).
pub type ExactEvaluation = (Vec<Vec<f64>>, Vec<f64>, JacobianEval);

/// The predictions (per set) and residuals at `z` and d r / d z from the
/// sets' exact sensitivities,
/// both from one run per set ([`palpate_core::Sensitivities::predict_with_jacobian`]
/// gives the predictions with their derivatives), so that an estimator that
/// needs both at one point (Levenberg-Marquardt at an accepted trial, the
/// statistics at the optimum) pays one forward run, not two. The Jacobian
/// counts one evaluation. Errors when a set has no exact sensitivities.
pub fn residuals_and_exact_jacobian(
    objective: &Objective,
    z: &[f64],
    stage: &'static str,
) -> Result<ExactEvaluation, InverseError> {
    let theta = objective.theta_from_unbounded(z);
    let dxdz = objective.dx_dz(z);
    let mut matrix = DMatrix::zeros(objective.n_residuals(), z.len());
    let mut predictions = Vec::with_capacity(objective.sets().len());
    for (s, set) in objective.sets().iter().enumerate() {
        let Some(sens) = &set.sensitivities else {
            return Err(InverseError::InvalidOption {
                option: "sensitivities",
                reason: format!("data set `{}` has no exact sensitivities", set.name),
            });
        };
        let (pred, cols) = sens
            .predict_with_jacobian(&theta, &set.loading)
            .map_err(|source| InverseError::Forward {
                set: set.name.clone(),
                theta: theta.clone(),
                stage,
                source: Box::new(source),
            })?;
        let range = objective.residual_range(s);
        for (j, &k) in objective.free_indices().iter().enumerate() {
            for (row, &(i, f)) in range.clone().zip(objective.factors(s)) {
                matrix[(row, j)] = f * cols[k][i] * dxdz[j];
            }
        }
        predictions.push(pred);
    }
    let mut r = vec![0.0; objective.n_residuals()];
    objective.residuals_from_predictions(&predictions, &mut r);
    Ok((
        predictions,
        r,
        JacobianEval {
            matrix,
            evaluations: 1,
        },
    ))
}
