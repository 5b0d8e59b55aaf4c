//! Exact parameter sensitivities: the capability of a model that gives the
//! derivatives of its predictions along with them (a finite-element model
//! by direct differentiation through its converged increments), so that
//! estimators need not difference the model. A model offers it through
//! [`crate::ForwardModel::as_sensitivities`]; estimators that find none fall
//! back to finite differences ([`crate::fd`]).

use crate::{ForwardError, Loading};

/// Exact derivatives of a model's predictions with respect to its physical
/// parameters. A data set that carries one (`palpate_inverse::DataSet::
/// with_sensitivities`) replaces finite differences; when any set of an
/// objective has none, the whole Jacobian is computed by finite differences.
pub trait Sensitivities: Send + Sync {
    /// `(predictions, columns)` at `theta`, with `columns[j][i]` =
    /// d prediction_i / d theta_j (column-major, one column per parameter
    /// of the model's space).
    fn predict_with_jacobian(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError>;
}
