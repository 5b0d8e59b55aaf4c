//! Small shared helpers: material parameters as a [`ParamSpace`], checks of
//! parameters and loading histories that return [`ForwardError`]s.

use palpate_core::{Drive, ForwardError, Loading, ParamSpace};
pub(crate) use palpate_enrich::law_space;
use palpate_material::Law;

/// Bounds of the space, then the law's own sign rules.
pub(crate) fn check_law_params(
    law: &Law,
    space: &ParamSpace,
    theta: &[f64],
) -> Result<(), ForwardError> {
    space.check(theta)?;
    law.check(theta)
        .map_err(|e| ForwardError::InvalidParameter {
            name: law.to_string(),
            value: f64::NAN,
            reason: e.to_string(),
        })
}

/// Loading checks shared by every model: kind of drive, lengths, finiteness.
pub(crate) fn check_loading(
    loading: &Loading,
    kind: Drive,
    out_len: usize,
) -> Result<(), ForwardError> {
    if loading.drive_kind != kind {
        return Err(ForwardError::InvalidLoading(format!(
            "expected drive `{}`, got `{}`",
            kind.column(),
            loading.drive_kind.column()
        )));
    }
    if out_len != loading.len() {
        return Err(ForwardError::InvalidLoading(format!(
            "output has {out_len} slots for {} samples",
            loading.len()
        )));
    }
    loading.validate().map_err(ForwardError::InvalidLoading)
}

/// Checks the parameter count of a wrapper and splits `theta` into the
/// wrapped model's part and the wrapper's own part.
pub(crate) fn split<'a>(
    theta: &'a [f64],
    space: &ParamSpace,
    own: usize,
) -> Result<(&'a [f64], &'a [f64]), ForwardError> {
    space.check(theta)?;
    Ok(theta.split_at(theta.len() - own))
}
