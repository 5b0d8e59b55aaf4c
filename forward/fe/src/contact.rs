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
//! and unsymmetric in slip.
//!
//! Tangential (3D): the same return map with a two-component slip
//! (Wriggers 2006, 5.2; Laursen, *Computational Contact and
//! Impact Mechanics*, 2002, ch. 5, with the rigid master's material point
//! as the stick point). The stick point `X_s` is stored in the tool frame
//! (the tool's material point the body point is stuck to, carried by a
//! rotating tool); with the pose `x = p + R X`, the current closest point
//! `x_c = x - g n` ([`SurfacePoint::closest`]) and `P = I - n (x) n`:
//!
//! ```text
//! x_s = p + R X_s,   d = x_c - x_s,   s = P d                 (slip, tangential)
//! trial  t_T = -eps_T A s
//! stick  |t_T| <= mu t_N:  t_T as is,                 X_s kept
//! slip   otherwise:        t_T = -mu t_N m, m = s/|s|, x_s <- x_c + t_T / (eps_T A)
//! f = t_N n + t_T   (the force on the body)
//! ```
//!
//! The moved stick point lies in the tangent plane at `x_c`, at the
//! distance for which a re-evaluation at the same `x` is exactly at the
//! Coulomb limit. At first contact `X_s` is the closest point of the
//! position at the last commit (committed pose). The tangent, with
//! `C = d x_c / d x = I - n (x) n - g dn/dx` ([`SurfacePoint::dclosest`]),
//! `d t_N / d x = -eps_N A n` and `dn/dx` symmetric (the surface module):
//!
//! ```text
//! S = ds/dx = C - (n . d) dn/dx - n (x) (dn/dx^T d + C^T n)
//! stick  d t_T / d x = -eps_T A S
//! slip   d t_T / d x = -(mu t_N / |s|) (I - m (x) m) S - mu m (x) d t_N / d x
//! d f / d x = n (x) d t_N / d x + t_N dn/dx + d t_T / d x
//! ```
//!
//! (`C^T n = -g dn/dx n = 0` on a smooth piece; it is kept for generality.)
//! `x_s` does not depend on `x` within an evaluation: the stick point is
//! history. Like the 2D one, the 3D stick point is trial state written by
//! every assembly, accepted by a commit and restored by a rollback.

use crate::contribution::{Assembly, AssemblyContext, Contribution};
use crate::kinematics::Kinematics;
use crate::mesh::{CellType, Mesh};
use crate::motion::{Pose, ToolMotion};
use crate::quadrature::QuadratureRule;
use crate::surface::{RigidSurface, SurfacePoint};
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
    /// Along every straight edge (2D `Line2` facets), Gauss points on each
    /// stretch between the points where the tool's piece changes or the
    /// force starts ([`crate::contact_split`]), so that the assembled force
    /// has no kinks. A pure penalty (the points move along the edge, so they
    /// carry no multipliers; nodal multipliers interpolated along the edges
    /// were tried and load a band beyond the contact's end,
    /// docs/validation/fe.md "Q1"). Frictionless only.
    EdgeSplit,
}

/// Numbers per contact point in [`Contribution::history`].
const HISTORY: usize = 10;

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
pub(crate) struct PointHistory {
    /// 2D stick point (tool-frame arc length), when in contact.
    stick: Option<f64>,
    /// 3D stick point (tool-frame coordinates of the tool's material point
    /// the body point is stuck to), when in contact.
    stick_point: Option<[f64; 3]>,
    /// Normal multiplier (N).
    lambda: f64,
    /// Position at the last commit.
    pos: [f64; 3],
    /// Normal force (N) and gap (mm) of the last evaluation.
    normal_force: f64,
    /// Sliding (at the Coulomb limit) at the last evaluation.
    slipping: bool,
    gap: f64,
}

/// The discrete state of a contact point: clear of the tool, in contact
/// and sticking (or frictionless), or in contact and sliding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Branch {
    Clear,
    Stick,
    Slip,
}

impl Branch {
    fn of(h: &PointHistory) -> Branch {
        match (h.normal_force > 0.0, h.slipping) {
            (false, _) => Branch::Clear,
            (true, false) => Branch::Stick,
            (true, true) => Branch::Slip,
        }
    }
}

/// Force on the body at a contact point and its derivative with respect
/// to the point's position.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct PointForce {
    pub(crate) force: [f64; 3],
    pub(crate) stiffness: [[f64; 3]; 3],
}

/// A rigid tool and the body surface that may touch it.
pub struct RigidContact {
    pub name: String,
    pub surface: Box<dyn RigidSurface>,
    pub motion: ToolMotion,
    pub options: ContactOptions,
    /// A pure penalty (`lambda = 0` always: no Uzawa update at commit, no
    /// augmentation): the contact force is a function of the current
    /// configuration alone, so a frictionless state depends on the tool's
    /// position only, not on the path that led there (R2's rolled pass),
    /// at the price of a penetration `t_N / eps_N` (a force bias that falls
    /// as `1 / eps_N`). Default `false` (augmented Lagrangian).
    pub pure_penalty: bool,
    /// Width `delta` (mm) of a softened onset of the normal force: with
    /// the penetration `s = lambda / eps_N - g`,
    /// `t_N = eps_N (s + delta/2)^2 / (2 delta)` for `|s| < delta/2` and
    /// `t_N = eps_N s` beyond (continuous with its derivative, the same
    /// force as the sharp law once `s >= delta/2`, so a loaded point has no
    /// bias). The kink at first touch is what makes Newton chatter when a
    /// stiff penalty meets a moving contact edge (R2's wheel). 0 (default):
    /// the sharp law.
    pub smoothing: f64,
    points: Vec<ContactPoint>,
    facets: Vec<Vec<usize>>,
    committed: Vec<PointHistory>,
    trial: Vec<PointHistory>,
    /// The multipliers of the current increment (committed ones, or
    /// augmented since the last commit).
    lambda: Vec<f64>,
    forces: Vec<PointForce>,
    /// [`ContactPoints::EdgeSplit`]: per facet its reference length and the
    /// volume factors at its two nodes (`None` for the fixed points).
    split: Option<Vec<(f64, f64, f64)>>,
    /// Branches held by [`Contribution::hold_branches`].
    held: Option<Vec<Branch>>,
}

impl RigidContact {
    /// Contact between `surface` moving by `motion` and facet set `facets`
    /// of `mesh`. Errors: unknown set, bad tool dimensions, a surface,
    /// motion or kinematics of another dimension than the mesh, a tool that starts inside the body (naming tool, node and position).
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
        let mut split = None;
        if options.points == ContactPoints::EdgeSplit {
            let mut edges = Vec::new();
            if set.cell_type != CellType::Line2 || options.friction > 0.0 {
                return Err(bad(
                    "split edge contact needs 2-node edges and no friction".into()
                ));
            }
            for f in &facets {
                let (pa, pb) = (mesh.nodes[f[0]], mesh.nodes[f[1]]);
                let len = ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2)).sqrt();
                edges.push((
                    len,
                    kinematics.volume_factor(pa[0]),
                    kinematics.volume_factor(pb[0]),
                ));
            }
            split = Some(edges);
        }
        let mut c = RigidContact {
            name: name.into(),
            surface,
            motion,
            options,
            pure_penalty: false,
            smoothing: 0.0,
            committed: vec![PointHistory::default(); points.len()],
            trial: vec![PointHistory::default(); points.len()],
            lambda: vec![0.0; points.len()],
            forces: vec![PointForce::default(); points.len()],
            points,
            facets,
            split,
            held: None,
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

    /// Number of contact points sliding (at the Coulomb limit) at the last
    /// assembly.
    pub fn slipping(&self) -> usize {
        self.trial.iter().filter(|h| h.slipping).count()
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
        // the points are placed at every assembly
        (_, ContactPoints::EdgeSplit) => {}
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
        (ct @ (CellType::Line3 | CellType::Quad4 | CellType::Quad9), mode) => {
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
                        ContactPoints::Nodes | ContactPoints::EdgeSplit => {
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
/// of a Line3, Quad4 or Quad9 facet at reference point `xi`.
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
            let (mut t1, mut t2) = ([0.0; 3], [0.0; 3]);
            let mut tangents = |s: &[f64], d: &[[f64; 2]]| {
                for a in 0..s.len() {
                    n[a] = s[a];
                    for i in 0..3 {
                        t1[i] += d[a][0] * x[a][i];
                        t2[i] += d[a][1] * x[a][i];
                    }
                }
            };
            if ct == CellType::Quad9 {
                let (s, d) = crate::shape::quad9(xi);
                tangents(&s, &d);
            } else {
                let (s, d) = crate::shape::quad4(xi);
                tangents(&s, &d);
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

/// What the evaluation of a contact point needs of its tool.
pub(crate) struct Tool<'a> {
    pub(crate) surface: &'a dyn RigidSurface,
    /// The pose of the current evaluation and of the last commit.
    pub(crate) pose: &'a Pose,
    pose_committed: &'a Pose,
    options: &'a ContactOptions,
    /// [`RigidContact::smoothing`].
    pub(crate) smoothing: f64,
    dim: usize,
}

impl Tool<'_> {
    /// The trial history and the force (on the body) of a contact point of
    /// reference area `area` at position `x`, with normal multiplier
    /// `lambda` and committed history `c`.
    pub(crate) fn point(
        &self,
        area: f64,
        lambda: f64,
        c: &PointHistory,
        x: [f64; 3],
    ) -> (PointHistory, PointForce) {
        self.point_on(area, lambda, c, x, None)
    }

    /// [`Tool::point`] on the branch `held` when given (a point held in
    /// contact keeps the linear normal law below zero force, a point held
    /// clear has none, and a point held sticking or sliding does so
    /// whatever its trial traction), on its own branch otherwise.
    pub(crate) fn point_on(
        &self,
        area: f64,
        lambda: f64,
        c: &PointHistory,
        x: [f64; 3],
        held: Option<Branch>,
    ) -> (PointHistory, PointForce) {
        let (o, dim, surface) = (self.options, self.dim, self.surface);
        let pr = self.pose.project(surface, x);
        let (eps_n, eps_t) = (o.penalty_normal * area, o.penalty_tangent * area);
        let mut tn = lambda - eps_n * pr.gap;
        // d t_N / d(-g): eps_N, or less on the softened onset
        let mut slope = eps_n;
        let half = 0.5 * self.smoothing;
        if half > 0.0 && eps_n > 0.0 {
            let s = tn / eps_n;
            if s <= -half {
                tn = 0.0;
            } else if s < half {
                let r = s + half;
                tn = eps_n * r * r / (4.0 * half);
                slope = eps_n * r / (2.0 * half);
            }
        }
        let mut t = PointHistory {
            pos: c.pos,
            lambda,
            gap: pr.gap,
            ..Default::default()
        };
        let clear = match held {
            Some(b) => b == Branch::Clear,
            None => tn <= 0.0,
        };
        if clear {
            return (t, PointForce::default());
        }
        t.normal_force = tn;
        let stick_held = match held {
            Some(Branch::Stick) => Some(true),
            Some(Branch::Slip) => Some(false),
            _ => None,
        };
        let nv = pr.normal;
        let dtn: [f64; 3] = std::array::from_fn(|j| -slope * nv[j]);
        let mut f: [f64; 3] = std::array::from_fn(|i| tn * nv[i]);
        let mut kmat = [[0.0; 3]; 3];
        for i in 0..dim {
            for j in 0..dim {
                kmat[i][j] = nv[i] * dtn[j] + tn * pr.dnormal[i][j];
            }
        }
        if o.friction > 0.0 && dim == 3 {
            let (stick, slipping, tt, dtt) =
                self.friction_3d(&pr, eps_t, tn, &dtn, c, x, stick_held);
            t.stick_point = Some(stick);
            t.slipping = slipping;
            for i in 0..3 {
                f[i] += tt[i];
                for j in 0..3 {
                    kmat[i][j] += dtt[i][j];
                }
            }
        } else if o.friction > 0.0 {
            let tv = pr.tangent;
            let stick = c.stick.unwrap_or_else(|| {
                // first contact: stick where the point was at the last commit
                self.pose_committed.project(surface, c.pos).xi
            });
            let slip = pr.xi - stick;
            let tt_trial = -eps_t * slip;
            let limit = o.friction * tn;
            let (tt, dtt) = if stick_held.unwrap_or(tt_trial.abs() <= limit) {
                t.stick = Some(stick);
                (
                    tt_trial,
                    std::array::from_fn::<f64, 3, _>(|j| -eps_t * pr.dxi[j]),
                )
            } else {
                let s = slip.signum();
                let tt = -s * limit;
                t.slipping = true;
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
        (
            t,
            PointForce {
                force: f,
                stiffness: kmat,
            },
        )
    }

    /// 3D Coulomb friction at a point in contact (see the module
    /// documentation for the equations): the stick point in the tool frame,
    /// the tangential traction `t_T` on the body and `d t_T / d x`, given
    /// whether it slips, given the projection `pr` of `x`, `eps_T = eps_t`, `t_N = tn` and
    /// `d t_N / d x = dtn`; `stick_held`: stick (`true`) or slip whatever
    /// the trial traction.
    #[allow(clippy::too_many_arguments)]
    fn friction_3d(
        &self,
        pr: &SurfacePoint,
        eps_t: f64,
        tn: f64,
        dtn: &[f64; 3],
        c: &PointHistory,
        x: [f64; 3],
        stick_held: Option<bool>,
    ) -> ([f64; 3], bool, [f64; 3], [[f64; 3]; 3]) {
        let stick = c.stick_point.unwrap_or_else(|| {
            // first contact: stick to the tool's material point closest to
            // where the point was at the last commit
            let local = self.pose_committed.to_local(c.pos);
            self.surface.project(local).closest(local)
        });
        let (n, dn) = (pr.normal, pr.dnormal);
        let xc = pr.closest(x);
        let xs = self.pose.to_global_point(stick);
        let d: [f64; 3] = std::array::from_fn(|i| xc[i] - xs[i]);
        let nd = dot(n, d);
        let s: [f64; 3] = std::array::from_fn(|i| d[i] - nd * n[i]);
        // ds/dx = C - (n . d) dn/dx - n (x) (dn/dx^T d + C^T n)
        let cm = pr.dclosest();
        let w: [f64; 3] = std::array::from_fn(|j| {
            (0..3)
                .map(|k| d[k] * dn[k][j] + n[k] * cm[k][j])
                .sum::<f64>()
        });
        let ds: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| cm[i][j] - nd * dn[i][j] - n[i] * w[j])
        });
        let limit = self.options.friction * tn;
        let norm_s = dot(s, s).sqrt();
        if stick_held.unwrap_or(eps_t * norm_s <= limit) {
            // stick: t_T = -eps_T s
            let tt = s.map(|v| -eps_t * v);
            let dtt = ds.map(|row| row.map(|v| -eps_t * v));
            return (stick, false, tt, dtt);
        }
        // slip: t_T = -mu t_N m, m = s / |s|, and the stick point moves to
        // x_c + t_T / eps_T (then |t_T| is the trial traction of the next
        // evaluation at the same x)
        let m = s.map(|v| v / norm_s);
        let tt = m.map(|v| -limit * v);
        let moved: [f64; 3] = std::array::from_fn(|i| xc[i] + tt[i] / eps_t);
        // dm/dx = (I - m (x) m) ds/dx / |s|
        let mds: [f64; 3] = std::array::from_fn(|j| (0..3).map(|k| m[k] * ds[k][j]).sum::<f64>());
        let dtt = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                -limit * (ds[i][j] - m[i] * mds[j]) / norm_s - self.options.friction * m[i] * dtn[j]
            })
        });
        (self.pose.to_local(moved), true, tt, dtt)
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
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
        let tool = Tool {
            surface: &*self.surface,
            pose: &pose,
            pose_committed: &pose_c,
            options: &o,
            smoothing: self.smoothing,
            dim,
        };
        if let Some(split) = &self.split {
            return crate::contact_split::assemble_split(
                &tool,
                &self.facets,
                split,
                ctx,
                out,
                (&mut self.trial, &mut self.forces),
            );
        }
        for (k, p) in self.points.iter().enumerate() {
            let x = p.position(|n| ctx.position(n));
            let held = self.held.as_ref().map(|h| h[k]);
            let (t, f) = tool.point_on(p.area, self.lambda[k], &self.committed[k], x, held);
            self.trial[k] = t;
            self.forces[k] = f;
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
        if self.split.is_some()
            || self.pure_penalty
            || self.max_penetration() <= self.options.penetration_tol
        {
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
                lambda: if self.pure_penalty {
                    0.0
                } else {
                    self.trial[k].normal_force
                },
                ..self.trial[k]
            };
            self.lambda[k] = self.committed[k].lambda;
        }
    }

    /// Holds which points touch, stick and slip as the last assembly found
    /// them (the fixed points; a split edge's points move with the edge and
    /// carry no history, so they follow the state).
    fn hold_branches(&mut self, hold: bool) {
        self.held =
            (hold && self.split.is_none()).then(|| self.trial.iter().map(Branch::of).collect());
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

    /// Per contact point: whether it has a 2D stick point and the stick
    /// point, whether it has a 3D one and its coordinates, the multiplier
    /// of the increment, and the position at the last commit.
    fn history(&self) -> Vec<f64> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mut v = Vec::with_capacity(HISTORY * self.committed.len());
        for (c, l) in self.committed.iter().zip(&self.lambda) {
            let sp = c.stick_point.unwrap_or_default();
            v.extend_from_slice(&[
                flag(c.stick.is_some()),
                c.stick.unwrap_or(0.0),
                flag(c.stick_point.is_some()),
                sp[0],
                sp[1],
                sp[2],
                *l,
                c.pos[0],
                c.pos[1],
                c.pos[2],
            ]);
        }
        v
    }

    fn set_history(&mut self, h: &[f64]) {
        for ((c, l), v) in self
            .committed
            .iter_mut()
            .zip(self.lambda.iter_mut())
            .zip(h.chunks_exact(HISTORY))
        {
            c.stick = (v[0] > 0.5).then_some(v[1]);
            c.stick_point = (v[2] > 0.5).then_some([v[3], v[4], v[5]]);
            *l = v[6];
            c.lambda = v[6];
            c.pos = [v[7], v[8], v[9]];
        }
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

#[cfg(test)]
#[path = "contact_tests.rs"]
mod tests;
