//! The hook for models that give exact sensitivities (STYLE.md 3).

use palpate_core::{ForwardError, Loading};

/// Exact derivatives of a model's predictions with respect to its physical
/// parameters. A data set that carries one (see
/// [`crate::DataSet::with_sensitivities`]) replaces finite differences; when
/// any set of an objective has none, the whole Jacobian is computed by
/// finite differences.
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
