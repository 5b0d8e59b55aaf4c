//! The numbering of unknowns, built from the boundary conditions.
//!
//! The global state is one vector: the node displacements (`dim` per node,
//! index `node * dim + c`), then the unknowns that contributions own (the
//! pressure multipliers of exactly incompressible bodies), each block at the
//! offset it was given. A prescribed entry has no equation; every other
//! entry has one, in state order.

use serde::{Deserialize, Serialize};

use crate::mesh::Mesh;
use crate::sparse::NONE;
use crate::FeError;

/// What a prescribed displacement component follows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DofValue {
    /// Held at zero.
    Fixed,
    /// `u = scale * value of loading channel `channel``.
    Channel { channel: usize, scale: f64 },
}

/// A displacement boundary condition: component `component` of every node
/// of node set `nodes`. A symmetry plane is `Fixed` on its normal component.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dirichlet {
    pub nodes: String,
    pub component: usize,
    pub value: DofValue,
}

impl Dirichlet {
    /// Component `component` of the nodes of `nodes` held at zero.
    pub fn fixed(nodes: &str, component: usize) -> Self {
        Dirichlet {
            nodes: nodes.into(),
            component,
            value: DofValue::Fixed,
        }
    }

    /// Component `component` of the nodes of `nodes` driven by a channel.
    pub fn driven(nodes: &str, component: usize, channel: usize, scale: f64) -> Self {
        Dirichlet {
            nodes: nodes.into(),
            component,
            value: DofValue::Channel { channel, scale },
        }
    }
}

/// The map from state entries to equations.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    /// Displacement components per node.
    pub dim: usize,
    /// Number of nodes.
    pub nodes: usize,
    /// Equation of each state entry, or [`NONE`] when prescribed.
    eq: Vec<usize>,
    /// Number of equations.
    pub equations: usize,
    /// The prescribed entries and what they follow, in the order given.
    pub prescribed: Vec<(usize, DofValue)>,
}

impl DofMap {
    /// Numbering for `mesh` with `dim` components per node, `extra`
    /// contribution-owned unknowns after the node displacements, and the
    /// conditions `bcs`. Errors name the condition: an unknown node set, a
    /// component out of range, a channel index not below `channels`, or the
    /// same component prescribed two different ways.
    pub fn new(
        mesh: &Mesh,
        dim: usize,
        extra: usize,
        bcs: &[Dirichlet],
        channels: usize,
    ) -> Result<DofMap, FeError> {
        let nn = mesh.nodes.len();
        let n = nn * dim + extra;
        let mut how: Vec<Option<DofValue>> = vec![None; nn * dim];
        let mut prescribed = Vec::new();
        for (i, bc) in bcs.iter().enumerate() {
            let field = format!("boundary condition {i} (node set `{}`)", bc.nodes);
            let bad = |reason: String| FeError::InvalidConfig {
                field: field.clone(),
                reason,
            };
            if bc.component >= dim {
                return Err(bad(format!(
                    "component {} does not exist with {dim} per node",
                    bc.component
                )));
            }
            if let DofValue::Channel { channel, scale } = bc.value {
                if channel >= channels {
                    return Err(bad(format!(
                        "loading channel {channel} does not exist ({channels} channels)"
                    )));
                }
                if !scale.is_finite() {
                    return Err(bad(format!("scale {scale} is not finite")));
                }
            }
            for &node in mesh.node_set(&bc.nodes)? {
                let k = node * dim + bc.component;
                match how[k] {
                    None => {
                        how[k] = Some(bc.value);
                        prescribed.push((k, bc.value));
                    }
                    Some(v) if v == bc.value => {}
                    Some(v) => {
                        return Err(bad(format!(
                            "node {node} component {} is already {v:?}",
                            bc.component
                        )))
                    }
                }
            }
        }
        let mut eq = vec![0; n];
        let mut equations = 0;
        for (k, e) in eq.iter_mut().enumerate() {
            if k < nn * dim && how[k].is_some() {
                *e = NONE;
            } else {
                *e = equations;
                equations += 1;
            }
        }
        Ok(DofMap {
            dim,
            nodes: nn,
            eq,
            equations,
            prescribed,
        })
    }

    /// Length of the state vector.
    pub fn len(&self) -> usize {
        self.eq.len()
    }

    /// True when there is no state.
    pub fn is_empty(&self) -> bool {
        self.eq.is_empty()
    }

    /// Equation of state entry `k`, or [`NONE`].
    #[inline]
    pub fn equation(&self, k: usize) -> usize {
        self.eq[k]
    }

    /// Whether a channel drives some condition.
    pub fn uses_channel(&self, channel: usize) -> bool {
        self.prescribed
            .iter()
            .any(|(_, v)| matches!(v, DofValue::Channel { channel: c, .. } if *c == channel))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Grading;

    #[test]
    fn numbering_skips_prescribed_and_names_bad_conditions() {
        let m =
            Mesh::graded_rectangle(2.0, 1.0, Grading::uniform(2.0, 2), Grading::uniform(1.0, 1))
                .unwrap();
        let bcs = [
            Dirichlet::fixed("axis", 0),
            Dirichlet::fixed("bottom", 1),
            Dirichlet::fixed("bottom", 0),
            Dirichlet::driven("top", 1, 0, -1.0),
        ];
        let d = DofMap::new(&m, 2, 3, &bcs, 1).unwrap();
        // 6 nodes x 2 + 3 = 15 entries; prescribed: axis x (2), bottom x,y (3 + 3, one shared), top y (3)
        assert_eq!(d.len(), 15);
        assert_eq!(d.prescribed.len(), 2 + 3 + 2 + 3);
        assert_eq!(d.equations, 15 - d.prescribed.len());
        assert_eq!(d.equation(12), d.equations - 3);
        assert!(d.uses_channel(0));
        let e = DofMap::new(&m, 2, 0, &[Dirichlet::fixed("nope", 0)], 1).unwrap_err();
        assert!(e.to_string().contains("nope"), "{e}");
        let e = DofMap::new(&m, 2, 0, &[Dirichlet::driven("top", 1, 3, 1.0)], 1).unwrap_err();
        assert!(e.to_string().contains("channel 3"), "{e}");
        let e = DofMap::new(
            &m,
            2,
            0,
            &[
                Dirichlet::fixed("top", 1),
                Dirichlet::driven("top", 1, 0, 1.0),
            ],
            1,
        )
        .unwrap_err();
        assert!(e.to_string().contains("already"), "{e}");
        assert!(DofMap::new(&m, 2, 0, &[Dirichlet::fixed("top", 2)], 1).is_err());
    }
}
