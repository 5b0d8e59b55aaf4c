//! Contact of a body's surface (a facet set) with a moving rigid tool
//! (a [`RigidSurface`] following a [`ToolMotion`]), with Coulomb friction,
//! enforced at contact points: the facet nodes (tributary areas) or the
//! Gauss points of every facet (the force shared by the facet's nodes
//! through its shape functions, so straight edges cannot cut through a
//! curved tool between nodes).
//!
//! Normal: augmented Lagrangian (Alart & Curnier 1991; Simo & Laursen 1992),
//! `t_N = max(0, lambda + eps_N A (-g))`. The multiplier `lambda` takes the
//! converged normal force at every commit (one Uzawa update per increment),
//! and [`Contribution::augment`] can update it between Newton solves of one
//! increment until the penetration is below a tolerance. Augmented
//! multipliers are trial state: a rollback restores the committed ones.
//! Tangential (2D): elastic-predictor / plastic-corrector return map
//! (Wriggers, *Computational Contact Mechanics*, 2006, 5.2.3): trial
//! `t_T = -eps_T A (xi - xi_stick)`; slip when `|t_T| > mu t_N`, then
//! `t_T = -mu t_N sign(xi - xi_stick)` and the stick point moves. `xi` is
//! the arc length of the closest point in the tool's own frame, so a
//! rotating wheel carries its stick points with it. `A` is the point's
//! area (360 degrees in axisymmetry), and the tangent `d f / d x` is exact
//! and unsymmetric in slip. (3D friction, with a two-component slip, comes
//! with the 3D needle; 3D contact is frictionless for now.)

use crate::contribution::{Assembly, AssemblyContext, Contribution};
use crate::kinematics::Kinematics;
use crate::mesh::{CellType, Mesh};
use crate::motion::ToolMotion;
use crate::quadrature::QuadratureRule;
use crate::surface::RigidSurface;
use crate::FeError;

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
    /// At the facet nodes, with their tributary areas (node-to-surface).
    #[default]
    Nodes,
    /// At the Gauss points of every facet, the force shared by the facet's
    /// nodes through the shape functions (a surface-to-rigid integration).
    EdgeGauss,
}

/// Largest number of facet nodes a contact point interpolates.
const MAX_NODES: usize = 9;

/// A contact point on the surface: `x = sum_a w_a x[nodes[a]]` with
/// reference area `area`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    pub nodes: [usize; MAX_NODES],
    pub weights: [f64; MAX_NODES],
    pub len: usize,
    pub area: f64,
}

impl ContactPoint {
    fn position(&self, x: impl Fn(usize) -> [f64; 3]) -> [f64; 3] {
        let mut p = [0.0; 3];
        for a in 0..self.len {
            let xa = x(self.nodes[a]);
            for i in 0..3 {
                p[i] += self.weights[a] * xa[i];
            }
        }
        p
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct PointHistory {
    /// Stick point (tool-frame arc length), when in contact.
    stick: Option<f64>,
    /// Normal multiplier (N).
    lambda: f64,
    /// Position at the last commit.
    pos: [f64; 3],
    /// Normal force (N) and gap (mm) of the last evaluation.
    normal_force: f64,
    gap: f64,
}

/// Force on the body at a contact point and its derivative with respect
/// to the point's position.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct PointForce {
    force: [f64; 3],
    stiffness: [[f64; 3]; 3],
}

/// A rigid tool and the body surface that may touch it.
pub struct RigidContact {
    pub name: String,
    pub surface: Box<dyn RigidSurface>,
    pub motion: ToolMotion,
    pub options: ContactOptions,
    points: Vec<ContactPoint>,
    facets: Vec<Vec<usize>>,
    committed: Vec<PointHistory>,
    trial: Vec<PointHistory>,
    /// The multipliers of the current increment (committed ones, or
    /// augmented since the last commit).
    lambda: Vec<f64>,
    forces: Vec<PointForce>,
}

impl RigidContact {
    /// Contact between `surface` moving by `motion` and facet set `facets`
    /// of `mesh`. Errors: unknown set, bad tool dimensions, a surface,
    /// motion or kinematics of another dimension than the mesh, friction in
    /// 3D, a tool that starts inside the body (naming tool, node and position).
    // (the tool, its motion, the body's surface and the options are all
    // independent inputs; a builder would only rename them)
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: &str,
        surface: Box<dyn RigidSurface>,
        motion: ToolMotion,
        mesh: &Mesh,
        facets: &str,
        kinematics: Kinematics,
        options: ContactOptions,
        channels: usize,
    ) -> Result<RigidContact, FeError> {
        let bad = |reason: String| FeError::InvalidConfig {
            field: format!("tool `{name}`"),
            reason,
        };
        surface.check().map_err(bad)?;
        motion.check(channels).map_err(bad)?;
        if surface.dim() != kinematics.dim() {
            return Err(bad(format!(
                "a {}D surface in {kinematics:?} kinematics",
                surface.dim()
            )));
        }
        if kinematics.dim() == 3 && options.friction != 0.0 {
            return Err(bad("3D contact is frictionless for now".into()));
        }
        if mesh.dim != kinematics.dim() {
            return Err(bad(format!(
                "{kinematics:?} kinematics on a {}D mesh",
                mesh.dim
            )));
        }
        motion.check_dim(kinematics.dim()).map_err(bad)?;
        mesh.validate()?;
        let set = mesh.facet_set(facets)?;
        let points = contact_points(mesh, set, kinematics, options.points)?;
        let facets: Vec<Vec<usize>> = set.iter().map(|f| f.to_vec()).collect();
        let mut c = RigidContact {
            name: name.into(),
            surface,
            motion,
            options,
            committed: vec![PointHistory::default(); points.len()],
            trial: vec![PointHistory::default(); points.len()],
            lambda: vec![0.0; points.len()],
            forces: vec![PointForce::default(); points.len()],
            points,
            facets,
        };
        c.reset(&mesh.nodes);
        let pose = c.motion.pose(&vec![0.0; channels]);
        for p in &c.points {
            let x = p.position(|n| mesh.nodes[n]);
            let g = pose.project(&*c.surface, x).gap;
            if g < -1e-9 {
                return Err(FeError::ToolStartsInside {
                    tool: name.into(),
                    node: p.nodes[0],
                    at: x,
                    gap: g,
                });
            }
        }
        Ok(c)
    }

    /// Number of contact points in contact at the last assembly.
    pub fn active(&self) -> usize {
        self.trial.iter().filter(|h| h.normal_force > 0.0).count()
    }

    /// Largest penetration (mm) of the last assembly.
    pub fn max_penetration(&self) -> f64 {
        self.trial
            .iter()
            .filter(|h| h.normal_force > 0.0)
            .map(|h| -h.gap)
            .fold(0.0, f64::max)
    }

    /// The contact points.
    pub fn points(&self) -> &[ContactPoint] {
        &self.points
    }
}

/// Contact points of a facet set.
fn contact_points(
    mesh: &Mesh,
    set: &crate::mesh::FacetSet,
    kin: Kinematics,
    mode: ContactPoints,
) -> Result<Vec<ContactPoint>, FeError> {
    let vf = |x: &[f64; 3]| kin.volume_factor(x[0]);
    let mut out = Vec::new();
    let point = |nodes: &[usize], weights: &[f64], area: f64| {
        let mut p = ContactPoint {
            nodes: [0; MAX_NODES],
            weights: [0.0; MAX_NODES],
            len: nodes.len(),
            area,
        };
        p.nodes[..nodes.len()].copy_from_slice(nodes);
        p.weights[..nodes.len()].copy_from_slice(weights);
        p
    };
    match (set.cell_type, mode) {
        (CellType::Line2, ContactPoints::Nodes) => {
            let mut area = std::collections::BTreeMap::<usize, f64>::new();
            for f in set.iter() {
                let (a, b) = (f[0], f[1]);
                let (pa, pb) = (mesh.nodes[a], mesh.nodes[b]);
                let len = ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2)).sqrt();
                // integral of N_a times the volume factor along the edge (linear in r)
                let (fa, fb) = (vf(&pa), vf(&pb));
                *area.entry(a).or_default() += len * (2.0 * fa + fb) / 6.0;
                *area.entry(b).or_default() += len * (fa + 2.0 * fb) / 6.0;
            }
            out.extend(area.into_iter().map(|(n, a)| point(&[n], &[1.0], a)));
        }
        (CellType::Line2, ContactPoints::EdgeGauss) => {
            let g = 1.0 / 3f64.sqrt();
            for f in set.iter() {
                let (a, b) = (f[0], f[1]);
                let (pa, pb) = (mesh.nodes[a], mesh.nodes[b]);
                let len = ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2)).sqrt();
                for xi in [-g, g] {
                    let w = [0.5 * (1.0 - xi), 0.5 * (1.0 + xi)];
                    let r = w[0] * pa[0] + w[1] * pb[0];
                    out.push(point(&[a, b], &w, 0.5 * len * kin.volume_factor(r)));
                }
            }
        }
        (ct @ (CellType::Line3 | CellType::Quad4), mode) => {
            // facet quadrature: shape functions N_a and the area element
            let rule = QuadratureRule::for_cell(ct);
            let mut tributary = std::collections::BTreeMap::<usize, f64>::new();
            for f in set.iter() {
                let xs: Vec<[f64; 3]> = f.iter().map(|&n| mesh.nodes[n]).collect();
                for (xi, w) in rule.points.iter().zip(&rule.weights) {
                    let (n, da) = facet_shape(ct, xi, &xs);
                    let mut x = [0.0; 3];
                    for (a, p) in xs.iter().enumerate() {
                        for i in 0..3 {
                            x[i] += n[a] * p[i];
                        }
                    }
                    let area = w * da * vf(&x);
                    match mode {
                        ContactPoints::EdgeGauss => out.push(point(f, &n[..f.len()], area)),
                        ContactPoints::Nodes => {
                            for (a, &node) in f.iter().enumerate() {
                                *tributary.entry(node).or_default() += n[a] * area;
                            }
                        }
                    }
                }
            }
            out.extend(tributary.into_iter().map(|(n, a)| point(&[n], &[1.0], a)));
        }
        (ct, _) => {
            return Err(FeError::InvalidConfig {
                field: "contact".into(),
                reason: format!("no contact points on {ct:?} facets"),
            })
        }
    }
    Ok(out)
}

/// Shape functions (first `nodes` entries) and the length or area element
/// of a Line3 or Quad4 facet at reference point `xi`.
fn facet_shape(ct: CellType, xi: &[f64; 3], x: &[[f64; 3]]) -> ([f64; MAX_NODES], f64) {
    let mut n = [0.0; MAX_NODES];
    match ct {
        CellType::Line3 => {
            let (s, d) = crate::shape::line3(xi);
            let mut t = [0.0; 3];
            for a in 0..3 {
                n[a] = s[a];
                for i in 0..3 {
                    t[i] += d[a][0] * x[a][i];
                }
            }
            (n, (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt())
        }
        _ => {
            let (s, d) = crate::shape::quad4(xi);
            let (mut t1, mut t2) = ([0.0; 3], [0.0; 3]);
            for a in 0..4 {
                n[a] = s[a];
                for i in 0..3 {
                    t1[i] += d[a][0] * x[a][i];
                    t2[i] += d[a][1] * x[a][i];
                }
            }
            let c = [
                t1[1] * t2[2] - t1[2] * t2[1],
                t1[2] * t2[0] - t1[0] * t2[2],
                t1[0] * t2[1] - t1[1] * t2[0],
            ];
            (n, (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt())
        }
    }
}

impl Contribution for RigidContact {
    fn name(&self) -> String {
        format!("tool `{}`", self.name)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }

    fn channels(&self) -> Vec<usize> {
        self.motion.channels()
    }

    fn couplings(&self, dim: usize) -> Vec<Vec<usize>> {
        self.facets
            .iter()
            .map(|f| {
                f.iter()
                    .flat_map(|&n| (0..dim).map(move |c| n * dim + c))
                    .collect()
            })
            .collect()
    }

    fn assemble(&mut self, ctx: &AssemblyContext, out: &mut Assembly) -> Result<(), FeError> {
        let o = self.options;
        let dim = ctx.dofs.dim;
        let pose = self.motion.pose(ctx.channels);
        let pose_c = self.motion.pose(ctx.channels_committed);
        let surface = &*self.surface;
        for (k, p) in self.points.iter().enumerate() {
            let a = p.area;
            let c = self.committed[k];
            let pr = pose.project(surface, p.position(|n| ctx.position(n)));
            let (eps_n, eps_t) = (o.penalty_normal * a, o.penalty_tangent * a);
            let tn = self.lambda[k] - eps_n * pr.gap;
            let mut t = PointHistory {
                pos: c.pos,
                lambda: self.lambda[k],
                gap: pr.gap,
                ..Default::default()
            };
            if tn <= 0.0 {
                self.trial[k] = t;
                self.forces[k] = PointForce::default();
                continue;
            }
            t.normal_force = tn;
            let nv = pr.normal;
            let dtn: [f64; 3] = std::array::from_fn(|j| -eps_n * nv[j]);
            let mut f: [f64; 3] = std::array::from_fn(|i| tn * nv[i]);
            let mut kmat = [[0.0; 3]; 3];
            for i in 0..dim {
                for j in 0..dim {
                    kmat[i][j] = nv[i] * dtn[j] + tn * pr.dnormal[i][j];
                }
            }
            if o.friction > 0.0 {
                let tv = pr.tangent;
                let stick = c.stick.unwrap_or_else(|| {
                    // first contact: stick where the point was at the last commit
                    pose_c.project(surface, c.pos).xi
                });
                let slip = pr.xi - stick;
                let tt_trial = -eps_t * slip;
                let limit = o.friction * tn;
                let (tt, dtt) = if tt_trial.abs() <= limit {
                    t.stick = Some(stick);
                    (
                        tt_trial,
                        std::array::from_fn::<f64, 3, _>(|j| -eps_t * pr.dxi[j]),
                    )
                } else {
                    let s = slip.signum();
                    let tt = -s * limit;
                    t.stick = Some(pr.xi + tt / eps_t);
                    (tt, std::array::from_fn(|j| -s * o.friction * dtn[j]))
                };
                for i in 0..dim {
                    f[i] += tt * tv[i];
                }
                for i in 0..dim {
                    for j in 0..dim {
                        kmat[i][j] += tv[i] * dtt[j] + tt * pr.dtangent[i][j];
                    }
                }
            }
            self.trial[k] = t;
            self.forces[k] = PointForce {
                force: f,
                stiffness: kmat,
            };
        }
        for (p, pf) in self.points.iter().zip(&self.forces) {
            if pf.force == [0.0; 3] && pf.stiffness == [[0.0; 3]; 3] {
                continue;
            }
            out.force_scale2 += (0..dim).map(|i| pf.force[i].powi(2)).sum::<f64>();
            for a in 0..p.len {
                let wa = p.weights[a];
                if wa == 0.0 {
                    continue;
                }
                let na = p.nodes[a];
                for i in 0..dim {
                    out.fint[na * dim + i] -= wa * pf.force[i];
                }
                if out.values.is_none() {
                    continue;
                }
                for b in 0..p.len {
                    let wab = wa * p.weights[b];
                    if wab == 0.0 {
                        continue;
                    }
                    let nb = p.nodes[b];
                    for i in 0..dim {
                        for j in 0..dim {
                            out.add_entry(na * dim + i, nb * dim + j, -wab * pf.stiffness[i][j]);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn augment(&mut self) -> bool {
        if self.max_penetration() <= self.options.penetration_tol {
            return false;
        }
        for (l, t) in self.lambda.iter_mut().zip(&self.trial) {
            *l = t.normal_force;
        }
        true
    }

    fn commit(&mut self, ctx: &AssemblyContext) {
        for (k, p) in self.points.iter().enumerate() {
            self.committed[k] = PointHistory {
                pos: p.position(|n| ctx.position(n)),
                lambda: self.trial[k].normal_force,
                ..self.trial[k]
            };
            self.lambda[k] = self.committed[k].lambda;
        }
    }

    fn rollback(&mut self) {
        for (l, c) in self.lambda.iter_mut().zip(&self.committed) {
            *l = c.lambda;
        }
        self.trial.clone_from(&self.committed);
    }

    fn reset(&mut self, x0: &[[f64; 3]]) {
        for (h, p) in self.committed.iter_mut().zip(&self.points) {
            *h = PointHistory {
                pos: p.position(|n| x0[n]),
                ..Default::default()
            };
        }
        self.trial.clone_from(&self.committed);
        self.lambda.iter_mut().for_each(|l| *l = 0.0);
        self.forces
            .iter_mut()
            .for_each(|f| *f = PointForce::default());
    }

    fn tool_force(&self, axis: [f64; 3]) -> Option<f64> {
        Some(
            self.forces
                .iter()
                .map(|f| f.force[0] * axis[0] + f.force[1] * axis[1] + f.force[2] * axis[2])
                .sum(),
        )
    }
}
