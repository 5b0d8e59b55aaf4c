//! `N3Needle`: needle indentation of a block in 3D (docs/benchmarks.md N3) —
//! 70 x 80 x 80 mm (x, y, z up), bottom fixed, the N1 needle (hemispherical
//! tip 2.5 mm tangent to a 15 degree cone, [`ToolShape::n1_needle`] revolved
//! about z, [`Revolution3d`]) pressed into the centre of the top face with
//! Coulomb friction 0.8. The quarter `[0, 35] x [0, 40] x [0, 80]` is
//! modelled, with symmetry on x = 0 (`u_x = 0`) and y = 0 (`u_y = 0`) and the
//! needle's axis on the line x = y = 0; the force is 4 x the quarter's
//! needle reaction, positive in compression.
//!
//! It is N1's setup in 3D on the same layer: 8-node hexahedra with a
//! constant pressure per element (Q1/P0, exact incompressibility by
//! default), a graded box fine at the needle ([`Mesh::graded_box`]), the 3D
//! Coulomb contact (two-component slip) at the Gauss points of the top
//! facets. Effects: `friction` (a parameter, 0..2) and `zero_offset`.

use palpate_core::{
    enrichable::not_applicable, Effect, ForwardError, ForwardModel, Loading, ParamSpace,
};
use palpate_enrich::ZeroOffset;
use palpate_material::Law;
use std::sync::Arc;

use crate::body::{RegionMaterial, SolidBody};
use crate::contact::{ContactOptions, ContactPoints, RigidContact};
use crate::contribution::Contribution;
use crate::discretisation::{Coarser, ConvergenceOrder};
use crate::dofs::Dirichlet;
use crate::kernel::{kernel_for, PressureSpace};
use crate::kinematics::Kinematics;
use crate::mesh::{CellType, Grading, Mesh};
use crate::model::{doubled, friction_param, graded_mesh_words, law_space, Bulk, FeModel, Setup};
use crate::motion::ToolMotion;
use crate::surface::Revolution3d;
use crate::system::{Part, Parts, SolverOptions, System};
use crate::tool::ToolShape;
use crate::FeError;

/// The N3 grading of mesh level `n` (radially and in z from the needle):
/// elements of `0.8 / n` mm over a 4 mm zone, growing by `1 + 0.4 / n`
/// beyond it; the O-grid has `3n` core cells per side ([`n3_core_cells`]).
/// O-grid level 1 has 945 hexahedra (4,110 equations), level 2 7,308
/// (30,479), level 3 24,381 (100,276, beyond 2 GiB). The box of the same
/// grading (`N3Mesh::Box`) has 2,340 hexahedra at level 1 and 17,400 at
/// level 2 (docs/validation/fe.md, N3).
pub fn n3_grading(level: usize) -> Grading {
    let n = level.max(1) as f64;
    Grading {
        h_fine: 0.8 / n,
        fine_length: 4.0,
        growth: 1.0 + 0.4 / n,
    }
}

/// The N3 grading of quadratic mesh level `n` ([`N3Element::Hex27`]):
/// cells of `1.6 / n` mm over the 4 mm zone growing by `1 + 0.8 / n`, so
/// that with their mid-nodes the nodes are as dense as [`n3_grading`]'s of
/// the same level. Level 1 on the O-grid: 192 cells, 5,808 equations.
pub fn n3_quadratic_grading(level: usize) -> Grading {
    let g = n3_grading(level);
    Grading {
        h_fine: 2.0 * g.h_fine,
        growth: 1.0 + 2.0 * (g.growth - 1.0),
        ..g
    }
}

/// How the N3 quarter block is meshed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum N3Mesh {
    /// The quarter O-grid ([`Mesh::quarter_ogrid`]): rings of hexahedra
    /// around the needle's axis, fine radially and in z under the needle,
    /// blended to the rectangular outer boundary.
    OGrid,
    /// The graded tensor box ([`Mesh::graded_box`], the same grading in x,
    /// y and z): fine lines repeated across the whole block.
    Box,
}

/// The element of the N3 mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum N3Element {
    /// 8-node hexahedra with a constant pressure per cell (Q1/P0, the
    /// mean-dilatation element).
    Hex8,
    /// 27-node hexahedra with a discontinuous linear pressure (Q2/P1, 4
    /// pressure unknowns per cell; Sussman & Bathe 1987, stable: Boffi,
    /// Brezzi & Fortin 2013, 8.6.3), on the same grading's cells made
    /// triquadratic ([`Mesh::to_triquadratic`]), so the nodes are twice as
    /// dense as the cells.
    Hex27,
}

/// The number of O-grid core cells per side for elements of `h_fine` mm:
/// a core of about 2.4 mm (`round(2.4 / h)`, at least 2: 3 per 0.8 mm, so
/// levels 1, 2, 3 have 3, 6, 9 and the cells around a ring are refined with
/// the radial ones), whose rings have `2n` cells of `pi r / 4n` mm around.
pub fn n3_core_cells(h_fine: f64) -> usize {
    ((2.4 / h_fine).round() as usize).max(2)
}

/// The N3 model: [`N3Setup`] as a forward model.
pub type N3Needle = FeModel<N3Setup>;

/// The N3 experiment ([`N3Needle`]).
#[derive(Debug, Clone, PartialEq)]
pub struct N3Setup {
    law: Law,
    pub bulk: Bulk,
    pub friction: f64,
    pub tool: ToolShape,
    /// Mesh level ([`n3_grading`], [`n3_quadratic_grading`] for 27-node
    /// cells); 1 coarse, 2 medium, 3 fine.
    pub level: usize,
    /// The mesh layout (default the box, the mesh of the mesa2011 study;
    /// the O-grid is 2.5-8x smaller for the same element size under the
    /// needle but, at level 1, 1.2 % stiffer at 10 mm: docs/validation/fe.md, N3).
    pub mesh: N3Mesh,
    /// The element (default Q1/P0 hexahedra).
    pub element: N3Element,
    /// When set, this grading (radial and z from the needle) replaces the
    /// one of `level`.
    pub grading: Option<Grading>,
    /// When set, the O-grid's core cells per side ([`n3_core_cells`] of the
    /// grading otherwise).
    pub core_cells: Option<usize>,
    /// Quarter-block sizes (mm): x, y, height.
    pub size: [f64; 3],
    /// Height of the tool tip above the top face at the start (mm); a
    /// negative value puts it inside the body, which is refused.
    pub start_gap: f64,
    /// Contact penalty factor: `eps = penalty * mu0 / h_fine` (augmented
    /// once per increment, so the converged force does not depend on it).
    pub penalty: f64,
    pub penetration_tol: f64,
    pub contact_points: ContactPoints,
    /// Width of the softened contact onset ([`RigidContact::smoothing`]) as
    /// a fraction of the node spacing under the needle; 0 (default): the
    /// sharp penalty law.
    pub contact_smoothing: f64,
    pub options: SolverOptions,
    /// Friction is the parameter after the law's (the `friction` effect).
    friction_is_parameter: bool,
}

/// The contributions of the N3 system.
#[derive(Debug, Clone, Copy)]
pub struct N3Parts {
    body: Part<SolidBody>,
    contact: Part<RigidContact>,
}

impl N3Setup {
    /// Makes the friction coefficient the parameter after the law's (as
    /// the `friction` effect does), starting at `friction`, or not.
    pub fn set_friction_parameter(&mut self, on: bool) {
        self.friction_is_parameter = on;
    }
}

impl N3Needle {
    /// docs/benchmarks.md N3 with the given law: friction 0.8, exact
    /// incompressibility, the box of mesh level 1, contact at the facet
    /// Gauss points, multipliers updated once per increment (as N1), each
    /// Newton system solved by GMRES on the LDL^T of the tangent's
    /// symmetric part (`options.gmres`; the LU's fill in 3D is many times
    /// larger).
    pub fn new(law: Law) -> Self {
        FeModel::from_setup(N3Setup {
            law,
            bulk: Bulk::Exact,
            friction: 0.8,
            tool: ToolShape::n1_needle(),
            level: 1,
            mesh: N3Mesh::Box,
            element: N3Element::Hex8,
            grading: None,
            core_cells: None,
            size: [35.0, 40.0, 80.0],
            start_gap: 0.0,
            penalty: 100.0,
            penetration_tol: 2e-3,
            contact_points: ContactPoints::EdgeGauss,
            contact_smoothing: 0.0,
            options: SolverOptions {
                max_step: 0.25,
                first_step: 0.05,
                max_augmentations: 0,
                gmres: true,
                ..SolverOptions::default()
            },
            friction_is_parameter: false,
        })
    }

    /// The coarser companion of the error estimate: elements twice as large
    /// (fine size and `growth - 1` doubled, fine zone kept), so level 2 gives
    /// level 1.
    pub fn coarser(&self) -> Coarser<N3Needle> {
        let coarse = doubled(self.effective_grading());
        let core = (self.effective_core_cells() / 2).max(2);
        self.companion(2.0, graded_mesh_words(coarse, "tool"), |s| {
            s.grading = Some(coarse);
            s.core_cells = Some(core);
        })
    }
}

impl N3Setup {
    fn effective_grading(&self) -> Grading {
        self.grading.unwrap_or_else(|| match self.element {
            N3Element::Hex8 => n3_grading(self.level),
            N3Element::Hex27 => n3_quadratic_grading(self.level),
        })
    }

    /// The O-grid's core cells per side.
    fn effective_core_cells(&self) -> usize {
        self.core_cells
            .unwrap_or_else(|| n3_core_cells(self.effective_grading().h_fine))
    }

    /// The radius (mm) up to which the O-grid's rings are circles.
    fn circle_radius(&self) -> f64 {
        0.5 * self.size[0].min(self.size[1])
    }

    /// Nodes, cells and equations of the mesh, counted from the grading
    /// without building it.
    pub fn mesh_size(&self) -> Result<(usize, usize, usize), FeError> {
        let g = self.effective_grading();
        let [lx, ly, lz] = self.size;
        let nz = g.positions(lz)?.len();
        let (plane_nodes, plane_cells, sym_nodes) = match self.mesh {
            N3Mesh::Box => {
                let (nx, ny) = (g.positions(lx)?.len(), g.positions(ly)?.len());
                (nx * ny, (nx - 1) * (ny - 1), nx + ny)
            }
            N3Mesh::OGrid => {
                let n = self.effective_core_cells();
                let k = g.positions(lx.min(ly))?.len() - 1;
                let rings = k.saturating_sub(n);
                (
                    (n + 1) * (n + 1) + rings * (2 * n + 1),
                    n * n + rings * 2 * n,
                    2 * (k + 1),
                )
            }
        };
        let cells = plane_cells * (nz - 1);
        let (plane_nodes, sym_nodes, nz, pressures) = match self.element {
            N3Element::Hex8 => (plane_nodes, sym_nodes, nz, 1),
            // a planar quadrilateral mesh has V + F - 1 edges (Euler), each
            // gaining a mid-node, and each cell a centre; lines of k nodes
            // become 2k - 1
            N3Element::Hex27 => (
                2 * plane_nodes + 2 * plane_cells - 1,
                2 * sym_nodes - 2,
                2 * nz - 1,
                4,
            ),
        };
        let nodes = plane_nodes * nz;
        // displacements less the fixed ones (bottom, two symmetry planes),
        // plus the pressures of each cell
        let equations =
            (3 * nodes).saturating_sub(3 * plane_nodes + sym_nodes * (nz - 1)) + pressures * cells;
        Ok((nodes, cells, equations))
    }

    /// The estimated peak memory of a run (bytes) from the number of
    /// equations ([`N3Setup::mesh_size`]), without building anything.
    /// O-grid (LDL^T and GMRES): `0.6 GiB x (equations / 30,500)^1.25`,
    /// through the measured peaks of O-grid levels 1, 1.5 and 2 (4,110,
    /// 13,248 and 30,479 equations: 0.05, 0.2 and 0.6 GiB) with a slightly
    /// steeper exponent than they show (1.2). Box (the LU of the first N3):
    /// `1.6 GiB x (equations / 24,500)^1.8`, through the 0.6 mm box's peak
    /// (24,500 equations, 1.6 GiB) with the exponent its level 2's lower
    /// bound needs (> 10.5 GiB at ~70,000). docs/validation/fe.md, N3.
    pub fn memory_estimate(&self) -> Result<f64, FeError> {
        let (_, _, equations) = self.mesh_size()?;
        let e = equations as f64;
        // 27-node cells couple 125 nodes per node, not 27: their factors
        // fill about twice as much per equation (O-grid, 1.6 and 1.2 mm
        // cells: 155 and 301 MiB at 5,808 and 10,538 equations)
        let fill = match self.element {
            N3Element::Hex8 => 1.0,
            N3Element::Hex27 => 2.0,
        };
        Ok(fill
            * match self.mesh {
                N3Mesh::OGrid => 0.6 * GIB * (e / 30_500.0).powf(1.25),
                N3Mesh::Box => 1.6 * GIB * (e / 24_500.0).powf(1.8),
            })
    }

    /// The mesh this model uses.
    pub fn build_mesh(&self) -> Result<Mesh, FeError> {
        let g = self.effective_grading();
        let [lx, ly, lz] = self.size;
        let linear = match self.mesh {
            N3Mesh::Box => Mesh::graded_box(lx, ly, lz, g, g, g),
            N3Mesh::OGrid => Mesh::quarter_ogrid(
                lx,
                ly,
                lz,
                g,
                g,
                self.effective_core_cells(),
                self.circle_radius(),
            ),
        }?;
        match self.element {
            N3Element::Hex8 => Ok(linear),
            N3Element::Hex27 => linear.to_triquadratic(),
        }
    }

    /// The spacing of the nodes under the needle (mm): the grading's fine
    /// element size, halved for 27-node cells.
    fn node_spacing(&self) -> f64 {
        let h = self.effective_grading().h_fine;
        match self.element {
            N3Element::Hex8 => h,
            N3Element::Hex27 => 0.5 * h,
        }
    }

    /// The order of convergence of the force with the element size.
    /// Q1/P0: taken as N1's Q1/P0 order (1.22 at 10 mm), the same element
    /// family and contact in 3D; on N3 itself (h = 1.2, 0.8, 0.6 mm, NH,
    /// friction 0.8) the observed order is 3.9 at 2 mm and 1.7 at 5 mm, and
    /// at 10 mm the differences do not yet shrink, so the estimate is
    /// indicative at large depth. Q2/P1: 3, below the 3.8 observed at 10 mm
    /// on the O-grid cells of 1.6, 1.2 and 0.8 mm (NH, friction 0.8; more
    /// than 4 at 5 mm, none at 2 mm where the three differ by less than
    /// 0.7 %); with it the level-1 estimate from the 3.2 mm companion is
    /// +0.56 % at 10 mm, the three meshes' extrapolation +0.58 % (order 2
    /// would say +1.33 %) (docs/validation/fe.md, N3).
    pub fn convergence_order(&self) -> ConvergenceOrder {
        match self.element {
            N3Element::Hex8 => ConvergenceOrder {
                order: 1.22,
                source: "N1 Q1/P0 order (docs/validation/fe.md N1 speed); N3 at 10 mm is not in the asymptotic range (fe.md N3)"
                    .to_string(),
            },
            N3Element::Hex27 => ConvergenceOrder {
                order: 3.0,
                source: "N3 Q2/P1, below the 3.8 observed at 10 mm on 1.6/1.2/0.8 mm cells (docs/validation/fe.md N3)"
                    .to_string(),
            },
        }
    }

    /// A depth of half the block height or more is refused
    /// ([`N3Needle::simulate`]).
    fn check_depth(&self, loading: &Loading) -> Result<(), ForwardError> {
        let max = loading.drive.iter().cloned().fold(0.0, f64::max);
        if max >= 0.5 * self.size[2] {
            return Err(ForwardError::InvalidLoading(format!(
                "a depth of {max} mm is beyond what the {} mm block allows (at most half its height)",
                self.size[2]
            )));
        }
        Ok(())
    }
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// `MemAvailable` of `/proc/meminfo` (bytes); `None` off Linux.
fn available_memory() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kib: f64 = s
        .lines()
        .find(|l| l.starts_with("MemAvailable:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some(kib * 1024.0)
}

impl Setup for N3Setup {
    type Parts = N3Parts;
    fn law(&self) -> &Law {
        &self.law
    }
    fn set_law(&mut self, law: Law) {
        self.law = law;
    }
    fn param_space(&self) -> ParamSpace {
        let law = law_space(&self.law);
        if self.friction_is_parameter {
            law.extended(&[friction_param(self.friction)])
        } else {
            law
        }
    }
    fn bulk(&self) -> Bulk {
        self.bulk
    }
    fn options(&self) -> SolverOptions {
        self.options
    }
    fn build(&self) -> Result<(System, N3Parts), FeError> {
        if !(self.friction >= 0.0 && self.friction.is_finite()) {
            return Err(FeError::InvalidConfig {
                field: "friction".into(),
                reason: format!("{} must be >= 0", self.friction),
            });
        }
        if !self.start_gap.is_finite() {
            return Err(FeError::InvalidConfig {
                field: "start_gap".into(),
                reason: format!("{} is not a height", self.start_gap),
            });
        }
        let need = self.memory_estimate()?;
        if let Some(available) = available_memory() {
            if need > available {
                return Err(FeError::InvalidConfig {
                    field: "mesh".into(),
                    reason: format!(
                        "this N3 mesh would need about {:.1} GiB, more than the {:.1} GiB available; use a coarser mesh",
                        need / GIB,
                        available / GIB
                    ),
                });
            }
        }
        let mesh = self.build_mesh()?;
        let kin = Kinematics::ThreeD;
        let body = SolidBody::new(
            "body",
            &mesh,
            &["body"],
            match self.element {
                N3Element::Hex8 => kernel_for(CellType::Hex8, kin, PressureSpace::P0)?,
                N3Element::Hex27 => kernel_for(CellType::Hex27, kin, PressureSpace::P1)?,
            },
            self.bulk.exact(),
        )?;
        let mut bcs: Vec<Dirichlet> = (0..3).map(|k| Dirichlet::fixed("bottom", k)).collect();
        bcs.push(Dirichlet::fixed("x0", 0));
        bcs.push(Dirichlet::fixed("y0", 1));
        let options = ContactOptions {
            friction: self.friction,
            penalty_normal: 0.0,
            penalty_tangent: 0.0,
            penetration_tol: self.penetration_tol,
            points: self.contact_points,
        };
        let motion = ToolMotion::translating(
            [0.0, 0.0, self.size[2] + self.start_gap],
            vec![(0, [0.0, 0.0, -1.0])],
        );
        let contact = RigidContact::new(
            &self.tool.name(),
            Box::new(Revolution3d(self.tool)),
            motion,
            &mesh,
            "top",
            kin,
            options,
            1,
        )?;
        let mut parts = Parts::new();
        let handles = N3Parts {
            body: parts.add(body),
            contact: parts.add(contact),
        };
        Ok((System::from_parts(mesh, 3, parts, &bcs, 1)?, handles))
    }
    fn prepare(
        &self,
        sys: &mut System,
        parts: &N3Parts,
        material: RegionMaterial,
        extra: &[f64],
    ) -> Result<(), FeError> {
        let mu = material.material.shear_modulus();
        let h = self.node_spacing();
        sys.force_floor = 1e-6 * mu * sys.mesh.min_edge().powi(2);
        sys.get_mut(parts.body)?.set_material("body", material)?;
        let cs = sys.get_mut(parts.contact)?;
        cs.smoothing = self.contact_smoothing * h;
        cs.options.penalty_normal = self.penalty * mu / h;
        cs.options.penalty_tangent = self.penalty * mu / h;
        cs.options.friction = if self.friction_is_parameter {
            extra.first().copied().unwrap_or(self.friction)
        } else {
            self.friction
        };
        Ok(())
    }
    fn observe(&self, sys: &System, parts: &N3Parts) -> Vec<f64> {
        vec![
            4.0 * sys
                .get(parts.contact)
                .and_then(|c| c.tool_force([0.0, 0.0, -1.0]))
                .unwrap_or(0.0),
        ]
    }
    fn check_loading(&self, loading: &Loading) -> Result<(), ForwardError> {
        self.check_depth(loading)
    }
    fn name(&self) -> String {
        format!(
            "N3 FE needle indentation (3D quarter block), {}, friction {}",
            self.law, self.friction
        )
    }
    fn effects(&self) -> Option<Vec<Effect>> {
        let mut v = Vec::new();
        if !self.friction_is_parameter {
            v.push(Effect::Friction);
        }
        v.push(Effect::ZeroOffset);
        Some(v)
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        match effect {
            Effect::Friction if !self.friction_is_parameter => {
                let mut m = self.clone();
                m.friction_is_parameter = true;
                Ok(Box::new(FeModel::from_setup(m)))
            }
            Effect::ZeroOffset => Ok(Box::new(ZeroOffset::from_arc(Arc::new(
                FeModel::from_setup(self.clone()),
            )))),
            _ => Err(not_applicable(effect, &self.name())),
        }
    }
}
