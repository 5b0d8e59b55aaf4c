//! `N1Needle`: needle indentation of a cylinder (docs/benchmarks.md N1) —
//! diameter 70 mm, height 80 mm, bottom fixed, a rigid needle (hemispherical
//! tip 2.5 mm tangent to a 15 degree cone) pressed on the axis with Coulomb
//! friction 0.8. The force is the needle reaction for the whole body,
//! positive in compression.
//!
//! The mesh is graded toward the indentation point ([`N1Setup::mesh`]); the
//! contact surface is the whole top face.
//!
//! The setup is the axisymmetric cylinder of any experiment description
//! ([`crate::cylinder`], [`N1Setup::from_experiment`]): any [`ToolShape`]
//! on the axis (a platen over the whole top), the tool's friction a number,
//! a parameter or infinite (bonded: a point sticks where it first touches),
//! the base bonded, sliding, or on a fixed rigid plane with Coulomb
//! friction ([`N1Setup::base_friction`], a number or a parameter),
//! horizontal bands of several materials ([`N1Setup::layers`]), Prony
//! terms fixed or as parameters, and a mesh by a sizing rule at any level
//! ([`Sizing`], [`N1Needle::with_level`]). N1 is the preset with none of
//! these. The effects of the gap diagnosis it offers are in
//! `models/n1_effects.rs`.

use palpate_core::enrichable::EffectForm;
use palpate_core::{Drive, Effect, ForwardError, ForwardModel, Loading, ParamSpace, ParamSpec};
use palpate_enrich::prony_params;
use palpate_material::Law;
use std::sync::Arc;

use crate::body::{RegionMaterial, SolidBody};
use crate::contact::{ContactOptions, ContactPoints, RigidContact};
use crate::contribution::Contribution;
use crate::discretisation::{Coarser, ConvergenceOrder};
use crate::dofs::Dirichlet;
use crate::kernel::kernel_for;
use crate::kinematics::Kinematics;
use crate::material::LawMaterial;
use crate::mesh::{Grading, Mesh, RimWindow};
use crate::model::{
    doubled, friction_param, graded_mesh_words, law_space, Bulk, FeModel, Path, PlaneCell, Setup,
    Support,
};
use crate::motion::ToolMotion;
use crate::stepper::LoadPath;
use crate::surface::{Floor2d, Profile2d};
use crate::system::{Part, Parts, SolverOptions, System};
use crate::tool::ToolShape;
use crate::viscoelastic::Prony;
use crate::FeError;

/// Mesh density of the N1 model: level `n` has elements of `0.4 / n` mm in a
/// 5 x 5 mm zone under the needle, growing by `1 + 0.2 / n` beyond it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeshDensity {
    pub level: usize,
}

impl MeshDensity {
    pub const COARSE: MeshDensity = MeshDensity { level: 1 };
    pub const MEDIUM: MeshDensity = MeshDensity { level: 2 };
    pub const FINE: MeshDensity = MeshDensity { level: 3 };

    /// The N1 speed-benchmark mesh (set it as [`N1Setup::grading`]):
    /// level 2's 0.2 mm elements in a 3 x 3 mm zone under the needle instead
    /// of 5 x 5, growing by 1.1 beyond it (2332 elements instead of 3286).
    /// The cheapest grading found that is as accurate as level 2 for the
    /// friction-0.8 needle: forces within 0.14 / 0.31 / 0.35 % of level 5's
    /// at 2 / 5 / 10 mm (level 2: 0.10 / 0.26 / 0.38 %) in two thirds of level 2's
    /// CPU time. A smaller zone or faster growth costs accuracy first (2 mm
    /// zone: 0.63 % at 10 mm; growth 1.3: 0.71 %) and a finer tip does not
    /// buy it back (0.1 mm in a 2 mm zone, growth 1.3: 1.26 %). Its accuracy
    /// is the favourable end of a ~0.15 % scatter at 10 mm from where the
    /// zone edge falls (2.8 or 3.2 mm: 0.50 / 0.47 % from level 5).
    /// docs/validation/fe.md, "N1 speed".
    pub const BENCH_GRADING: Grading = Grading {
        h_fine: 0.2,
        fine_length: 3.0,
        growth: 1.1,
    };

    /// Size of the fine elements (mm).
    pub fn h_fine(&self) -> f64 {
        0.4 / self.level.max(1) as f64
    }

    /// The grading of this level with a fine zone of `fine_length` mm.
    pub fn grading(&self, fine_length: f64) -> Grading {
        let n = self.level.max(1) as f64;
        Grading {
            h_fine: self.h_fine(),
            fine_length,
            growth: 1.0 + 0.2 / n,
        }
    }
}

/// The N1 model: [`N1Setup`] as a forward model.
pub type N1Needle = FeModel<N1Setup>;

/// The N1 experiment ([`N1Needle`]).
#[derive(Debug, Clone, PartialEq)]
pub struct N1Setup {
    pub(crate) law: Law,
    /// The law's parameter space when it is not [`law_space`]`(law)`: the
    /// richer law of the `material_form` enrichment, whose added modulus
    /// is >= 0.
    pub(crate) law_bounds: Option<ParamSpace>,
    pub bulk: Bulk,
    pub friction: f64,
    pub tool: ToolShape,
    pub base: Support,
    pub mesh: MeshDensity,
    /// When set, this grading (radial from the axis and axial from the top)
    /// replaces the one of `mesh` and `fine_zone`, e.g. for a contact zone
    /// much smaller than the needle's (Hertz).
    pub grading: Option<Grading>,
    /// Cylinder radius and height (mm).
    pub radius: f64,
    pub height: f64,
    /// Size of the uniformly fine zone under the tool (mm, radial and axial).
    pub fine_zone: f64,
    /// Contact penalty factor: `eps_N = penalty * mu0 / h_fine` (augmented, so
    /// the converged force does not depend on it).
    pub penalty: f64,
    /// Accepted penetration (mm) when an inner augmentation loop is enabled
    /// (`options.max_augmentations > 0`; off by default: the multipliers are
    /// updated once per converged increment, at commit, so the penetration
    /// of an increment only comes from its own load change).
    pub penetration_tol: f64,
    /// Where contact is enforced. Default: the two Gauss points of every
    /// surface edge, which keeps the element edges out of the curved tip
    /// (with contact at the nodes, frictionless neo-Hookean localises in one
    /// surface element and stalls near 7.6 mm; docs/validation/fe.md).
    pub contact_points: ContactPoints,
    /// The element: 4-node Q1/P0 (default, the validated one) or 9-node
    /// Q2/P1 on the same grading made quadratic (each cell of the grading
    /// becomes one 9-node cell: twice the nodes per direction).
    pub element: PlaneCell,
    /// A Prony series on the law's isochoric stress
    /// ([`crate::viscoelastic::Viscoelastic`], as C1 and Q1); `None`:
    /// elastic. A viscoelastic run needs timed loading and steps by at most
    /// `options.max_time_step` (a tenth of the shortest relaxation time
    /// when unset).
    pub prony: Option<Prony>,
    pub options: SolverOptions,
    /// Friction is the parameter after the law's (the `friction` effect).
    pub(crate) friction_is_parameter: bool,
    /// Number of Prony terms of the law's material taken from the
    /// parameters after the law's (`g1, tau1_s, ...`; 0: `prony` fixed).
    pub(crate) prony_parameters: usize,
    /// Horizontal bands of the cylinder from the top down: thickness (mm)
    /// and material (0: the law's, `k > 0`: `materials[k - 1]`); each band
    /// is its own region `layer{i}` with mesh lines at the interfaces.
    /// Empty: one region `body` (N1).
    pub layers: Vec<(f64, usize)>,
    /// The materials after the law's, in the order of their parameters.
    pub materials: Vec<BandMaterial>,
    /// `Some(mu)`: the base rests on a fixed rigid plane with Coulomb
    /// friction `mu` (unilateral; `base` is then not used); `None`: the
    /// base is held as `base` says.
    pub base_friction: Option<f64>,
    /// The base's friction coefficient is the last parameter.
    pub(crate) base_friction_is_parameter: bool,
    /// When set, the mesh is graded by this sizing rule at its level
    /// (unless `grading` is set): the rule of a described experiment.
    pub sizing: Option<Sizing>,
    /// The parameter space of a description (its names, bounds and
    /// starts); `None`: derived from the law and the options.
    pub(crate) space: Option<ParamSpace>,
    /// The name of the law's material (the prefix of its parameters when
    /// there are band materials).
    pub first_material: String,
    /// A band of the mesh graded towards a tool's edge (a flat punch's);
    /// `None`: the grading alone.
    pub edge_band: Option<EdgeBand>,
    /// The body is the upper half of a specimen compressed between two
    /// identical platens (a mirror plane at the base): the drive is the
    /// platens' travel, twice the half model's, and the force is the
    /// whole specimen's (the same through every horizontal section).
    pub mirror: bool,
    /// The specimen's thickness is the last parameter (`thickness_mm`, the
    /// `boundary_condition` effect of a described cylinder): each run
    /// meshes the specimen at that thickness ([`Setup::geometry`]).
    pub(crate) thickness_is_parameter: bool,
    /// The height (mm) whose axial mesh lines are stretched to `height`
    /// below the fine zone (the same cells at every thickness, so the force
    /// is smooth in it); `None`: the lines of `height`.
    pub(crate) mesh_height: Option<f64>,
}

/// The mesh about a tool's edge, where the contact pressure is singular (a
/// flat punch's rim at radius `r` on the top face): a window about it, of
/// half the smaller of `r` and the grading's fine zone, in which elements
/// of `h` mm at the edge grow by about `1 + slope` per element, radially
/// and in depth, until they meet the grading's ([`crate::mesh::rim`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EdgeBand {
    /// Radius of the edge (mm).
    pub r: f64,
    /// Element size at the edge (mm).
    pub h: f64,
    /// Growth of the size per unit distance from the edge.
    pub slope: f64,
}

/// A material of a band after the law's ([`N1Setup::layers`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BandMaterial {
    /// The material's name (its parameters are prefixed with it).
    pub name: String,
    pub law: Law,
    pub bulk: Bulk,
    /// A fixed Prony series on its isochoric stress.
    pub prony: Option<Prony>,
    /// Prony terms taken from the parameters after its law's.
    pub prony_parameters: usize,
}

impl BandMaterial {
    /// The number of its parameters (law, then Prony terms).
    fn param_count(&self) -> usize {
        self.law.params().len() + 2 * self.prony_parameters
    }
}

/// The mesh of a described experiment: at level `level`, elements of
/// `h / level` mm in a zone of `fine_zone` mm (radial from the axis and
/// axial from the top) growing by `1 + growth / level` beyond it. The
/// needle's rule with `h = 0.4`, `fine_zone = 5`, `growth = 0.2` is N1's
/// [`MeshDensity`] at integer levels, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sizing {
    pub h: f64,
    pub fine_zone: f64,
    pub growth: f64,
    /// Any level > 0 (elements scale as `1 / level`).
    pub level: f64,
}

impl Sizing {
    /// N1's rule ([`MeshDensity`]) at `level`.
    pub fn needle(level: f64) -> Sizing {
        Sizing {
            h: 0.4,
            fine_zone: 5.0,
            growth: 0.2,
            level,
        }
    }

    /// The grading at this level.
    pub fn grading(&self) -> Grading {
        Grading {
            h_fine: self.h / self.level,
            fine_length: self.fine_zone,
            growth: 1.0 + self.growth / self.level,
        }
    }
}

/// The contributions of the N1 system.
#[derive(Debug, Clone, Copy)]
pub struct N1Parts {
    body: Part<SolidBody>,
    contact: Part<RigidContact>,
    /// The rigid base and the element size along it.
    base: Option<(Part<RigidContact>, f64)>,
}

impl N1Needle {
    /// docs/benchmarks.md N1 with the given law: friction 0.8, bonded base, exact
    /// incompressibility, medium mesh, contact at the edge Gauss points with
    /// the multipliers updated once per increment.
    pub fn new(law: Law) -> Self {
        FeModel::from_setup(N1Setup {
            law,
            law_bounds: None,
            bulk: Bulk::Exact,
            friction: 0.8,
            tool: ToolShape::n1_needle(),
            base: Support::Bonded,
            mesh: MeshDensity::MEDIUM,
            grading: None,
            radius: 35.0,
            height: 80.0,
            fine_zone: 5.0,
            penalty: 100.0,
            penetration_tol: 2e-3,
            contact_points: ContactPoints::EdgeGauss,
            element: PlaneCell::Quad4,
            prony: None,
            options: SolverOptions {
                max_step: 0.25,
                first_step: 0.05,
                // An inner augmentation loop chatters where the cap meets the
                // cone (a contact point alternating between them): update the
                // multipliers once per increment instead (Uzawa at commit).
                max_augmentations: 0,
                // A viscoelastic frictional history (friction 0.8, the
                // real-time surrogate's held-out history 1 to 5 mm) stalled
                // at 3.83 mm after 12 step cuts; proximal steps carry it
                // through. Only failing increments use them, so
                // every run that converged before is unchanged.
                stabilisation: 0.1,
                ..SolverOptions::default()
            },
            friction_is_parameter: false,
            prony_parameters: 0,
            layers: Vec::new(),
            materials: Vec::new(),
            base_friction: None,
            base_friction_is_parameter: false,
            sizing: None,
            space: None,
            first_material: "body".into(),
            edge_band: None,
            mirror: false,
            thickness_is_parameter: false,
            mesh_height: None,
        })
    }

    /// The same experiment meshed at `level` (> 0; any real: element sizes
    /// scale as `1 / level`) by its sizing rule (N1's [`MeshDensity`] rule
    /// for a model without one), e.g. for a mesh chosen for an accuracy.
    pub fn with_level(&self, level: f64) -> N1Needle {
        let mut s = self.setup().clone();
        let rule = s.sizing.unwrap_or_else(|| Sizing {
            fine_zone: s.fine_zone,
            ..Sizing::needle(level)
        });
        s.sizing = Some(Sizing { level, ..rule });
        s.grading = None;
        FeModel::from_setup(s)
    }

    /// The coarser companion of the discretisation error estimate: the same
    /// mesh family with elements twice as large (fine size and `growth - 1`
    /// doubled, fine zone kept), so level L gives level L/2 (level 2 ->
    /// level 1) and level 1, which has no coarser level, gets 0.8 mm
    /// elements growing by 1.4.
    pub fn coarser(&self) -> Coarser<N1Needle> {
        let coarse = doubled(self.effective_grading());
        let edge = self.edge_band.map_or(0.0, |b| self.edge_size(&b));
        self.companion(2.0, graded_mesh_words(coarse, "tool"), |s| {
            s.grading = Some(coarse);
            if let Some(b) = &mut s.edge_band {
                b.h = 2.0 * edge;
            }
        })
    }
}

impl N1Setup {
    /// The mesh this model uses.
    pub fn build_mesh(&self) -> Result<Mesh, FeError> {
        let g = self.effective_grading();
        let m = match (self.edge_band, self.stretch()) {
            (None, None) => {
                Mesh::graded_layers(self.radius, self.height, g, g, &self.interfaces())?
            }
            (None, Some(map)) => Mesh::lines_in_layers(
                &g.positions(self.radius)?,
                &map.apply(&g.positions(map.from)?),
                self.height,
                &self.interfaces(),
            )?,
            (Some(b), map) => {
                let ts = match map {
                    None => g.positions(self.height)?,
                    Some(map) => map.apply(&g.positions(map.from)?),
                };
                let window = RimWindow {
                    centre: b.r,
                    half_width: 0.5 * b.r.min(g.fine_length),
                    spacing: g.h_fine,
                    h: self.edge_size(&b),
                    slope: b.slope,
                };
                Mesh::rim_refined(
                    &g.positions(self.radius)?,
                    &ts,
                    self.height,
                    &self.interfaces(),
                    window,
                )?
            }
        };
        match self.element {
            PlaneCell::Quad4 => Ok(m),
            PlaneCell::Quad9 => m.to_quadratic(),
        }
    }

    /// The element size at a tool's edge (mm): the band's `h` at the
    /// sizing rule's level (`h / level`), `h` without a rule.
    fn edge_size(&self, b: &EdgeBand) -> f64 {
        match (self.grading, self.sizing) {
            (None, Some(s)) => b.h / s.level,
            _ => b.h,
        }
    }

    /// The drive (the tool's or the platens' travel) over the modelled
    /// body's: 2 for the upper half of a mirrored specimen, else 1.
    fn drive_scale_inverse(&self) -> f64 {
        if self.mirror {
            2.0
        } else {
            1.0
        }
    }

    /// The grading in use (radial from the axis and axial from the top).
    pub fn effective_grading(&self) -> Grading {
        self.grading.unwrap_or_else(|| match self.sizing {
            Some(s) => s.grading(),
            None => self.mesh.grading(self.fine_zone),
        })
    }

    /// The depths of the band interfaces below the top (mm).
    fn interfaces(&self) -> Vec<f64> {
        let mut t = 0.0;
        let mut out = Vec::new();
        for (thickness, _) in self.layers.iter().take(self.layers.len().saturating_sub(1)) {
            t += thickness;
            out.push(t);
        }
        out
    }

    /// The regions of the body.
    fn regions(&self) -> Vec<String> {
        if self.layers.is_empty() {
            vec!["body".into()]
        } else {
            (0..self.layers.len())
                .map(|i| format!("layer{i}"))
                .collect()
        }
    }

    /// Number of Prony terms of the law's material taken from the
    /// parameters.
    pub fn prony_parameters(&self) -> usize {
        self.prony_parameters
    }

    /// Whether the tool's friction is a parameter.
    pub fn friction_is_parameter(&self) -> bool {
        self.friction_is_parameter
    }

    /// Whether the base's friction is a parameter.
    pub fn base_friction_is_parameter(&self) -> bool {
        self.base_friction_is_parameter
    }

    /// The number of parameters after the law's.
    pub(super) fn extra_len(&self) -> usize {
        2 * self.prony_parameters
            + self
                .materials
                .iter()
                .map(BandMaterial::param_count)
                .sum::<usize>()
            + usize::from(self.friction_is_parameter)
            + usize::from(self.base_friction_is_parameter)
            + usize::from(self.thickness_is_parameter)
    }

    /// The parameters after the law's: its Prony terms, then each band
    /// material's, then the tool's and the base's friction; `(prony of the
    /// law, per material its slice, friction, base friction)`.
    #[allow(clippy::type_complexity)]
    fn split_extra<'a>(
        &self,
        extra: &'a [f64],
    ) -> Result<(&'a [f64], Vec<&'a [f64]>, Option<f64>, Option<f64>), FeError> {
        let need = self.extra_len();
        if extra.len() < need {
            return Err(FeError::InvalidConfig {
                field: "parameters".into(),
                reason: format!(
                    "{} parameters after the law's, {need} expected",
                    extra.len()
                ),
            });
        }
        let (prony, mut rest) = extra.split_at(2 * self.prony_parameters);
        let mut mats = Vec::new();
        for m in &self.materials {
            let (p, r) = rest.split_at(m.param_count());
            mats.push(p);
            rest = r;
        }
        let mut next = rest.iter().copied();
        let friction = if self.friction_is_parameter {
            next.next()
        } else {
            None
        };
        let base = if self.base_friction_is_parameter {
            next.next()
        } else {
            None
        };
        Ok((prony, mats, friction, base))
    }

    /// The order of convergence of the force with the element size. Q1/P0,
    /// from docs/validation/fe.md ("N1 speed", the converged force): levels 2, 3
    /// and 5 with 0.125 mm increments, neo-Hookean, friction 0.8, 1.22 at
    /// 10 mm. It is the lowest order measured for this family (levels 1-3:
    /// 2.71 / 1.71 / 1.51 at 2 / 5 / 10 mm; 3-4-5: 1.46 at 10 mm), so the
    /// estimate errs on the large side.
    pub fn convergence_order(&self) -> ConvergenceOrder {
        let (order, mut source) = match self.element {
            PlaneCell::Quad4 => (
                1.22,
                "docs/validation/fe.md N1 speed (levels 2, 3, 5, friction 0.8, at 10 mm)"
                    .to_string(),
            ),
            // Q2/P1 on gradings 1.0/2/1.5, 0.5/2/1.25, 0.25/2/1.125 with
            // 0.125 mm increments: observed order 0.9 at 5 mm, larger at
            // 10 mm (the finest two agree to 0.006 %), non-monotone at
            // 2 mm; the smallest is taken.
            PlaneCell::Quad9 => (
                0.9,
                "docs/validation/fe.md N1 speed, Q2/P1 convergence (h 1, 0.5, 0.25 mm, at 5 mm)"
                    .to_string(),
            ),
        };
        if self.tool != ToolShape::n1_needle() {
            source.push_str("; measured for the needle, not for this tool");
        }
        ConvergenceOrder { order, source }
    }
}

impl Setup for N1Setup {
    type Parts = N1Parts;
    fn law(&self) -> &Law {
        &self.law
    }
    fn set_law(&mut self, law: Law) {
        self.law = law;
        self.law_bounds = None;
        self.space = None;
    }
    fn param_space(&self) -> ParamSpace {
        if let Some(space) = &self.space {
            return space.clone();
        }
        let law = self
            .law_bounds
            .clone()
            .unwrap_or_else(|| law_space(&self.law));
        let prefixed = !self.materials.is_empty();
        let prefix = |space: ParamSpace, name: &str| -> Vec<ParamSpec> {
            space
                .params
                .iter()
                .map(|p| ParamSpec {
                    name: if prefixed {
                        format!("{name}_{}", p.name)
                    } else {
                        p.name.clone()
                    },
                    ..p.clone()
                })
                .collect()
        };
        let mut specs = prefix(
            law.extended(&prony_params(self.prony_parameters)),
            &self.first_material,
        );
        for m in &self.materials {
            specs.extend(prefix(
                law_space(&m.law).extended(&prony_params(m.prony_parameters)),
                &m.name,
            ));
        }
        if self.friction_is_parameter {
            specs.push(friction_param(self.friction));
        }
        if self.base_friction_is_parameter {
            specs.push(ParamSpec {
                name: "base_friction".into(),
                ..friction_param(self.base_friction.unwrap_or(0.0))
            });
        }
        if self.thickness_is_parameter {
            specs.push(self.thickness_param());
        }
        ParamSpace::new(specs)
    }
    fn bulk(&self) -> Bulk {
        self.bulk
    }
    fn prony(&self) -> Option<&Prony> {
        self.prony.as_ref()
    }
    fn prony_for(&self, extra: &[f64]) -> Result<Option<Prony>, FeError> {
        if self.prony_parameters == 0 {
            return Ok(self.prony.clone());
        }
        prony_of(&extra[..(2 * self.prony_parameters).min(extra.len())]).map(Some)
    }
    fn options(&self) -> SolverOptions {
        let mut o = self.options;
        // a band material's relaxation sets the time step when the law's
        // material is elastic (the run sets it from the law's otherwise)
        if o.max_time_step.is_none() && self.prony.is_none() && self.prony_parameters == 0 {
            let shortest = self
                .materials
                .iter()
                .filter_map(|m| m.prony.as_ref().map(Prony::shortest_time))
                .fold(f64::INFINITY, f64::min);
            if shortest.is_finite() {
                o.max_time_step = Some(0.1 * shortest);
            }
        }
        o
    }
    fn check_loading(&self, loading: &Loading) -> Result<(), ForwardError> {
        let viscous = self
            .materials
            .iter()
            .any(|m| m.prony.is_some() || m.prony_parameters > 0);
        if viscous && loading.time.is_none() {
            return Err(ForwardError::InvalidLoading(
                "a viscoelastic material needs the time of each sample".into(),
            ));
        }
        let reach = self.drive_scale_inverse() * self.height;
        if let Some(&d) = loading
            .drive
            .iter()
            .find(|&&d| !(d.is_finite() && d < reach))
        {
            return Err(ForwardError::InvalidLoading(if self.mirror {
                format!("a travel of {d} mm: the platens must stay apart (the specimen is {reach} mm high)")
            } else {
                format!(
                    "a depth of {d} mm: the tool must stay above the base ({} mm below the top)",
                    self.height
                )
            }));
        }
        Ok(())
    }
    /// The default path ([`Setup::path`]) of the tool's travel in the
    /// modelled body: half the platens' travel for a mirrored half.
    fn path(&self, loading: &Loading, opts: &SolverOptions) -> Result<Path, ForwardError> {
        if loading.drive_kind != Drive::DisplacementMm {
            return Err(ForwardError::InvalidLoading(format!(
                "FE models are driven by {}, got {}",
                Drive::DisplacementMm.column(),
                loading.drive_kind.column()
            )));
        }
        let scale = 1.0 / self.drive_scale_inverse();
        let drive: Vec<f64> = loading.drive.iter().map(|d| scale * d).collect();
        Ok(Path {
            path: LoadPath::from_loading(
                &drive,
                loading.time.as_deref(),
                opts.max_step,
                opts.max_time_step,
            ),
            preload: 0,
        })
    }
    fn build(&self) -> Result<(System, N1Parts), FeError> {
        if !(self.friction >= 0.0) {
            return Err(FeError::InvalidConfig {
                field: "friction".into(),
                reason: format!("{} must be >= 0 (infinite: bonded)", self.friction),
            });
        }
        if let Some(mu) = self.base_friction {
            if !(mu >= 0.0) {
                return Err(FeError::InvalidConfig {
                    field: "base_friction".into(),
                    reason: format!("{mu} must be >= 0 (infinite: bonded)"),
                });
            }
        }
        let mut mesh = self.build_mesh()?;
        let kin = Kinematics::Axisymmetric;
        // A platen also meets the free side where it bulges and folds over
        // onto the platen (bonded or rough platens at large compression).
        let surface = if self.tool == ToolShape::Platen {
            let (top, side) = (mesh.facet_set("top")?, mesh.facet_set("side")?);
            let mut both = top.clone();
            both.nodes.extend_from_slice(&side.nodes);
            mesh.facet_sets.insert("top_and_side".into(), both);
            "top_and_side"
        } else {
            "top"
        };
        let regions = self.regions();
        let region_refs: Vec<&str> = regions.iter().map(String::as_str).collect();
        let body = SolidBody::new(
            "body",
            &mesh,
            &region_refs,
            {
                let (cell, pressure) = self.element.element();
                kernel_for(cell, kin, pressure)?
            },
            self.bulk.exact(),
        )?;
        let mut bcs = vec![Dirichlet::fixed("axis", 0)];
        if self.base_friction.is_none() {
            bcs.push(Dirichlet::fixed("bottom", 1));
            if self.base == Support::Bonded {
                bcs.push(Dirichlet::fixed("bottom", 0));
            }
        }
        // Penalties scale with the initial shear modulus, set per run.
        let options = ContactOptions {
            friction: self.friction,
            penalty_normal: 0.0,
            penalty_tangent: 0.0,
            penetration_tol: self.penetration_tol,
            points: self.contact_points,
        };
        let motion = ToolMotion::translating([0.0, self.height, 0.0], vec![(0, [0.0, -1.0, 0.0])]);
        let contact = RigidContact::new(
            &self.tool.name(),
            Box::new(Profile2d(self.tool)),
            motion,
            &mesh,
            surface,
            kin,
            options,
            1,
        )?;
        let base = match self.base_friction {
            None => None,
            Some(mu) => {
                // the element size along the base, for its penalty
                let bottom = mesh.facet_set("bottom")?;
                let h = bottom
                    .iter()
                    .map(|f| (mesh.nodes[f[1]][0] - mesh.nodes[f[0]][0]).abs())
                    .fold(0.0, f64::max);
                let floor = RigidContact::new(
                    "base",
                    Box::new(Floor2d),
                    ToolMotion::translating([0.0; 3], Vec::new()),
                    &mesh,
                    "bottom",
                    kin,
                    ContactOptions {
                        friction: mu,
                        points: ContactPoints::EdgeGauss,
                        ..options
                    },
                    1,
                )?;
                Some((floor, h))
            }
        };
        let mut parts = Parts::new();
        let handles = N1Parts {
            body: parts.add(body),
            contact: parts.add(contact),
            base: base.map(|(floor, h)| (parts.add(floor), h)),
        };
        Ok((System::from_parts(mesh, 2, parts, &bcs, 1)?, handles))
    }
    fn prepare(
        &self,
        sys: &mut System,
        parts: &N1Parts,
        material: RegionMaterial,
        extra: &[f64],
    ) -> Result<(), FeError> {
        let mu = material.material.shear_modulus();
        let h = self.effective_grading().h_fine;
        let (_, mats, friction, base_friction) = self.split_extra(extra)?;
        sys.force_floor = 1e-6 * mu * sys.mesh.min_edge().powi(2);
        let body = sys.get_mut(parts.body)?;
        if self.layers.is_empty() {
            body.set_material("body", material)?;
        } else {
            let mut band_materials = vec![material];
            for (m, p) in self.materials.iter().zip(mats) {
                band_materials.push(band_material(m, p)?);
            }
            for (i, (_, k)) in self.layers.iter().enumerate() {
                let m = band_materials
                    .get(*k)
                    .ok_or_else(|| FeError::InvalidConfig {
                        field: format!("layers[{i}]"),
                        reason: format!("material {k} of {}", band_materials.len()),
                    })?
                    .clone();
                body.set_material(&format!("layer{i}"), m)?;
            }
        }
        let cs = sys.get_mut(parts.contact)?;
        cs.options.penalty_normal = self.penalty * mu / h;
        cs.options.penalty_tangent = self.penalty * mu / h;
        cs.options.friction = friction.unwrap_or(self.friction);
        if let Some((part, hb)) = parts.base {
            let floor = sys.get_mut(part)?;
            floor.options.penalty_normal = self.penalty * mu / hb;
            floor.options.penalty_tangent = self.penalty * mu / hb;
            floor.options.friction = base_friction.or(self.base_friction).unwrap_or(0.0);
        }
        Ok(())
    }
    fn observe(&self, sys: &System, parts: &N1Parts) -> Vec<f64> {
        vec![sys
            .get(parts.contact)
            .and_then(|c| c.tool_force([0.0, -1.0, 0.0]))
            .unwrap_or(0.0)]
    }
    fn name(&self) -> String {
        let words = |mu: f64| {
            if mu.is_infinite() {
                "bonded".to_string()
            } else {
                mu.to_string()
            }
        };
        let base = match (self.base_friction, self.base) {
            (Some(mu), _) => format!(", base on a rigid plane with friction {}", words(mu)),
            (None, Support::Bonded) => String::new(),
            (None, Support::Sliding) => ", sliding base".into(),
        };
        let n1 = self.tool == ToolShape::n1_needle()
            && self.radius == 35.0
            && self.height == 80.0
            && self.layers.is_empty();
        let mut name = if n1 {
            format!(
                "N1 FE needle indentation, {}, friction {}{base}",
                self.law,
                words(self.friction)
            )
        } else {
            format!(
                "FE axisymmetric cylinder (radius {} mm, height {} mm), {}, {}, friction {}{base}",
                self.radius,
                self.height,
                self.tool.name(),
                self.law,
                words(self.friction)
            )
        };
        if let Some(p) = &self.prony {
            name += &format!(", Prony {p}");
        }
        if self.prony_parameters > 0 {
            name += &format!(", {} Prony terms as parameters", self.prony_parameters);
        }
        if !self.layers.is_empty() {
            let names: Vec<String> = self
                .layers
                .iter()
                .map(|(t, k)| {
                    let m = if *k == 0 {
                        format!("{} {}", self.first_material, self.law)
                    } else {
                        let b = &self.materials[*k - 1];
                        let mut w = format!("{} {}", b.name, b.law);
                        if let Some(p) = &b.prony {
                            w += &format!(" Prony {p}");
                        }
                        if b.prony_parameters > 0 {
                            w += &format!(" {} Prony terms as parameters", b.prony_parameters);
                        }
                        if b.bulk != self.bulk {
                            w += &format!(" bulk {:?}", b.bulk);
                        }
                        w
                    };
                    format!("{t} mm {m}")
                })
                .collect();
            name += &format!(", layers [{}]", names.join(", "));
        }
        if self.sizing.is_some() || self.grading.is_some() || self.element != PlaneCell::Quad4 {
            name += &format!(
                ", {:?} mesh of {}",
                self.element,
                graded_mesh_words(self.effective_grading(), "tool")
            );
        }
        if self.mirror {
            name += &format!(
                ", the upper half ({} mm) of a specimen between two identical platens",
                self.height
            );
        }
        if let Some(b) = &self.edge_band {
            name += &format!(
                ", refined to {} mm at the tool's edge (r = {} mm, slope {})",
                self.edge_size(b),
                b.r,
                b.slope
            );
        }
        if self.thickness_is_parameter {
            name += ", its thickness a parameter (the mesh lines below the fine zone moved with the base)";
        }
        if let Some(map) = self.stretch() {
            name += &format!(", meshed as {} mm stretched to {} mm", map.from, map.to);
        }
        name
    }
    fn has_geometric_parameters(&self) -> bool {
        self.thickness_is_parameter
    }
    /// With the thickness a parameter: the specimen at that thickness
    /// ([`N1Setup::at_thickness`]).
    fn geometry(&self, extra: &[f64]) -> Result<N1Setup, FeError> {
        self.at_thickness(extra)
    }
    fn effects(&self) -> Option<Vec<Effect>> {
        Some(self.offered_effects())
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        self.enriched(effect)
    }
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        self.enriched_forms(effect)
    }
}

impl N1Setup {
    /// The fine zone's depth (mm): the mesh lines above it stay where they
    /// are when the thickness changes.
    pub(super) fn kept_depth(&self) -> f64 {
        self.effective_grading().fine_length
    }

    /// How the axial mesh lines are stretched: from `mesh_height` to
    /// `height`, when the two differ.
    fn stretch(&self) -> Option<Stretch> {
        let from = self.mesh_height?;
        (from != self.height).then(|| Stretch {
            from,
            to: self.height,
            keep: self.kept_depth().min(0.5 * from.min(self.height)),
        })
    }
}

/// The axial mesh lines of a specimen `from` mm high moved to one `to` mm
/// high: depths down to `keep` stay, those below are scaled so that the
/// base goes to `to` (the same cells at every thickness).
#[derive(Debug, Clone, Copy)]
struct Stretch {
    from: f64,
    to: f64,
    keep: f64,
}

impl Stretch {
    /// The depths below the top (from 0 to `from`) moved.
    fn apply(&self, depths: &[f64]) -> Vec<f64> {
        let k = self.keep;
        let scale = (self.to - k) / (self.from - k);
        let mut out: Vec<f64> = depths
            .iter()
            .map(|&t| if t <= k { t } else { k + (t - k) * scale })
            .collect();
        if let Some(last) = out.last_mut() {
            *last = self.to;
        }
        out
    }
}

/// A Prony series from `[g1, tau1, g2, tau2, ...]`.
pub(crate) fn prony_of(flat: &[f64]) -> Result<Prony, FeError> {
    Prony::new(flat.chunks_exact(2).map(|c| (c[0], c[1])).collect())
}

/// The material of a band from its parameters (law's, then Prony terms).
fn band_material(m: &BandMaterial, p: &[f64]) -> Result<RegionMaterial, FeError> {
    let n = m.law.params().len();
    let law = LawMaterial::new(m.law, p[..n].to_vec())?;
    let mu = m.law.shear_modulus(&p[..n]);
    let prony = if m.prony_parameters > 0 {
        Some(prony_of(&p[n..])?)
    } else {
        m.prony.clone()
    };
    let material: Arc<dyn crate::material::PointMaterial> = match prony {
        None => Arc::new(law),
        Some(prony) => Arc::new(crate::viscoelastic::Viscoelastic::new(law, prony)),
    };
    Ok(RegionMaterial {
        material,
        volumetric: m.bulk.volumetric(mu),
    })
}

/// Parameters for exact sensitivities and their benches
/// ([`FeModel::simulate_sensitivities`]): the tool's friction and the law's
/// Prony terms made parameters directly (as the `friction` effect and a
/// description's Prony parameters do), keeping the model an [`N1Needle`].
impl N1Setup {
    /// Makes the tool's friction coefficient the parameter after the
    /// law's and Prony's, starting at [`N1Setup::friction`] (the
    /// `friction` effect's model), or fixes it again.
    pub fn set_friction_parameter(&mut self, on: bool) {
        self.friction_is_parameter = on;
    }

    /// Takes the law's Prony series from `terms` terms of parameters after
    /// the law's (`g1, tau1_s, ...`; 0: the fixed [`N1Setup::prony`]).
    pub fn set_prony_parameters(&mut self, terms: usize) {
        self.prony_parameters = terms;
    }
}
