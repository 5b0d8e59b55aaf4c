//! What the FE forward models share: the volumetric treatment, the
//! parameter space of a law, the per-thread evaluator that keeps its solver
//! (mesh, pattern, symbolic factorisation, scratch) between calls, and the
//! conversion of solver failures into [`ForwardError`].

use palpate_core::{Drive, Evaluator, ForwardError, Loading, ParamSpace, ParamSpec};
use palpate_material::{Law, Volumetric};

use std::sync::Arc;

use crate::body::RegionMaterial;
use crate::material::LawMaterial;
use crate::stepper::{self, LoadPath, Progress, RunFailure};
use crate::system::{RunStats, SolverOptions, System};
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
    /// Whether the body carries pressure multipliers (exact constraint).
    pub(crate) fn exact(self) -> bool {
        self == Bulk::Exact
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
    /// The first output at each sample (the force).
    pub forces: Vec<f64>,
    /// Every output at each sample.
    pub outputs: Vec<Vec<f64>>,
    pub stats: RunStats,
}

/// Something that builds a system for given extra (non-material)
/// parameters and applies those parameters before a run.
pub(crate) trait Setup: Send + Sync {
    fn law(&self) -> &Law;
    fn bulk(&self) -> Bulk;
    fn options(&self) -> SolverOptions;
    fn build(&self) -> Result<System, FeError>;
    /// Sets what depends on the parameters before a run: the materials,
    /// contact penalties (scaled by the shear modulus `mu`) and the
    /// parameters that follow the law's (e.g. friction).
    fn prepare(
        &self,
        sys: &mut System,
        material: RegionMaterial,
        extra: &[f64],
    ) -> Result<(), FeError>;
    /// The outputs of a converged state; the first is the force a
    /// single-output model predicts.
    fn observe(&self, sys: &System) -> Vec<f64>;
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
            completed: f.completed.iter().map(|o| o[0]).collect(),
        },
    }
}

/// Runs one loading history on `sys` (built by `setup`).
pub(crate) fn simulate(
    setup: &dyn Setup,
    space: &ParamSpace,
    sys: &mut System,
    theta: &[f64],
    loading: &Loading,
    progress: Option<&mut dyn FnMut(&Progress)>,
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
    let material = RegionMaterial {
        material: Arc::new(mat),
        volumetric: setup.bulk().volumetric(mu),
    };
    setup
        .prepare(sys, material, &theta[n_law..])
        .map_err(to_forward)?;
    let path = LoadPath::from_drive(&loading.drive);
    let mut observe = |s: &System| setup.observe(s);
    let outputs =
        stepper::run(sys, &path, &setup.options(), &mut observe, progress).map_err(failure)?;
    Ok(Simulation {
        forces: outputs.iter().map(|o| o[0]).collect(),
        outputs,
        stats: sys.stats,
    })
}

/// The per-thread evaluator of an FE model: the system is built on first use
/// and kept (pattern, symbolic LU, scratch) for every later call.
pub(crate) struct FeEvaluator<'a> {
    pub setup: &'a dyn Setup,
    pub space: &'a ParamSpace,
    pub system: Option<System>,
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
        if self.system.is_none() {
            self.system = Some(self.setup.build().map_err(to_forward)?);
        }
        let sys = self
            .system
            .as_mut()
            .ok_or_else(|| ForwardError::InvalidConfig {
                field: "fe".into(),
                reason: "system unavailable".into(),
            })?;
        let sim = simulate(self.setup, self.space, sys, theta, loading, None)?;
        out.copy_from_slice(&sim.forces);
        Ok(())
    }
}
