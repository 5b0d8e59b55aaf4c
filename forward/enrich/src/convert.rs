//! Small shared helpers: material parameters as a [`ParamSpace`], and the
//! split of a wrapper's parameter vector.

use palpate_core::{ForwardError, ParamRole, ParamSpace, ParamSpec};
use palpate_material::Law;

/// The law's parameters (names, units, bounds, starting values) as a space.
pub fn law_space(law: &Law) -> ParamSpace {
    ParamSpace::new(
        law.params()
            .into_iter()
            .map(|m| {
                ParamSpec::new(m.name, m.unit, m.lower, m.upper, m.initial).with_role(
                    if m.modulus {
                        ParamRole::Modulus
                    } else {
                        ParamRole::Shape
                    },
                )
            })
            .collect(),
    )
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
