//! Errors of the finite element machinery.

use thiserror::Error;

/// Why a finite element operation failed. Converted to
/// [`palpate_core::ForwardError`] at the forward-model boundary.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum FeError {
    /// A mesh description is unusable.
    #[error("mesh `{field}`: {reason}")]
    InvalidMesh { field: String, reason: String },
    /// A mesh file is unreadable or describes an unusable mesh; `line` is
    /// 1-based (0 when the fault is not tied to a line, e.g. an I/O error).
    #[error("{file}:{line}: {reason}")]
    MeshFile {
        file: String,
        line: usize,
        reason: String,
    },
    /// A rigid tool starts inside the body.
    #[error("tool `{tool}` starts inside the body at node {node} ({:.4}, {:.4}, {:.4}) mm, gap {gap:.3e} mm", at[0], at[1], at[2])]
    ToolStartsInside {
        tool: String,
        node: usize,
        at: [f64; 3],
        gap: f64,
    },
    /// An element turned inside out (det F <= 0 at a quadrature point).
    #[error("element {element} inverted (det F = {det_f:.3e})")]
    InvertedElement { element: usize, det_f: f64 },
    /// The material law returned a non-finite stress (`element` is
    /// `usize::MAX` when the residual as a whole overflowed and no single
    /// element is to blame).
    #[error("{}", non_finite_message(*element))]
    NonFiniteStress { element: usize },
    /// The sparse factorisation failed (singular tangent).
    #[error("sparse LU failed: {reason}")]
    Factorisation { reason: String },
    /// Newton did not converge within the iteration limit.
    #[error("Newton did not converge in {iterations} iterations (residual {residual:.3e}, tolerance {tolerance:.3e})")]
    NewtonFailed {
        iterations: usize,
        residual: f64,
        tolerance: f64,
    },
    /// A configuration value is invalid.
    #[error("configuration `{field}`: {reason}")]
    InvalidConfig { field: String, reason: String },
    /// A configuration file (an experiment description) is unreadable or
    /// does not describe one; `line` is 1-based (0 when the fault is not
    /// tied to a line, e.g. an I/O error).
    #[error("{file}:{line}: {reason}")]
    ConfigFile {
        file: String,
        line: usize,
        reason: String,
    },
}

impl FeError {
    /// Whether a smaller load increment might cure the failure.
    pub fn is_recoverable(&self) -> bool {
        matches!(
            self,
            FeError::InvertedElement { .. }
                | FeError::NonFiniteStress { .. }
                | FeError::Factorisation { .. }
                | FeError::NewtonFailed { .. }
        )
    }
}

/// The message of [`FeError::NonFiniteStress`]: the element, or the whole
/// residual when no element is known (never the `usize::MAX` sentinel).
fn non_finite_message(element: usize) -> String {
    if element == usize::MAX {
        "non-finite residual: the stresses or contact forces overflowed (are the material parameters or the tool displacement far outside their usual range?)".into()
    } else {
        format!("element {element}: non-finite stress")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_overflow_without_an_element_does_not_name_the_sentinel() {
        let e = FeError::NonFiniteStress {
            element: usize::MAX,
        }
        .to_string();
        assert!(
            !e.contains(&usize::MAX.to_string()) && e.contains("non-finite"),
            "{e}"
        );
        let e = FeError::NonFiniteStress { element: 7 }.to_string();
        assert_eq!(e, "element 7: non-finite stress");
    }
}
