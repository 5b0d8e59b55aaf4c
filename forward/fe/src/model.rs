//! What the FE forward models share: the volumetric treatment, the
//! parameter space of a law, the per-thread evaluator that keeps its solver
//! (mesh, pattern, symbolic factorisation, scratch) between calls, and the
//! conversion of solver failures into [`ForwardError`].

use palpate_core::{Drive, Evaluator, ForwardError, Loading, ParamSpace, ParamSpec};
use palpate_material::{Law, Volumetric};

use crate::material::LawMaterial;
use crate::solver::{Incompressibility, Progress, RunFailure, RunStats, Solver, SolverOptions};
use crate::FeError;

/// How an "incompressible" law is treated in the FE model.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bulk {
    /// Exact incompressibility (Lagrange multiplier per element).
    Exact,
    /// Bulk modulus `K = ratio * mu0` (mean-dilatation penalty), e.g. 1000
    /// to compare with CalculiX decks.
    Ratio(f64),
}

impl Bulk {
    pub(crate) fn incompressibility(self) -> Incompressibility {
        match self {
            Bulk::Exact => Incompressibility::Exact,
            Bulk::Ratio(_) => Incompressibility::Penalty,
        }
    }
    pub(crate) fn volumetric(self, mu: f64) -> Volumetric {
        match self {
            Bulk::Exact => Volumetric::Incompressible,
            Bulk::Ratio(r) => Volumetric::D1(2.0 / (r * mu)),
        }
    }
}

/// The parameter space of a law (commercial names, MPa).
pub fn law_space(law: &Law) -> ParamSpace {
    ParamSpace::new(
        law.params()
            .into_iter()
            .map(|p| ParamSpec::new(p.name, p.unit, p.lower, p.upper, p.initial))
            .collect(),
    )
}

/// The result of one simulation with its counters.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    pub forces: Vec<f64>,
    pub stats: RunStats,
}

/// Something that builds a solver for given extra (non-material) parameters
/// and applies those parameters before a run.
pub(crate) trait Setup: Send + Sync {
    fn law(&self) -> &Law;
    fn bulk(&self) -> Bulk;
    fn options(&self) -> SolverOptions;
    fn build(&self) -> Result<Solver, FeError>;
    /// Sets what depends on the parameters before a run: contact penalties
    /// (scaled by the shear modulus `mu`) and the parameters that follow the
    /// law's (e.g. friction).
    fn prepare(&self, _solver: &mut Solver, _mu: f64, _extra: &[f64]) {}
}

pub(crate) fn to_forward(e: FeError) -> ForwardError {
    match e {
        FeError::InvalidConfig { field, reason } | FeError::InvalidMesh { field, reason } => {
            ForwardError::InvalidConfig { field, reason }
        }
        FeError::MeshFile { file, line, reason } => ForwardError::InvalidConfig {
            field: file,
            reason: format!("line {line}: {reason}"),
        },
        other => ForwardError::InvalidConfig {
            field: "fe".into(),
            reason: other.to_string(),
        },
    }
}

fn failure(f: RunFailure) -> ForwardError {
    match f.error {
        FeError::InvalidConfig { .. }
        | FeError::InvalidMesh { .. }
        | FeError::MeshFile { .. }
        | FeError::ToolStartsInside { .. } => to_forward(f.error),
        e => ForwardError::NotConverged {
            sample: f.sample,
            drive: f.drive,
            cuts: f.cuts,
            reason: e.to_string(),
            completed: f.completed,
        },
    }
}

/// Runs one loading history on `solver` (built by `setup`).
pub(crate) fn simulate(
    setup: &dyn Setup,
    space: &ParamSpace,
    solver: &mut Solver,
    theta: &[f64],
    loading: &Loading,
    progress: Option<&dyn Fn(&Progress)>,
) -> Result<Simulation, ForwardError> {
    space.check(theta)?;
    if loading.drive_kind != Drive::DisplacementMm {
        return Err(ForwardError::InvalidLoading(format!(
            "FE models are driven by {}, got {}",
            Drive::DisplacementMm.column(),
            loading.drive_kind.column()
        )));
    }
    loading.validate().map_err(ForwardError::InvalidLoading)?;
    let law = setup.law();
    let n_law = law.params().len();
    let mat = LawMaterial::new(*law, theta[..n_law].to_vec()).map_err(to_forward)?;
    let mu = law.shear_modulus(&theta[..n_law]);
    setup.prepare(solver, mu, &theta[n_law..]);
    let vol = setup.bulk().volumetric(mu);
    let forces = solver
        .run(&mat, vol, &loading.drive, &setup.options(), progress)
        .map_err(failure)?;
    Ok(Simulation {
        forces,
        stats: solver.stats,
    })
}

/// The per-thread evaluator of an FE model: the solver is built on first use
/// and kept (pattern, symbolic LU, scratch) for every later call.
pub(crate) struct FeEvaluator<'a> {
    pub setup: &'a dyn Setup,
    pub space: &'a ParamSpace,
    pub solver: Option<Solver>,
}

impl Evaluator for FeEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        if out.len() != loading.len() {
            return Err(ForwardError::InvalidLoading(format!(
                "output has {} slots for {} samples",
                out.len(),
                loading.len()
            )));
        }
        if self.solver.is_none() {
            self.solver = Some(self.setup.build().map_err(to_forward)?);
        }
        let solver = self
            .solver
            .as_mut()
            .ok_or_else(|| ForwardError::InvalidConfig {
                field: "fe".into(),
                reason: "solver unavailable".into(),
            })?;
        let sim = simulate(self.setup, self.space, solver, theta, loading, None)?;
        out.copy_from_slice(&sim.forces);
        Ok(())
    }
}
