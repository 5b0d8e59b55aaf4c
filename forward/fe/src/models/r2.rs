//! `R2Rolling`: rolling indentation of a silicone block with bonded stiff
//! nodules (docs/benchmarks.md R2 and R2-1), 2D plane stress — a block 150 mm
//! long and 30 mm high, 50 mm thick out of plane (the forces are for the
//! whole thickness), bottom fixed, circular nodules of diameter 10 mm
//! perfectly bonded (a conforming mesh, [`InclusionBlock`]), and a rigid
//! wheel of diameter 8 mm ([`Wheel2d`]) pressed to the rolling depth RD at
//! x = 10 mm and rolled at that depth to x = 140 mm, rolling without slip
//! ([`ToolMotion::rolling`]; frictionless by default, Coulomb friction on
//! request).
//!
//! Two loading channels drive the wheel: 0 its depth (down), 1 its travel
//! along x from the pressing position. A [`Loading`] is read in one of two
//! ways:
//!
//! * `Drive::PositionMm` — the rolled pass: the wheel is pressed to `rd`
//!   at `press_x` (a preload, not reported), then rolled through the given
//!   wheel-centre positions (increasing, within `press_x..=roll_to`).
//! * `Drive::DisplacementMm` — the pressing phase: the wheel at `press_x`
//!   pressed through the given depths.
//!
//! Outputs per sample: `force_N`, the vertical force of the wheel on the
//! block (positive in compression), and `force_x_N`, its force along +x
//! (the force that pushes the block forward, i.e. the rolling resistance
//! the drive must overcome; zero for a symmetric frictionless contact).
//!
//! Elements: 9-node plane-stress quadrilaterals (incompressibility through
//! the thickness stretch, no pressure field: plane stress cannot lock), the
//! mid-edge nodes on the nodule circles placed on the circles. Contact at
//! the two... three Gauss points of each top facet (augmented Lagrangian,
//! multipliers updated once per increment).
//!
//! Parameters: the tissue law's, then the nodule law's (named `nodule_...`).
//! The geometry (nodule positions and depths, RD) is part of the model, so
//! a change of geometry is a new model ([`R2Rolling::with_nodules`]).

use palpate_core::{Drive, ForwardError, Loading, Observable, Output, ParamSpace, ParamSpec};
use palpate_material::Law;
use rayon::prelude::*;
use std::sync::Arc;

use crate::body::{RegionMaterial, SolidBody};
use crate::contact::{ContactOptions, ContactPoints, RigidContact};
use crate::contribution::Contribution;
use crate::discretisation::{Coarser, ConvergenceOrder};
use crate::dofs::Dirichlet;
use crate::kernel::{kernel_for, PressureSpace};
use crate::kinematics::Kinematics;
use crate::line_search::LineSearch;
use crate::material::LawMaterial;
use crate::mesh::{CellType, InclusionBlock, Mesh};
use crate::model::{law_space, Bulk, FeModel, Path, Setup, Support};
use crate::motion::ToolMotion;
use crate::predictor::FollowTool;
use crate::stepper::{LoadPath, Progress};
use crate::surface::Wheel2d;
use crate::system::{Part, Parts, SolverOptions, System};
use crate::FeError;

/// A nodule: centre position along the block and depth of its centre below
/// the top surface (mm).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Nodule {
    pub x: f64,
    pub depth: f64,
}

impl Nodule {
    /// docs/benchmarks.md R2's three nodules.
    pub fn r2_default() -> Vec<Nodule> {
        vec![
            Nodule {
                x: 37.5,
                depth: 10.0,
            },
            Nodule {
                x: 75.0,
                depth: 15.0,
            },
            Nodule {
                x: 112.5,
                depth: 20.0,
            },
        ]
    }

    /// Parses `X:DEPTH,X:DEPTH,...` (mm); `none` is no nodule.
    pub fn parse_list(text: &str) -> Result<Vec<Nodule>, String> {
        let t = text.trim();
        if t.eq_ignore_ascii_case("none") {
            return Ok(Vec::new());
        }
        t.split(',')
            .map(|item| {
                let (x, d) = item
                    .split_once(':')
                    .ok_or_else(|| format!("`{item}`: expected X:DEPTH (mm), e.g. 75:15"))?;
                let num = |s: &str, what: &str| {
                    s.trim()
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| format!("`{item}`: {what} `{s}` is not a number"))
                };
                Ok(Nodule {
                    x: num(x, "x")?,
                    depth: num(d, "depth")?,
                })
            })
            .collect()
    }
}

/// Mesh level `n`: 9-node elements of `2 / n` mm along the top surface and
/// around the nodules (1 coarse, 2 medium, 3 fine = 0.67 mm), uniform over a
/// 3 mm band under the surface, rows growing by 1.25 below it.
pub fn r2_element_size(level: usize) -> f64 {
    2.0 / level.max(1) as f64
}

/// The R2 model: [`R2Setup`] as a forward model.
pub type R2Rolling = FeModel<R2Setup>;

/// The R2 experiment ([`R2Rolling`]).
#[derive(Debug, Clone, PartialEq)]
pub struct R2Setup {
    /// The tissue (block) law; its parameters come first in `theta`.
    law: Law,
    /// The nodules' law; its parameters follow the tissue's.
    nodule_law: Law,
    pub bulk: Bulk,
    /// Rolling depth (mm) of the rolled pass.
    pub rd: f64,
    pub nodules: Vec<Nodule>,
    pub nodule_radius: f64,
    pub wheel_radius: f64,
    /// Block length, height and out-of-plane thickness (mm).
    pub length: f64,
    pub height: f64,
    pub thickness: f64,
    /// Where the wheel is pressed, and the last position of the rolled path
    /// (mm).
    pub press_x: f64,
    pub roll_to: f64,
    pub friction: f64,
    /// Bottom support: bonded (both components fixed, docs/benchmarks.md R2) or
    /// sliding (vertical component fixed, horizontal free except at the
    /// bottom node nearest mid-block, which removes the rigid translation).
    pub base: Support,
    /// Mesh level ([`r2_element_size`]).
    pub level: usize,
    /// When set, replaces the element size of `level` (mm).
    pub element_size: Option<f64>,
    /// Contact penalty factor: `eps = penalty * mu0 / h` (augmented once per
    /// increment).
    pub penalty: f64,
    /// Contact by a pure penalty ([`RigidContact::pure_penalty`]): the
    /// state is a function of the wheel position alone (frictionless).
    pub pure_penalty: bool,
    /// Softened contact onset width (mm, [`RigidContact::smoothing`]).
    pub contact_smoothing: f64,
    /// The predictor of each rolled increment: `Some(order)` the field
    /// carried with the wheel ([`FollowTool`], order 0 shifted, 1 the
    /// secant in the wheel's frame); `None` the stepper's secant.
    pub predictor: Option<usize>,
    /// Tangential (stick) penalty as a fraction of the normal one (with
    /// friction only). Default 0.1: with the normal one (1000 mu / h) the
    /// stick band is ~0.006 mm of elastic slip and Newton cannot settle
    /// the stick/slip state of the points under a rolling wheel (friction
    /// 0.5 on the 2 mm development mesh: no convergence at the first rolled
    /// increment after 12 cuts); at 0.1 the pass converges on 2 and 1 mm
    /// meshes, and the force moves by 0.18 % (0.01), 0.025 % (0.3) against
    /// 0.1, i.e. ~0.04 % from the stiff-stick limit by the 1/eps_T trend
    /// (docs/validation/fe.md, R2 friction).
    pub tangent_penalty: f64,
    pub options: SolverOptions,
}

/// The contributions of the R2 system.
#[derive(Debug, Clone, Copy)]
pub struct R2Parts {
    body: Part<SolidBody>,
    contact: Part<RigidContact>,
}

impl R2Rolling {
    /// docs/benchmarks.md R2 with the given laws (`rtv6166-ab` and `rubber-ab`
    /// are Arruda-Boyce for both): three nodules, RD `rd`, frictionless,
    /// exact incompressibility, mesh level 1.
    pub fn new(law: Law, nodule_law: Law, rd: f64) -> Self {
        FeModel::from_setup(R2Setup {
            law,
            nodule_law,
            bulk: Bulk::Exact,
            rd,
            nodules: Nodule::r2_default(),
            nodule_radius: 5.0,
            wheel_radius: 4.0,
            length: 150.0,
            height: 30.0,
            thickness: 50.0,
            press_x: 10.0,
            roll_to: 140.0,
            friction: 0.0,
            base: Support::Bonded,
            level: 1,
            element_size: None,
            penalty: 1000.0,
            pure_penalty: true,
            contact_smoothing: 0.01,
            predictor: Some(0),
            tangent_penalty: 0.1,
            options: SolverOptions {
                max_step: 0.5,
                first_step: 0.25,
                max_augmentations: 0,
                // frictionless: a potential problem, so the slope search
                // (no update cap needed) and a fresh factorisation at every
                // iteration (the supernodal LDL^T costs less than the chord
                // steps it saves); `options()` goes back to the residual
                // search, the 0.3 mm cap and chord steps with friction.
                // Short pass x 52 -> 62 mm (docs/validation/fe.md):
                // 276 -> 205 iterations, 18.7 -> 9.3 s wall.
                max_update: None,
                line_search: LineSearch::Slope,
                reuse_factorisation: false,
                tolerance: 1e-7,
                // hyperelastic plane stress without pressure unknowns and
                // frictionless contact: a symmetric tangent (`options()`
                // turns it off with friction)
                symmetric: true,
                ..SolverOptions::default()
            },
        })
    }

    /// docs/benchmarks.md's materials: `rtv6166-ab` (mu 4.98 kPa, lambda_m 1.05)
    /// for the tissue, `rubber-ab` (mu 73.40 kPa, lambda_m 1.01) for the
    /// nodules, in the model's parameter order (MPa).
    pub const BENCHMARK_PARAMS: [f64; 4] = [4.98e-3, 1.05, 73.40e-3, 1.01];

    /// The same model with other nodules.
    pub fn with_nodules(&self, nodules: Vec<Nodule>) -> Self {
        let mut m = self.clone();
        m.nodules = nodules;
        m
    }

    /// The coarser companion of the error estimate: elements twice as large.
    pub fn coarser(&self) -> Coarser<R2Rolling> {
        let h = 2.0 * self.h();
        self.companion(2.0, format!("{h} mm elements"), |s| {
            s.element_size = Some(h)
        })
    }
}

impl R2Setup {
    /// The element size in use (mm).
    pub fn h(&self) -> f64 {
        self.element_size
            .unwrap_or_else(|| r2_element_size(self.level))
    }

    /// The mesh generator's description of this block.
    pub fn block(&self) -> InclusionBlock {
        InclusionBlock {
            width: self.length,
            height: self.height,
            centres: self
                .nodules
                .iter()
                .map(|n| [n.x, self.height - n.depth])
                .collect(),
            radius: self.nodule_radius,
            h: self.h(),
            band: 3.0,
            growth: 1.25,
            ring: 2.0,
        }
    }

    /// The mesh this model uses.
    pub fn build_mesh(&self) -> Result<Mesh, FeError> {
        self.block().mesh()
    }

    /// The positions of a full pass every `step` mm (`press_x` to
    /// `roll_to`).
    pub fn pass_positions(&self, step: f64) -> Vec<f64> {
        let n = ((self.roll_to - self.press_x) / step).round().max(1.0) as usize;
        (0..=n)
            .map(|k| self.press_x + (self.roll_to - self.press_x) * k as f64 / n as f64)
            .collect()
    }

    /// The order of convergence of the force with the element size
    /// (docs/validation/fe.md, R2).
    pub fn convergence_order(&self) -> ConvergenceOrder {
        ConvergenceOrder {
            order: R2_ORDER,
            source: "docs/validation/fe.md R2 (h = 4, 2, 1 mm presses at RD 3: 0.93-8 by position, the smallest taken)".into(),
        }
    }
}

impl R2Rolling {
    /// The rolled pass through `positions` (increasing, within
    /// `press_x..=roll_to`), split into up to `segments` contiguous pieces
    /// solved in parallel (rayon tasks: safe to call from a rayon worker),
    /// each pressed to `rd` at its first
    /// position and rolled from there. Exact for a frictionless wheel with
    /// [`R2Setup::pure_penalty`] contact, whose state is a function of the
    /// wheel position alone (the press at x equals the rolled state at x,
    /// tests/integration/r2_rolling.rs); with friction (path-dependent) or augmented
    /// contact one segment is used whatever `segments` says.
    ///
    /// Returns `[force_N, force_x_N]` per position and the system at the
    /// last position (for VTK output). `progress` is called once per solved
    /// position, from any thread. On a failure, the error keeps the outputs
    /// of the positions before the first failed one.
    pub fn rolled_pass(
        &self,
        theta: &[f64],
        positions: &[f64],
        segments: usize,
        progress: Option<&(dyn Fn() + Sync)>,
    ) -> Result<(Vec<[f64; 2]>, Option<System>), ForwardError> {
        self.rolling_path(positions)?;
        let exact = self.friction == 0.0 && self.pure_penalty;
        let n = if exact {
            segments.clamp(1, positions.len().max(1))
        } else {
            1
        };
        let chunk = positions.len().div_ceil(n).max(1);
        let pieces: Vec<&[f64]> = positions.chunks(chunk).collect();
        type Piece = Result<(Vec<Vec<f64>>, System), ForwardError>;
        // Segments as rayon tasks, not threads of their own: a caller that
        // is itself a rayon worker (a design of runs) then lends its thread
        // to the segments and to the element loops inside them, where a
        // worker blocked on a plain thread join would starve the pool
        // those loops need (a deadlock once every worker waits so).
        let results: Vec<Piece> = pieces
            .par_iter()
            .map(|piece| {
                let run = || {
                    let mut model = self.clone();
                    model.press_x = piece[0];
                    let loading = Loading::quasi_static(Drive::PositionMm, piece.to_vec());
                    let mut report = |p: &Progress| {
                        if p.sample > 0 {
                            if let Some(f) = progress {
                                f();
                            }
                        }
                    };
                    model
                        .simulate(theta, &loading, Some(&mut report))
                        .map(|(sim, sys)| (sim.outputs, sys))
                };
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).unwrap_or_else(|_| {
                    Err(ForwardError::InvalidConfig {
                        field: "R2".into(),
                        reason: "a segment of the rolled pass panicked".into(),
                    })
                })
            })
            .collect();
        let mut out: Vec<[f64; 2]> = Vec::with_capacity(positions.len());
        let mut last = None;
        for r in results {
            match r {
                Ok((rows, sys)) => {
                    out.extend(rows.iter().map(|o| [o[0], o[1]]));
                    last = Some(sys);
                }
                Err(ForwardError::NotConverged {
                    sample,
                    drive,
                    cuts,
                    reason,
                    completed,
                }) => {
                    let before = out.len();
                    let mut done: Vec<f64> = out.iter().flat_map(|o| o.to_vec()).collect();
                    done.extend(completed);
                    return Err(ForwardError::NotConverged {
                        sample: before + sample,
                        drive,
                        cuts,
                        reason,
                        completed: done,
                    });
                }
                Err(e) => return Err(e),
            }
        }
        Ok((out, last))
    }
}

impl R2Setup {
    /// The nodules' law.
    pub fn nodule_law(&self) -> &Law {
        &self.nodule_law
    }

    /// Replaces the nodules' law (the parameter space follows).
    pub fn set_nodule_law(&mut self, law: Law) {
        self.nodule_law = law;
    }

    /// The weight of the wheel-following prediction per node
    /// ([`FollowTool::weights`]): 0 in the nodules and rising linearly to
    /// 1 at [`FOLLOW_FADE`] mm from their circles (a nodule does not
    /// travel with the wheel), 1 elsewhere.
    fn follow_weights(&self, mesh: &Mesh) -> Vec<f64> {
        let fade = FOLLOW_FADE;
        mesh.nodes
            .iter()
            .map(|x| {
                self.nodules
                    .iter()
                    .map(|n| {
                        let (cx, cy) = (n.x, self.height - n.depth);
                        let d =
                            ((x[0] - cx).powi(2) + (x[1] - cy).powi(2)).sqrt() - self.nodule_radius;
                        (d / fade).clamp(0.0, 1.0)
                    })
                    .fold(1.0, f64::min)
            })
            .collect()
    }

    /// Checks the scalars (the geometry of the nodules is the mesh
    /// generator's to check).
    fn check(&self) -> Result<(), FeError> {
        let bad = |field: &str, reason: String| FeError::InvalidConfig {
            field: field.into(),
            reason,
        };
        if !(self.rd > 0.0 && self.rd.is_finite()) {
            return Err(bad("rd", format!("{} mm must be > 0", self.rd)));
        }
        if self.rd >= 2.0 * self.wheel_radius {
            return Err(bad(
                "rd",
                format!(
                    "{} mm is deeper than the block allows for this wheel: the wheel (diameter {} mm) would sink entirely below the surface",
                    self.rd,
                    2.0 * self.wheel_radius
                ),
            ));
        }
        if !(self.friction >= 0.0 && self.friction.is_finite()) {
            return Err(bad("friction", format!("{} must be >= 0", self.friction)));
        }
        let r = self.wheel_radius;
        if !(self.press_x >= r && self.press_x <= self.roll_to && self.roll_to <= self.length - r) {
            return Err(bad(
                "press_x",
                format!(
                    "the wheel path {}..{} mm must lie within the block ({} mm long, wheel radius {r} mm)",
                    self.press_x, self.roll_to, self.length
                ),
            ));
        }
        Ok(())
    }

    /// The rolled-pass path: press to `rd` at `press_x` (one preload
    /// station), then the positions.
    fn rolling_path(&self, positions: &[f64]) -> Result<LoadPath, ForwardError> {
        let bad = |reason: String| ForwardError::InvalidLoading(reason);
        for (k, &x) in positions.iter().enumerate() {
            if !(x >= self.press_x - 1e-9 && x <= self.roll_to + 1e-9) {
                return Err(bad(format!(
                    "position {k} ({x} mm) is outside the rolled path {}..{} mm",
                    self.press_x, self.roll_to
                )));
            }
            if k > 0 && !(x > positions[k - 1]) {
                return Err(bad(format!(
                    "positions must increase: position {k} ({x} mm) follows {} mm",
                    positions[k - 1]
                )));
            }
        }
        let mut tau = vec![self.rd];
        let mut values = vec![vec![self.rd, 0.0]];
        for &x in positions {
            let travel = (x - self.press_x).max(0.0);
            tau.push(self.rd + travel);
            values.push(vec![self.rd, travel]);
        }
        let time = vec![0.0; tau.len()];
        Ok(LoadPath { tau, values, time })
    }
}

/// Checks a model's scalars (RD, friction, the wheel path) and its
/// geometry (every nodule inside the block, none overlapping another, far
/// enough apart in x for the mesh) without building anything: `(field,
/// reason)`, the field `rd`, `friction`, `press_x` or `nodules` (the reason
/// then names the nodule).
pub fn check_model(m: &R2Rolling) -> Result<(), (String, String)> {
    let split = |e: FeError| match e {
        FeError::InvalidConfig { field, reason } | FeError::InvalidMesh { field, reason } => {
            match field.as_str() {
                "rd" | "friction" | "press_x" => (field, reason),
                _ => ("nodules".to_string(), format!("{field} {reason}")),
            }
        }
        other => ("nodules".to_string(), other.to_string()),
    };
    m.check().map_err(split)?;
    m.block().check().map_err(split)
}

/// Distance from a nodule's circle (mm) over which the wheel-following
/// prediction fades in ([`R2Setup::follow_weights`]).
const FOLLOW_FADE: f64 = 5.0;

/// The order stated for the R2 force (docs/validation/fe.md, R2).
const R2_ORDER: f64 = 1.0;

impl Setup for R2Setup {
    type Parts = R2Parts;
    fn law(&self) -> &Law {
        &self.law
    }
    fn set_law(&mut self, law: Law) {
        self.law = law;
    }
    /// The tissue law's parameters, then the nodule law's (`nodule_...`).
    fn param_space(&self) -> ParamSpace {
        let nodule: Vec<ParamSpec> = law_space(&self.nodule_law)
            .params
            .iter()
            .map(|p| {
                let mut q = p.clone();
                q.name = format!("nodule_{}", p.name);
                q
            })
            .collect();
        law_space(&self.law).extended(&nodule)
    }
    fn bulk(&self) -> Bulk {
        self.bulk
    }
    fn options(&self) -> SolverOptions {
        if self.friction == 0.0 {
            return self.options;
        }
        // Coulomb friction makes the contact tangent unsymmetric and the
        // problem non-potential: LU, the residual search, a capped update
        // and chord steps (the settings the frictional passes were
        // measured with)
        SolverOptions {
            symmetric: false,
            line_search: LineSearch::Residual,
            max_update: self.options.max_update.or(Some(0.3)),
            reuse_factorisation: true,
            ..self.options
        }
    }
    fn build(&self) -> Result<(System, R2Parts), FeError> {
        self.check()?;
        let mut mesh = self.build_mesh()?;
        let kin = Kinematics::PlaneStress {
            thickness: self.thickness,
        };
        let mut regions = vec!["tissue"];
        if mesh.regions.contains_key("nodule") {
            regions.push("nodule");
        }
        let body = SolidBody::new(
            "block",
            &mesh,
            &regions,
            kernel_for(CellType::Quad9, kin, PressureSpace::None)?,
            false,
        )?;
        let bcs = match self.base {
            Support::Bonded => {
                vec![Dirichlet::fixed("bottom", 0), Dirichlet::fixed("bottom", 1)]
            }
            Support::Sliding => {
                let mid = self.length / 2.0;
                let anchor = mesh
                    .node_sets
                    .get("bottom")
                    .into_iter()
                    .flatten()
                    .copied()
                    .min_by(|&a, &b| {
                        (mesh.nodes[a][0] - mid)
                            .abs()
                            .total_cmp(&(mesh.nodes[b][0] - mid).abs())
                    })
                    .ok_or_else(|| FeError::InvalidMesh {
                        field: "bottom".into(),
                        reason: "the block has no bottom nodes".into(),
                    })?;
                mesh.node_sets.insert("bottom_anchor".into(), vec![anchor]);
                vec![
                    Dirichlet::fixed("bottom", 1),
                    Dirichlet::fixed("bottom_anchor", 0),
                ]
            }
        };
        let options = ContactOptions {
            friction: self.friction,
            penalty_normal: 0.0,
            penalty_tangent: 0.0,
            penetration_tol: 2e-3,
            points: ContactPoints::EdgeGauss,
        };
        let motion = ToolMotion::rolling(
            [self.press_x, self.height, 0.0],
            (0, [0.0, -1.0, 0.0]),
            (1, [1.0, 0.0, 0.0]),
            self.wheel_radius,
            2,
        );
        let mut contact = RigidContact::new(
            "wheel",
            Box::new(Wheel2d {
                radius: self.wheel_radius,
            }),
            motion,
            &mesh,
            "top",
            kin,
            options,
            2,
        )?;
        contact.pure_penalty = self.pure_penalty;
        contact.smoothing = self.contact_smoothing;
        let mut parts = Parts::new();
        let handles = R2Parts {
            body: parts.add(body),
            contact: parts.add(contact),
        };
        let mut sys = System::from_parts(mesh, 2, parts, &bcs, 2)?;
        if let Some(order) = self.predictor {
            let mut p = FollowTool::new(1, [1.0, 0.0, 0.0], order);
            p.weights = Some(self.follow_weights(&sys.mesh));
            sys.predictor = Some(Box::new(p));
        }
        Ok((sys, handles))
    }
    fn prepare(
        &self,
        sys: &mut System,
        parts: &R2Parts,
        material: RegionMaterial,
        extra: &[f64],
    ) -> Result<(), FeError> {
        let mu = material.material.shear_modulus();
        let h = self.h();
        sys.force_floor = 1e-6 * mu * self.thickness * h;
        let body = sys.get_mut(parts.body)?;
        body.set_material("tissue", material)?;
        if !self.nodules.is_empty() {
            let n = self.nodule_law.params().len();
            let p = extra.get(..n).ok_or_else(|| FeError::InvalidConfig {
                field: "nodule parameters".into(),
                reason: format!("{} needs {n} parameters", self.nodule_law),
            })?;
            let nodule = LawMaterial::new(self.nodule_law, p.to_vec())?;
            let mu_n = self.nodule_law.shear_modulus(p);
            body.set_material(
                "nodule",
                RegionMaterial {
                    material: Arc::new(nodule),
                    volumetric: self.bulk.volumetric(mu_n),
                },
            )?;
        }
        let cs = sys.get_mut(parts.contact)?;
        cs.options.penalty_normal = self.penalty * mu / h;
        cs.options.penalty_tangent = self.tangent_penalty * self.penalty * mu / h;
        cs.options.friction = self.friction;
        Ok(())
    }
    fn path(&self, loading: &Loading, _opts: &SolverOptions) -> Result<Path, ForwardError> {
        match loading.drive_kind {
            Drive::PositionMm => Ok(Path {
                path: self.rolling_path(&loading.drive)?,
                preload: 1,
            }),
            Drive::DisplacementMm => {
                if let Some((k, d)) = loading
                    .drive
                    .iter()
                    .enumerate()
                    .find(|(_, &d)| !(d >= 0.0 && d < 2.0 * self.wheel_radius))
                {
                    return Err(ForwardError::InvalidLoading(format!(
                        "depth {k} ({d} mm) must be >= 0 and less than the wheel diameter ({} mm)",
                        2.0 * self.wheel_radius
                    )));
                }
                let mut path = LoadPath::from_drive(&loading.drive);
                for v in path.values.iter_mut() {
                    v.push(0.0);
                }
                Ok(Path { path, preload: 0 })
            }
            other => Err(ForwardError::InvalidLoading(format!(
                "R2 is driven by {} (the rolled pass) or {} (pressing), got {}",
                Drive::PositionMm.column(),
                Drive::DisplacementMm.column(),
                other.column()
            ))),
        }
    }
    fn observe(&self, sys: &System, parts: &R2Parts) -> Vec<f64> {
        let force = |axis| {
            sys.get(parts.contact)
                .and_then(|c| c.tool_force(axis))
                .unwrap_or(0.0)
        };
        vec![force([0.0, -1.0, 0.0]), force([1.0, 0.0, 0.0])]
    }
    fn name(&self) -> String {
        let nodules: Vec<String> = self
            .nodules
            .iter()
            .map(|n| format!("{}:{}", n.x, n.depth))
            .collect();
        let base = match self.base {
            Support::Bonded => "",
            Support::Sliding => ", sliding base",
        };
        format!(
            "R2 FE rolling indentation (plane stress), RD {} mm, nodules {}, {} / {}, friction {}{base}",
            self.rd,
            if nodules.is_empty() {
                "none".to_string()
            } else {
                nodules.join(",")
            },
            self.law,
            self.nodule_law,
            self.friction
        )
    }
    fn outputs(&self) -> Vec<Output> {
        vec![
            Output::new("force_N", Observable::ForceN),
            Output::new("force_x_N", Observable::ForceN),
        ]
    }
}
