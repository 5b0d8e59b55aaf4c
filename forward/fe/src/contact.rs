//! Contact of a body's surface with a rigid analytic tool, with Coulomb
//! friction, enforced at contact points: the surface nodes (tributary areas)
//! or the two Gauss points of every surface edge (the force shared by the
//! edge's nodes through the shape functions, so straight edges cannot cut
//! through a curved tool between nodes).
//!
//! Normal: augmented Lagrangian (Alart & Curnier 1991; Simo & Laursen 1992),
//! `t_N = max(0, lambda + eps_N A (-g))`. The multiplier `lambda` takes the
//! converged normal force at every commit (one Uzawa update per increment),
//! and [`ContactSet::augment`] can update it between Newton solves of one
//! increment until the penetration is below a tolerance.
//! Tangential: elastic-predictor / plastic-corrector return map
//! (Wriggers, *Computational Contact Mechanics*, 2006, 5.2.3): trial
//! `t_T = -eps_T A (xi - xi_stick)`; slip when `|t_T| > mu t_N`, then
//! `t_T = -mu t_N sign(xi - xi_stick)` and the stick point moves.
//! `A` is the point's area (360 degrees), `xi` the arc length of its
//! closest point on the tool profile; the tangent `d f / d x` is exact and
//! unsymmetric in slip.
//!
//! History (stick point, multiplier, position) follows a trial/commit
//! protocol: [`ContactSet::evaluate`] only reads the committed state and
//! writes the trial state; [`ContactSet::commit`] accepts it.

use crate::kinematics::Kinematics;
use crate::mesh2d::Mesh;
use crate::tool::ToolShape;
use crate::FeError;

/// A rigid tool moving along `direction` from `origin` (tool-local origin at
/// travel 0), in the global (r, z) frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidTool {
    pub shape: ToolShape,
    pub origin: [f64; 2],
    /// Unit travel direction (e.g. `[0, -1]`: pressing down).
    pub direction: [f64; 2],
}

impl RigidTool {
    /// Tool-local coordinates of a global point at tool travel `travel`.
    pub fn local(&self, x: [f64; 2], travel: f64) -> [f64; 2] {
        [
            x[0] - self.origin[0] - travel * self.direction[0],
            x[1] - self.origin[1] - travel * self.direction[1],
        ]
    }
}

/// Contact options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactOptions {
    /// Coulomb friction coefficient (0 = frictionless).
    pub friction: f64,
    /// Normal penalty per unit area (MPa/mm).
    pub penalty_normal: f64,
    /// Tangential (stick) penalty per unit area (MPa/mm).
    pub penalty_tangent: f64,
    /// Accepted penetration (mm) after augmentation.
    pub penetration_tol: f64,
    /// Where the contact conditions are enforced.
    pub points: ContactPoints,
}

/// Where the contact conditions are enforced on the body's surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactPoints {
    /// At the surface nodes, with their tributary areas (node-to-surface).
    #[default]
    Nodes,
    /// At the two Gauss points of every surface edge, the force shared by
    /// the edge's nodes through the shape functions (a surface-to-rigid
    /// integration: edges cannot cut through a curved tool between nodes).
    EdgeGauss,
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct NodeHistory {
    /// Stick point (arc length on the tool), when in contact.
    stick: Option<f64>,
    /// Augmented normal multiplier (N).
    lambda: f64,
    /// Position at the last commit.
    pos: [f64; 2],
    /// Normal force (N) of the last evaluation.
    normal_force: f64,
    /// Gap of the last evaluation (mm).
    gap: f64,
}

/// A contact point on the surface: `x = w0 x[n0] + w1 x[n1]` with
/// reference area `area` (360 degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    pub nodes: [usize; 2],
    pub weights: [f64; 2],
    pub area: f64,
}

impl ContactPoint {
    fn position(&self, x: &[[f64; 2]]) -> [f64; 2] {
        let [a, b] = self.nodes;
        let [wa, wb] = self.weights;
        [wa * x[a][0] + wb * x[b][0], wa * x[a][1] + wb * x[b][1]]
    }
}

/// Contribution of one contact point: force on the body at the point and
/// `d force / d x_point`; node `nodes[k]` receives `weights[k] * force` and
/// the stiffness block `(k, l)` is `weights[k] weights[l] stiffness`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NodeContact {
    pub nodes: [usize; 2],
    pub weights: [f64; 2],
    pub force: [f64; 2],
    pub stiffness: [[f64; 2]; 2],
}

/// A rigid tool and the body nodes that may touch it.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSet {
    pub name: String,
    pub tool: RigidTool,
    /// Contact points (surface nodes or edge Gauss points).
    pub points: Vec<ContactPoint>,
    pub options: ContactOptions,
    committed: Vec<NodeHistory>,
    trial: Vec<NodeHistory>,
    committed_travel: f64,
}

impl ContactSet {
    /// Contact between `tool` and the nodes of edge set `edges` of `mesh`.
    pub fn new(
        name: &str,
        tool: RigidTool,
        mesh: &Mesh,
        edges: &str,
        kin: Kinematics,
        options: ContactOptions,
    ) -> Result<ContactSet, FeError> {
        tool.shape
            .check()
            .map_err(|reason| FeError::InvalidConfig {
                field: format!("tool `{name}`"),
                reason,
            })?;
        let mut points = Vec::new();
        match options.points {
            ContactPoints::Nodes => {
                let mut area = std::collections::BTreeMap::<usize, f64>::new();
                for &[a, b] in mesh.edge_set(edges)? {
                    let (pa, pb) = (mesh.nodes[a], mesh.nodes[b]);
                    let len = ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2)).sqrt();
                    // integral of N_a times the volume factor along the edge (linear in r)
                    let (fa, fb) = (kin.volume_factor(pa[0]), kin.volume_factor(pb[0]));
                    *area.entry(a).or_default() += len * (2.0 * fa + fb) / 6.0;
                    *area.entry(b).or_default() += len * (fa + 2.0 * fb) / 6.0;
                }
                points.extend(area.into_iter().map(|(n, a)| ContactPoint {
                    nodes: [n, n],
                    weights: [1.0, 0.0],
                    area: a,
                }));
            }
            ContactPoints::EdgeGauss => {
                let g = 1.0 / 3f64.sqrt();
                for &[a, b] in mesh.edge_set(edges)? {
                    let (pa, pb) = (mesh.nodes[a], mesh.nodes[b]);
                    let len = ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2)).sqrt();
                    for xi in [-g, g] {
                        let w = [0.5 * (1.0 - xi), 0.5 * (1.0 + xi)];
                        let r = w[0] * pa[0] + w[1] * pb[0];
                        points.push(ContactPoint {
                            nodes: [a, b],
                            weights: w,
                            area: 0.5 * len * kin.volume_factor(r),
                        });
                    }
                }
            }
        }
        let mut hist = vec![NodeHistory::default(); points.len()];
        for (h, p) in hist.iter_mut().zip(&points) {
            h.pos = p.position(&mesh.nodes);
            let g = tool.shape.project(tool.local(h.pos, 0.0)).gap;
            if g < -1e-9 {
                return Err(FeError::ToolStartsInside {
                    tool: name.into(),
                    node: p.nodes[0],
                    r: h.pos[0],
                    z: h.pos[1],
                    gap: g,
                });
            }
        }
        Ok(ContactSet {
            name: name.into(),
            tool,
            points,
            options,
            trial: hist.clone(),
            committed: hist,
            committed_travel: 0.0,
        })
    }

    /// Forgets all history (a fresh loading history starts).
    pub fn reset(&mut self, mesh: &Mesh) {
        for (h, p) in self.committed.iter_mut().zip(&self.points) {
            *h = NodeHistory {
                pos: p.position(&mesh.nodes),
                ..Default::default()
            };
        }
        self.trial.clone_from(&self.committed);
        self.committed_travel = 0.0;
    }

    /// Trial contact forces at tool travel `travel` for current nodal
    /// positions `x` (indexed by node), into `out` (one entry per node of
    /// the set; nodes out of contact have zero force).
    pub fn evaluate(&mut self, x: &[[f64; 2]], travel: f64, out: &mut Vec<NodeContact>) {
        out.clear();
        let o = self.options;
        for (k, p) in self.points.iter().enumerate() {
            let a = p.area;
            let c = self.committed[k];
            let pr = self
                .tool
                .shape
                .project(self.tool.local(p.position(x), travel));
            let (eps_n, eps_t) = (o.penalty_normal * a, o.penalty_tangent * a);
            let tn = c.lambda - eps_n * pr.gap;
            let mut t = NodeHistory {
                pos: c.pos,
                lambda: c.lambda,
                gap: pr.gap,
                ..Default::default()
            };
            if tn <= 0.0 {
                self.trial[k] = t;
                out.push(NodeContact {
                    nodes: p.nodes,
                    weights: p.weights,
                    ..Default::default()
                });
                continue;
            }
            t.normal_force = tn;
            let dtn = [-eps_n * pr.normal[0], -eps_n * pr.normal[1]];
            let (nv, tv) = (pr.normal, pr.tangent);
            let mut f = [tn * nv[0], tn * nv[1]];
            let mut kmat = [[0.0; 2]; 2];
            for i in 0..2 {
                for j in 0..2 {
                    kmat[i][j] = nv[i] * dtn[j] + tn * pr.dnormal[i][j];
                }
            }
            if o.friction > 0.0 {
                let stick = c.stick.unwrap_or_else(|| {
                    // first contact: stick where the node was at the last commit
                    self.tool
                        .shape
                        .project(self.tool.local(c.pos, self.committed_travel))
                        .xi
                });
                let slip = pr.xi - stick;
                let tt_trial = -eps_t * slip;
                let limit = o.friction * tn;
                let (tt, dtt) = if tt_trial.abs() <= limit {
                    t.stick = Some(stick);
                    (tt_trial, [-eps_t * pr.dxi[0], -eps_t * pr.dxi[1]])
                } else {
                    let s = slip.signum();
                    let tt = -s * limit;
                    t.stick = Some(pr.xi + tt / eps_t);
                    (tt, [-s * o.friction * dtn[0], -s * o.friction * dtn[1]])
                };
                f[0] += tt * tv[0];
                f[1] += tt * tv[1];
                for i in 0..2 {
                    for j in 0..2 {
                        kmat[i][j] += tv[i] * dtt[j] + tt * pr.dtangent[i][j];
                    }
                }
            }
            self.trial[k] = t;
            out.push(NodeContact {
                nodes: p.nodes,
                weights: p.weights,
                force: f,
                stiffness: kmat,
            });
        }
    }

    /// Largest penetration (mm) of the last evaluation.
    pub fn max_penetration(&self) -> f64 {
        self.trial
            .iter()
            .filter(|h| h.normal_force > 0.0)
            .map(|h| -h.gap)
            .fold(0.0, f64::max)
    }

    /// Augmentation: multipliers take the current normal forces.
    pub fn augment(&mut self) {
        for (c, t) in self.committed.iter_mut().zip(&self.trial) {
            c.lambda = t.normal_force;
        }
    }

    /// Accepts the trial state at tool travel `travel` with nodal positions `x`.
    pub fn commit(&mut self, x: &[[f64; 2]], travel: f64) {
        for (k, p) in self.points.iter().enumerate() {
            self.committed[k] = NodeHistory {
                pos: p.position(x),
                lambda: self.trial[k].normal_force,
                ..self.trial[k]
            };
        }
        self.committed_travel = travel;
    }

    /// Force on the tool opposite to its travel direction (N, positive when the
    /// body resists the tool) from the forces of the last evaluation.
    pub fn reaction(contacts: &[NodeContact], direction: [f64; 2]) -> f64 {
        contacts
            .iter()
            .map(|c| c.force[0] * direction[0] + c.force[1] * direction[1])
            .sum()
    }

    /// Number of nodes in contact in the last evaluation.
    pub fn active(&self) -> usize {
        self.trial.iter().filter(|h| h.normal_force > 0.0).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Grading;
    use crate::mesh2d::Mesh;

    fn set_with(friction: f64, points: ContactPoints) -> (Mesh, ContactSet) {
        let m =
            Mesh::graded_rectangle(4.0, 2.0, Grading::uniform(4.0, 4), Grading::uniform(2.0, 2))
                .unwrap();
        let tool = RigidTool {
            shape: ToolShape::Sphere { radius: 2.5 },
            origin: [0.0, 2.0],
            direction: [0.0, -1.0],
        };
        let opts = ContactOptions {
            friction,
            penalty_normal: 10.0,
            penalty_tangent: 5.0,
            penetration_tol: 1e-6,
            points,
        };
        let c = ContactSet::new("sphere", tool, &m, "top", Kinematics::Axisymmetric, opts).unwrap();
        (m, c)
    }

    #[test]
    fn tributary_areas_sum_to_the_top_face() {
        for points in [ContactPoints::Nodes, ContactPoints::EdgeGauss] {
            let (_, c) = set_with(0.0, points);
            let total: f64 = c.points.iter().map(|p| p.area).sum();
            assert!((total - std::f64::consts::PI * 16.0).abs() < 1e-12);
        }
    }

    #[test]
    fn tool_inside_is_an_error_naming_tool_and_node() {
        let m =
            Mesh::graded_rectangle(4.0, 2.0, Grading::uniform(4.0, 4), Grading::uniform(2.0, 2))
                .unwrap();
        let tool = RigidTool {
            shape: ToolShape::Platen,
            origin: [0.0, 1.5],
            direction: [0.0, -1.0],
        };
        let opts = ContactOptions {
            friction: 0.0,
            penalty_normal: 1.0,
            penalty_tangent: 1.0,
            penetration_tol: 1e-6,
            points: ContactPoints::Nodes,
        };
        let e =
            ContactSet::new("platen", tool, &m, "top", Kinematics::Axisymmetric, opts).unwrap_err();
        let s = e.to_string();
        assert!(s.contains("platen") && s.contains("node"), "{s}");
    }

    #[test]
    fn stiffness_matches_finite_differences_in_stick_and_slip() {
        for (friction, points) in [0.0, 0.3, 100.0]
            .into_iter()
            .flat_map(|f| [(f, ContactPoints::Nodes), (f, ContactPoints::EdgeGauss)])
        {
            let (m, mut c) = set_with(friction, points);
            // move nodes sideways so that some slip and some stick
            let mut x = m.nodes.clone();
            c.commit(&x, 0.0);
            for (i, p) in x.iter_mut().enumerate() {
                p[0] += 0.02 * (i as f64).sin();
                p[1] -= 0.001 * i as f64;
            }
            let travel = 0.3;
            let mut base = Vec::new();
            c.evaluate(&x, travel, &mut base);
            assert!(c.active() > 0);
            let h = 1e-7;
            let (mut p, mut q) = (Vec::new(), Vec::new());
            for (k, nc) in base.iter().enumerate() {
                // d force / d x_node = weight * d force / d x_point
                let (node, w) = (nc.nodes[0], nc.weights[0]);
                for j in 0..2 {
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[node][j] += h;
                    xm[node][j] -= h;
                    c.evaluate(&xp, travel, &mut p);
                    c.evaluate(&xm, travel, &mut q);
                    for i in 0..2 {
                        let fd = (p[k].force[i] - q[k].force[i]) / (2.0 * h);
                        let an = w * nc.stiffness[i][j];
                        assert!(
                            (fd - an).abs() < 1e-5 * (1.0 + an.abs()),
                            "mu {friction} {points:?} node {node} {i}{j}: {an} vs {fd}"
                        );
                    }
                }
            }
        }
    }
}
