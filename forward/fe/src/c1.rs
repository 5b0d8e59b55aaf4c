//! `C1Fe`: the C1 compression benchmark (BENCHMARKS.md) by finite elements —
//! a cylinder of diameter 38 mm and height 9 mm between rigid platens that
//! are frictionless (the deformation is homogeneous, the analytic C1 model is
//! exact) or bonded (no slip, barrelling).
//!
//! Platens are displacement conditions on the end faces: `u_z = -d` on top
//! and `u_z = 0` at the bottom, plus `u_r = 0` on both when bonded. The force
//! is the top platen reaction for the whole cylinder, positive in compression.

use palpate_core::{Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace};
use palpate_material::Law;

use crate::kinematics::Kinematics;
use crate::mesh::Grading;
use crate::mesh2d::Mesh;
use crate::model::{law_space, simulate, Bulk, FeEvaluator, Setup, Simulation};
use crate::solver::{Constraints, Progress, Solver, SolverOptions};
use crate::FeError;

/// Platen contact condition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Platens {
    Frictionless,
    Bonded,
}

/// The C1 model.
#[derive(Debug, Clone, PartialEq)]
pub struct C1Fe {
    pub law: Law,
    pub bulk: Bulk,
    pub platens: Platens,
    /// Cylinder diameter and height (mm).
    pub diameter: f64,
    pub height: f64,
    /// Elements along the radius and the height.
    pub elements: (usize, usize),
    pub options: SolverOptions,
    space: ParamSpace,
}

impl C1Fe {
    /// BENCHMARKS.md C1 geometry, 19 x 9 elements, exact incompressibility.
    pub fn new(law: Law, platens: Platens) -> Self {
        C1Fe {
            space: law_space(&law),
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
        }
    }

    /// Runs one history with a progress observer; keeps the solver for the caller.
    pub fn simulate(
        &self,
        theta: &[f64],
        loading: &Loading,
        progress: Option<&dyn Fn(&Progress)>,
    ) -> Result<(Simulation, Solver), ForwardError> {
        let mut solver = self.build().map_err(crate::model::to_forward)?;
        let sim = simulate(self, &self.space, &mut solver, theta, loading, progress)?;
        Ok((sim, solver))
    }
}

impl Setup for C1Fe {
    fn law(&self) -> &Law {
        &self.law
    }
    fn bulk(&self) -> Bulk {
        self.bulk
    }
    fn options(&self) -> SolverOptions {
        self.options
    }
    fn build(&self) -> Result<Solver, FeError> {
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
        let mut c = Constraints::default();
        for &n in mesh.node_set("axis")? {
            c.fixed.push((n, 0));
        }
        for &n in mesh.node_set("bottom")? {
            c.fixed.push((n, 1));
            if self.platens == Platens::Bonded && mesh.nodes[n][0] > 0.0 {
                c.fixed.push((n, 0));
            }
        }
        for &n in mesh.node_set("top")? {
            c.driven.push((n, 1, -1.0));
            if self.platens == Platens::Bonded && mesh.nodes[n][0] > 0.0 {
                c.fixed.push((n, 0));
            }
        }
        Solver::new(
            mesh,
            Kinematics::Axisymmetric,
            c,
            None,
            self.bulk.incompressibility(),
        )
    }
}

impl ForwardModel for C1Fe {
    fn name(&self) -> String {
        format!(
            "C1 FE compression ({:?} platens), {}",
            self.platens, self.law
        )
        .to_lowercase()
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(FeEvaluator {
            setup: self,
            space: &self.space,
            solver: None,
        })
    }
    /// A nonlinear FE solve per prediction.
    fn expensive(&self) -> bool {
        true
    }
}
