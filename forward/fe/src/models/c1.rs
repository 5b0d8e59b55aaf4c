//! `C1Fe`: the C1 compression benchmark (docs/benchmarks.md) by finite elements —
//! a cylinder of diameter 38 mm and height 9 mm between rigid platens that
//! are frictionless (the deformation is homogeneous, the analytic C1 model is
//! exact) or bonded (no slip, barrelling).
//!
//! Platens are displacement conditions on the end faces: `u_z = -d` on top
//! and `u_z = 0` at the bottom, plus `u_r = 0` on both when bonded. The force
//! is the top platen reaction for the whole cylinder, positive in compression.

use palpate_core::ParamSpace;
use palpate_material::Law;

use crate::body::{RegionMaterial, SolidBody};
use crate::discretisation::{Coarser, ConvergenceOrder};
use crate::dofs::Dirichlet;
use crate::kernel::{kernel_for, PressureSpace};
use crate::kinematics::Kinematics;
use crate::mesh::{CellType, Grading, Mesh};
use crate::model::{law_space, Bulk, FeModel, Setup};
use crate::system::{Part, Parts, SolverOptions, System};
use crate::viscoelastic::Prony;
use crate::FeError;

/// Platen contact condition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Platens {
    Frictionless,
    Bonded,
}

/// The C1 model: [`C1Setup`] as a forward model.
pub type C1Fe = FeModel<C1Setup>;

/// The C1 experiment ([`C1Fe`]).
#[derive(Debug, Clone, PartialEq)]
pub struct C1Setup {
    law: Law,
    pub bulk: Bulk,
    pub platens: Platens,
    /// Cylinder diameter and height (mm).
    pub diameter: f64,
    pub height: f64,
    /// Elements along the radius and the height.
    pub elements: (usize, usize),
    pub options: SolverOptions,
    /// A Prony series on the law's isochoric stress
    /// ([`crate::viscoelastic::Viscoelastic`]); `None`: elastic. A
    /// viscoelastic run needs the loading's time and steps it by at most
    /// `options.max_time_step` (a tenth of the shortest relaxation time
    /// when unset).
    pub prony: Option<Prony>,
}

/// The contributions of the C1 system: the body (the platens are
/// displacement conditions).
#[derive(Debug, Clone, Copy)]
pub struct C1Parts {
    body: Part<SolidBody>,
}

impl C1Fe {
    /// docs/benchmarks.md C1 geometry, 19 x 9 elements, exact incompressibility.
    pub fn new(law: Law, platens: Platens) -> Self {
        FeModel::from_setup(C1Setup {
            law,
            bulk: Bulk::Exact,
            platens,
            diameter: 38.0,
            height: 9.0,
            elements: (19, 9),
            options: SolverOptions {
                max_step: 0.25,
                first_step: 0.1,
                ..SolverOptions::default()
            },
            prony: None,
        })
    }

    /// The coarser companion of the discretisation error estimate: half the
    /// elements each way (rounded up, at least one), element-size ratio the
    /// square root of the ratio of element counts (2 for even counts;
    /// 19 x 9 -> 10 x 5: 1.85). A 1 x 1 mesh has none.
    pub fn coarser(&self) -> Result<Coarser<C1Fe>, FeError> {
        let (nr, nz) = self.elements;
        let coarse = (nr.div_ceil(2).max(1), nz.div_ceil(2).max(1));
        if coarse == self.elements {
            return Err(FeError::InvalidConfig {
                field: "elements".into(),
                reason: format!("{nr} x {nz} has no coarser mesh"),
            });
        }
        let ratio = ((nr * nz) as f64 / (coarse.0 * coarse.1) as f64).sqrt();
        Ok(
            self.companion(ratio, format!("{}x{}", coarse.0, coarse.1), |s| {
                s.elements = coarse
            }),
        )
    }
}

impl C1Setup {
    /// The order of convergence of the force with the element size.
    /// Bonded: 0.58, observed near the bonded edge on meshes 2 / 4 / 8
    /// (38 x 18, 76 x 36, 152 x 72), reduced polynomial N = 2, at 2 mm:
    /// 29.81 / 29.09 / 28.61 N (docs/validation/fe.md, "C1 bonded mesh
    /// convergence"). Frictionless: the deformation is homogeneous and Q1/P0
    /// is exact on any mesh (tests/integration/c1_frictionless.rs); the two meshes agree
    /// to round-off and the estimate is zero whatever the order (2 stated,
    /// the element's nominal order).
    pub fn convergence_order(&self) -> ConvergenceOrder {
        match self.platens {
            Platens::Bonded => ConvergenceOrder {
                order: 0.58,
                source: "docs/validation/fe.md C1 bonded (meshes 2, 4, 8, at 2 mm)".into(),
            },
            Platens::Frictionless => ConvergenceOrder {
                order: 2.0,
                source: "nominal Q1; frictionless C1 is homogeneous, exact on any mesh".into(),
            },
        }
    }
}

impl Setup for C1Setup {
    type Parts = C1Parts;
    fn law(&self) -> &Law {
        &self.law
    }
    fn set_law(&mut self, law: Law) {
        self.law = law;
    }
    fn param_space(&self) -> ParamSpace {
        law_space(&self.law)
    }
    fn bulk(&self) -> Bulk {
        self.bulk
    }
    fn options(&self) -> SolverOptions {
        self.options
    }
    fn prony(&self) -> Option<&Prony> {
        self.prony.as_ref()
    }
    fn build(&self) -> Result<(System, C1Parts), FeError> {
        let r = 0.5 * self.diameter;
        let (nr, nz) = self.elements;
        if nr == 0 || nz == 0 {
            return Err(FeError::InvalidConfig {
                field: "elements".into(),
                reason: "need at least one element each way".into(),
            });
        }
        let mesh = Mesh::graded_rectangle(
            r,
            self.height,
            Grading::uniform(r, nr),
            Grading::uniform(self.height, nz),
        )?;
        let body = SolidBody::new(
            "body",
            &mesh,
            &["body"],
            kernel_for(CellType::Quad4, Kinematics::Axisymmetric, PressureSpace::P0)?,
            self.bulk.exact(),
        )?;
        let mut bcs = vec![Dirichlet::fixed("axis", 0), Dirichlet::fixed("bottom", 1)];
        if self.platens == Platens::Bonded {
            bcs.push(Dirichlet::fixed("bottom", 0));
        }
        bcs.push(Dirichlet::driven("top", 1, 0, -1.0));
        if self.platens == Platens::Bonded {
            bcs.push(Dirichlet::fixed("top", 0));
        }
        let mut parts = Parts::new();
        let handles = C1Parts {
            body: parts.add(body),
        };
        Ok((System::from_parts(mesh, 2, parts, &bcs, 1)?, handles))
    }
    fn prepare(
        &self,
        sys: &mut System,
        parts: &C1Parts,
        material: RegionMaterial,
        _extra: &[f64],
    ) -> Result<(), FeError> {
        let mu = material.material.shear_modulus();
        sys.force_floor = 1e-6 * mu * sys.mesh.min_edge().powi(2);
        sys.get_mut(parts.body)?.set_material("body", material)
    }
    fn observe(&self, sys: &System, _parts: &C1Parts) -> Vec<f64> {
        vec![sys.channel_reaction(0)]
    }
    fn name(&self) -> String {
        let mut name = format!(
            "C1 FE compression ({:?} platens), {}",
            self.platens, self.law
        )
        .to_lowercase();
        if let Some(p) = &self.prony {
            name += &format!(", Prony {p}");
        }
        name
    }
}
