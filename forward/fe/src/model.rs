//! What the FE forward models share: the [`Setup`] a model describes (its
//! system, what its parameters set, what it observes) and the one
//! [`FeModel`] that makes any setup a [`ForwardModel`]; the layer's
//! vocabulary of a model ([`Bulk`], [`PlaneCell`], [`Support`]); the
//! parameter space of a law; the per-thread evaluator that keeps its solver
//! (mesh, pattern, symbolic factorisation, scratch) between calls; and the
//! conversion of solver failures into [`ForwardError`].

use palpate_core::{
    check_output_slots,
    enrichable::{not_applicable, one_form, EffectForm},
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamRole, ParamSpace, ParamSpec, Sensitivities,
};
use palpate_material::{Law, Volumetric};

use std::sync::{Arc, OnceLock};

use crate::body::RegionMaterial;
use crate::discretisation::Coarser;
use crate::kernel::PressureSpace;
use crate::material::LawMaterial;
use crate::material::PointMaterial;
use crate::mesh::{CellType, Grading};
use crate::sensitivity::Differentiation;
use crate::stepper::{self, LoadPath, Progress, RunFailure};
use crate::system::{RunStats, SolverOptions, System};
use crate::viscoelastic::{Prony, Viscoelastic};
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
            .map(|p| {
                ParamSpec::new(p.name, p.unit, p.lower, p.upper, p.initial).with_role(
                    if p.modulus {
                        ParamRole::Modulus
                    } else {
                        ParamRole::Shape
                    },
                )
            })
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
    /// With sensitivities ([`FeModel::simulate_sensitivities`]):
    /// `derivatives[i][j][k]`, the derivative of output `k` at sample `i`
    /// with respect to parameter `j`; empty otherwise.
    pub derivatives: Vec<Vec<Vec<f64>>>,
}

/// The cell of a 2D (axisymmetric or plane) mesh made from a grading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlaneCell {
    /// 4-node quadrilateral, constant pressure (Q1/P0).
    Quad4,
    /// 9-node quadrilateral, discontinuous linear pressure (Q2/P1), on the
    /// grading's cells made quadratic (twice the nodes per direction).
    Quad9,
}

impl PlaneCell {
    /// The mesh cell type and the pressure space of the mixed element.
    pub fn element(self) -> (CellType, PressureSpace) {
        match self {
            PlaneCell::Quad4 => (CellType::Quad4, PressureSpace::P0),
            PlaneCell::Quad9 => (CellType::Quad9, PressureSpace::P1),
        }
    }
}

/// How the specimen's base (bottom face) is supported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    /// Fixed in all directions.
    Bonded,
    /// Free to slide along the base (the normal component fixed only).
    Sliding,
}

/// The Coulomb coefficient of a tool as a parameter (bounds 0..2,
/// plausible 0..0.8: a lubricated to a dry tool on soft tissue), starting
/// at `initial`: the `friction` effect of the models with a tool.
pub fn friction_param(initial: f64) -> ParamSpec {
    ParamSpec::new("friction", "1", 0.0, 2.0, initial)
        .with_role(ParamRole::Friction)
        .with_plausible(0.0, 0.8)
}

/// The coarser companion of a graded mesh for the error estimate: the fine
/// size and `growth - 1` doubled, the fine zone kept (level L -> L/2).
pub fn doubled(g: Grading) -> Grading {
    Grading {
        h_fine: 2.0 * g.h_fine,
        fine_length: g.fine_length,
        growth: 1.0 + 2.0 * (g.growth - 1.0),
    }
}

/// A graded mesh in words for messages: `0.4 mm elements under the
/// {tool}, growth 1.4`.
pub fn graded_mesh_words(g: Grading, tool: &str) -> String {
    format!(
        "{} mm elements under the {tool}, growth {}",
        round6(g.h_fine),
        round6(g.growth)
    )
}

/// `x` to six decimals, for messages (0.4 rather than 0.4000000000000001).
fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// An FE experiment as data: what it builds (mesh, bodies, supports,
/// tool), what its parameters set before a run, how its loading drives the
/// stepper and what it observes. [`FeModel`] makes any setup a
/// [`ForwardModel`] (and [`Enrichable`]); the reference problems N1, N3,
/// C1, Q1 and R2 are setups ([`crate::models`]).
pub trait Setup: Clone + std::fmt::Debug + PartialEq + Send + Sync + 'static {
    /// Typed handles to the contributions [`Setup::build`] adds
    /// ([`crate::system::Parts`]), for [`Setup::prepare`] and
    /// [`Setup::observe`].
    type Parts: Send + Sync;
    /// The law of the specimen; its parameters come first.
    fn law(&self) -> &Law;
    /// Replaces the law ([`FeModel::set_law`]: the parameter space follows).
    fn set_law(&mut self, law: Law);
    fn bulk(&self) -> Bulk;
    fn options(&self) -> SolverOptions;
    /// The parameter space: the law's, then those [`Setup::prepare`] and
    /// [`Setup::prony_for`] read after them (`extra`).
    fn param_space(&self) -> ParamSpace;
    /// A Prony series on the material's isochoric stress (viscoelastic
    /// runs); `None` (the default): elastic.
    fn prony(&self) -> Option<&Prony> {
        None
    }
    /// The Prony series of a run with the parameters after the law's
    /// (`extra`): the fixed [`Setup::prony`] unless the model takes its
    /// Prony terms as parameters ([`crate::Q1Punch::with_prony_parameters`]).
    fn prony_for(&self, _extra: &[f64]) -> Result<Option<Prony>, FeError> {
        Ok(self.prony().cloned())
    }
    /// The system, and the handles of its contributions.
    fn build(&self) -> Result<(System, Self::Parts), FeError>;
    /// Sets what depends on the parameters before a run: the materials,
    /// contact penalties (scaled by the shear modulus `mu`) and the
    /// parameters that follow the law's (e.g. friction).
    fn prepare(
        &self,
        sys: &mut System,
        parts: &Self::Parts,
        material: RegionMaterial,
        extra: &[f64],
    ) -> Result<(), FeError>;
    /// The stepper's path for `loading` (channel values per station) and
    /// how many of its first stations are a preload whose outputs are not
    /// samples. Default: one channel driven by the displacement samples
    /// (`Drive::DisplacementMm`), no preload; a model with several channels
    /// or another drive (R2's wheel pressed, then rolled through positions)
    /// builds its own.
    fn path(&self, loading: &Loading, opts: &SolverOptions) -> Result<Path, ForwardError> {
        if loading.drive_kind != Drive::DisplacementMm {
            return Err(ForwardError::InvalidLoading(format!(
                "FE models are driven by {}, got {}",
                Drive::DisplacementMm.column(),
                loading.drive_kind.column()
            )));
        }
        Ok(Path {
            path: LoadPath::from_loading(
                &loading.drive,
                loading.time.as_deref(),
                opts.max_step,
                opts.max_time_step,
            ),
            preload: 0,
        })
    }
    /// The outputs of a converged state: as many as [`Setup::outputs`], in
    /// that order (the evaluator checks); the first is the force a
    /// one-output consumer sees.
    fn observe(&self, sys: &System, parts: &Self::Parts) -> Vec<f64>;
    /// The model's name, with every setting that changes its predictions
    /// (provenance records it).
    fn name(&self) -> String;
    /// The outputs [`Setup::observe`] returns. Default: the force.
    fn outputs(&self) -> Vec<Output> {
        vec![Output::from(Observable::ForceN)]
    }
    /// A check of a loading before [`FeModel::simulate`] builds anything
    /// (e.g. a depth the specimen cannot take). Default: none.
    fn check_loading(&self, _loading: &Loading) -> Result<(), ForwardError> {
        Ok(())
    }
    /// The effects of the gap diagnosis the model offers; `None` (the
    /// default): the model is not [`Enrichable`].
    fn effects(&self) -> Option<Vec<Effect>> {
        None
    }
    /// The model with `effect` ([`Enrichable::enrich`]).
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        Err(not_applicable(effect, &self.name()))
    }
    /// The forms of `effect` ([`Enrichable::enrich_forms`]), the first the
    /// one [`Setup::enrich`] gives. Default: that one alone.
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        Ok(one_form(self.enrich(effect)?))
    }
    /// Whether some parameters move the geometry (a specimen's thickness):
    /// the mesh is then built per run from [`Setup::geometry`], and the
    /// model has no exact sensitivities (its derivatives are finite
    /// differences of whole runs, the same cells moved, so smooth in the
    /// parameter). Default: none do.
    fn has_geometric_parameters(&self) -> bool {
        false
    }
    /// The setup whose [`Setup::build`] makes the mesh for the parameters
    /// after the law's (`extra`), when [`Setup::has_geometric_parameters`].
    /// Default: this one.
    fn geometry(&self, _extra: &[f64]) -> Result<Self, FeError> {
        Ok(self.clone())
    }
}

/// The forward model of a [`Setup`]: one FE run per prediction, each
/// thread's evaluator keeping its system between calls. It dereferences
/// to its setup, whose public fields are the model's settings; the
/// parameter space is derived from the setup ([`Setup::param_space`]) and
/// follows every change made through it.
#[derive(Clone)]
pub struct FeModel<S> {
    setup: S,
    space: OnceLock<ParamSpace>,
}

impl<S: Setup> FeModel<S> {
    /// The model of `setup`.
    pub fn from_setup(setup: S) -> Self {
        FeModel {
            setup,
            space: OnceLock::new(),
        }
    }

    /// The setup.
    pub fn setup(&self) -> &S {
        &self.setup
    }

    /// The law of the specimen.
    pub fn law(&self) -> &Law {
        self.setup.law()
    }

    /// Replaces the law; the parameter space follows.
    pub fn set_law(&mut self, law: Law) {
        std::ops::DerefMut::deref_mut(self).set_law(law);
    }

    /// The model with another law.
    pub fn with_law(mut self, law: Law) -> Self {
        self.set_law(law);
        self
    }

    /// Runs one history with a progress observer; returns the system too
    /// (fields for VTK output).
    pub fn simulate(
        &self,
        theta: &[f64],
        loading: &Loading,
        progress: Option<&mut dyn FnMut(&Progress)>,
    ) -> Result<(Simulation, System), ForwardError> {
        self.setup.check_loading(loading)?;
        let setup = self.setup_for(theta)?;
        let setup: &S = &setup;
        let (mut sys, parts) = setup.build().map_err(to_forward)?;
        let sim = simulate_with(
            setup,
            self.space(),
            &mut sys,
            &parts,
            theta,
            loading,
            progress,
            false,
            None,
        )?;
        Ok((sim, sys))
    }

    /// Runs one history with the exact derivatives of every output at every
    /// sample with respect to every parameter of the model's space
    /// ([`Simulation::derivatives`]), by direct differentiation through the
    /// converged increments ([`crate::sensitivity`]): each increment costs
    /// one more factorisation and, per parameter, one back-substitution and
    /// four residual assemblies. Every parameter of an FE model is one that
    /// [`Setup::prepare`] or [`Setup::prony_for`] sets (materials, Prony
    /// terms, friction coefficients, penalties through the shear modulus);
    /// parameters that move geometry (a nodule's position, a specimen's
    /// size) are settings of the setup, not parameters, and stay on finite
    /// differences of whole runs by whoever varies them. What is
    /// differentiated is the run with its increments (the nominal run's),
    /// so a model whose step control depends on a parameter (the time step
    /// of a Prony series whose times are parameters, when
    /// `SolverOptions::max_time_step` is unset) differs from differences of
    /// whole runs by the change of its increments.
    pub fn simulate_sensitivities(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<Simulation, ForwardError> {
        self.run_sensitivities(theta, loading, false)
    }

    /// [`FeModel::simulate_sensitivities`] with the history's derivatives
    /// dropped (held at zero): wrong for any path-dependent run, which is
    /// what the tests show with it.
    #[doc(hidden)]
    pub fn simulate_sensitivities_without_history(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<Simulation, ForwardError> {
        self.run_sensitivities(theta, loading, true)
    }

    fn run_sensitivities(
        &self,
        theta: &[f64],
        loading: &Loading,
        drop_history: bool,
    ) -> Result<Simulation, ForwardError> {
        if self.setup.has_geometric_parameters() {
            return Err(ForwardError::InvalidConfig {
                field: "parameters".into(),
                reason: format!(
                    "{} has parameters that move the mesh: its derivatives are finite differences, not sensitivities",
                    self.setup.name()
                ),
            });
        }
        self.setup.check_loading(loading)?;
        let (mut sys, parts) = self.setup.build().map_err(to_forward)?;
        simulate_with(
            &self.setup,
            self.space(),
            &mut sys,
            &parts,
            theta,
            loading,
            None,
            true,
            Some(drop_history),
        )
    }

    /// The setup that builds the mesh for `theta` ([`Setup::geometry`]).
    fn setup_for(&self, theta: &[f64]) -> Result<std::borrow::Cow<'_, S>, ForwardError> {
        if !self.setup.has_geometric_parameters() {
            return Ok(std::borrow::Cow::Borrowed(&self.setup));
        }
        self.space().check(theta)?;
        let n_law = self.setup.law().params().len();
        self.setup
            .geometry(&theta[n_law..])
            .map(std::borrow::Cow::Owned)
            .map_err(to_forward)
    }

    /// The model with its setup changed by `change`, as the coarser
    /// companion of the error estimate with element-size ratio `ratio` and
    /// the mesh in words.
    pub(crate) fn companion(
        &self,
        ratio: f64,
        mesh: String,
        change: impl FnOnce(&mut S),
    ) -> Coarser<Self> {
        let mut setup = self.setup.clone();
        change(&mut setup);
        Coarser {
            model: FeModel::from_setup(setup),
            ratio,
            mesh,
        }
    }
}

impl<S> std::ops::Deref for FeModel<S> {
    type Target = S;
    fn deref(&self) -> &S {
        &self.setup
    }
}

/// A change through the setup may change the parameter space: it is derived
/// again when next asked for.
impl<S> std::ops::DerefMut for FeModel<S> {
    fn deref_mut(&mut self) -> &mut S {
        self.space = OnceLock::new();
        &mut self.setup
    }
}

impl<S: PartialEq> PartialEq for FeModel<S> {
    fn eq(&self, other: &Self) -> bool {
        self.setup == other.setup
    }
}

impl<S: std::fmt::Debug> std::fmt::Debug for FeModel<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.setup.fmt(f)
    }
}

impl<S: Setup> ForwardModel for FeModel<S> {
    fn name(&self) -> String {
        self.setup.name()
    }
    fn space(&self) -> &ParamSpace {
        self.space.get_or_init(|| self.setup.param_space())
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn outputs(&self) -> Vec<Output> {
        self.setup.outputs()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(FeEvaluator {
            setup: &self.setup,
            space: self.space(),
            outputs: self.outputs().len(),
            system: None,
            geometry: None,
        })
    }
    /// A nonlinear FE solve per prediction (seconds or more).
    fn expensive(&self) -> bool {
        true
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        self.setup.effects().map(|_| self as &dyn Enrichable)
    }
    /// Every FE model differentiates its runs
    /// ([`FeModel::simulate_sensitivities`]), but one whose parameters
    /// move the mesh ([`Setup::has_geometric_parameters`]).
    fn as_sensitivities(&self) -> Option<&dyn Sensitivities> {
        (!self.setup.has_geometric_parameters()).then_some(self as &dyn Sensitivities)
    }
}

/// The force (first output) and its derivatives by direct differentiation
/// ([`FeModel::simulate_sensitivities`]): one run with sensitivities
/// instead of one run per finite-difference step.
impl<S: Setup> Sensitivities for FeModel<S> {
    fn predict_with_jacobian(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        let sim = self.simulate_sensitivities(theta, loading)?;
        let columns = (0..theta.len())
            .map(|j| sim.derivatives.iter().map(|d| d[j][0]).collect())
            .collect();
        Ok((sim.forces, columns))
    }
}

impl<S: Setup> Enrichable for FeModel<S> {
    fn effects(&self) -> Vec<Effect> {
        self.setup.effects().unwrap_or_default()
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        self.setup.enrich(effect)
    }
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        self.setup.enrich_forms(effect)
    }
}

/// A loading as the stepper runs it: the path, and the number of its first
/// stations that are a preload (run, not reported as samples).
pub struct Path {
    pub path: LoadPath,
    pub preload: usize,
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

/// A failed run as a [`ForwardError`]; `completed` holds the first output of
/// each converged sample, or (`all_outputs`) every output, row-major; the
/// first `preload` stations are not samples.
fn failure(mut f: RunFailure, all_outputs: bool, preload: usize) -> ForwardError {
    f.completed.drain(..preload.min(f.completed.len()));
    f.sample = f.sample.saturating_sub(preload);
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
            completed: if all_outputs {
                f.completed.concat()
            } else {
                f.completed.iter().map(|o| o[0]).collect()
            },
        },
    }
}

/// The material of the law's region for the parameters `theta`, and the
/// shortest relaxation time of its Prony series (`None`: elastic).
fn law_material<S: Setup>(
    setup: &S,
    theta: &[f64],
) -> Result<(RegionMaterial, Option<f64>), FeError> {
    let law = setup.law();
    let n_law = law.params().len();
    let mat = LawMaterial::new(*law, theta[..n_law].to_vec())?;
    let mu = law.shear_modulus(&theta[..n_law]);
    let (point, shortest): (Arc<dyn PointMaterial>, _) = match setup.prony_for(&theta[n_law..])? {
        None => (Arc::new(mat), None),
        Some(prony) => {
            let shortest = prony.shortest_time();
            (Arc::new(Viscoelastic::new(mat, prony)), Some(shortest))
        }
    };
    Ok((
        RegionMaterial {
            material: point,
            volumetric: setup.bulk().volumetric(mu),
        },
        shortest,
    ))
}

/// Sets what the parameters `theta` set on a built system (materials,
/// penalties, friction), leaving its history as it is.
fn set_parameters<S: Setup>(
    setup: &S,
    sys: &mut System,
    parts: &S::Parts,
    theta: &[f64],
) -> Result<(), FeError> {
    let n_law = setup.law().params().len();
    let (material, _) = law_material(setup, theta)?;
    let history = sys.histories();
    setup.prepare(sys, parts, material, &theta[n_law..])?;
    sys.set_histories(&history, &history, 0.0);
    Ok(())
}

/// Runs one loading history on `sys` (built by `setup`, with the handles
/// `parts`); a failure keeps the first output of the converged samples, or
/// with `all_outputs` every output (samples x outputs, row-major). With
/// `sensitivities`, every station's outputs are followed by their
/// derivatives with respect to each parameter (parameter by parameter), and
/// `Some(true)` drops the history's derivatives ([`crate::sensitivity`]).
#[allow(clippy::too_many_arguments)]
fn simulate_with<S: Setup>(
    setup: &S,
    space: &ParamSpace,
    sys: &mut System,
    parts: &S::Parts,
    theta: &[f64],
    loading: &Loading,
    progress: Option<&mut dyn FnMut(&Progress)>,
    all_outputs: bool,
    sensitivities: Option<bool>,
) -> Result<Simulation, ForwardError> {
    space.check(theta)?;
    loading.validate().map_err(ForwardError::InvalidLoading)?;
    let n_law = setup.law().params().len();
    let mut opts = setup.options();
    let (material, shortest) = law_material(setup, theta).map_err(to_forward)?;
    if let Some(shortest) = shortest {
        if loading.time.is_none() {
            return Err(ForwardError::InvalidLoading(
                "a viscoelastic material needs the time of each sample".into(),
            ));
        }
        if opts.max_time_step.is_none() {
            opts.max_time_step = Some(0.1 * shortest);
        }
    }
    setup
        .prepare(sys, parts, material, &theta[n_law..])
        .map_err(to_forward)?;
    let Path { path, preload } = setup.path(loading, &opts)?;
    let mut outputs = match sensitivities {
        None => {
            let mut observe = |s: &System| setup.observe(s, parts);
            stepper::run(sys, &path, &opts, &mut observe, progress)
        }
        Some(drop_history) => {
            let k = setup.outputs().len();
            let mut set = |s: &mut System, t: &[f64]| set_parameters(setup, s, parts, t);
            let mut diff = Differentiation::new(sys, theta, k, &mut set).map_err(to_forward)?;
            diff.drop_history = drop_history;
            let diff = std::cell::RefCell::new(diff);
            let observe_only = |s: &System| setup.observe(s, parts);
            let mut observe = |s: &System| {
                let mut o = setup.observe(s, parts);
                o.extend(diff.borrow().outputs.concat());
                o
            };
            let mut hook = |s: &mut System, target: &crate::system::Target| {
                diff.borrow_mut()
                    .increment(s, target, &mut set, &observe_only)
            };
            stepper::run_with_hook(sys, &path, &opts, &mut observe, progress, Some(&mut hook))
        }
    }
    .map_err(|f| failure(f, all_outputs, preload))?;
    outputs.drain(..preload.min(outputs.len()));
    let derivatives = if sensitivities.is_some() {
        let k = outputs.first().map_or(0, |o| o.len() / (1 + theta.len()));
        outputs
            .iter_mut()
            .map(|o| {
                let d = o.split_off(k);
                d.chunks(k.max(1)).map(<[f64]>::to_vec).collect()
            })
            .collect()
    } else {
        Vec::new()
    };
    Ok(Simulation {
        forces: outputs.iter().map(|o| o[0]).collect(),
        outputs,
        stats: sys.stats,
        derivatives,
    })
}

/// The per-thread evaluator of an FE model: the system is built on first use
/// and kept (pattern, symbolic LU, scratch) for every later call. Every
/// output [`Setup::observe`] returns is read at each sample;
/// `predict_into` gives the first, `predict_outputs_into` all of them.
struct FeEvaluator<'a, S: Setup> {
    setup: &'a S,
    space: &'a ParamSpace,
    /// The number of outputs the model declares ([`Setup::outputs`]), which
    /// `observe` returns.
    outputs: usize,
    system: Option<(System, S::Parts)>,
    /// The setup the system was built from when the parameters move the
    /// mesh ([`Setup::geometry`]); rebuilt when they change.
    geometry: Option<S>,
}

impl<S: Setup> FeEvaluator<'_, S> {
    /// The simulation of `loading`, on the system built at first use.
    fn run(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        all_outputs: bool,
    ) -> Result<Simulation, ForwardError> {
        if self.setup.has_geometric_parameters() {
            self.space.check(theta)?;
            let n_law = self.setup.law().params().len();
            let g = self.setup.geometry(&theta[n_law..]).map_err(to_forward)?;
            if self.geometry.as_ref() != Some(&g) {
                self.system = Some(g.build().map_err(to_forward)?);
                self.geometry = Some(g);
            }
        }
        if self.system.is_none() {
            self.system = Some(self.setup.build().map_err(to_forward)?);
        }
        let setup: &S = match &self.geometry {
            Some(g) => g,
            None => self.setup,
        };
        let (sys, parts) = self
            .system
            .as_mut()
            .ok_or_else(|| ForwardError::InvalidConfig {
                field: "fe".into(),
                reason: "system unavailable".into(),
            })?;
        simulate_with(
            setup,
            self.space,
            sys,
            parts,
            theta,
            loading,
            None,
            all_outputs,
            None,
        )
    }
}

impl<S: Setup> Evaluator for FeEvaluator<'_, S> {
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
        let sim = self.run(theta, loading, false)?;
        out.copy_from_slice(&sim.forces);
        Ok(())
    }

    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let k = self.outputs;
        check_output_slots(out.len(), loading.len(), k)?;
        let sim = self.run(theta, loading, true)?;
        for (row, values) in out.chunks_mut(k.max(1)).zip(&sim.outputs) {
            if values.len() != k {
                return Err(ForwardError::InvalidConfig {
                    field: "outputs".into(),
                    reason: format!(
                        "the model declares {k} outputs but observes {}",
                        values.len()
                    ),
                });
            }
            row.copy_from_slice(values);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{C1Fe, Platens};
    use palpate_enrich::ZeroOffset;

    /// Bonded C1 observing both platens: the reaction of the driven top
    /// platen (C1's force) and the sum of the internal forces along y on the
    /// bottom face, which equilibrium makes equal to it. `declared` is the
    /// number of outputs it claims (2, or wrong on purpose).
    #[derive(Debug, Clone, PartialEq)]
    struct BothPlatens {
        c1: crate::C1Setup,
        declared: usize,
    }

    impl Setup for BothPlatens {
        type Parts = <crate::C1Setup as Setup>::Parts;
        fn law(&self) -> &Law {
            self.c1.law()
        }
        fn set_law(&mut self, law: Law) {
            self.c1.set_law(law)
        }
        fn param_space(&self) -> ParamSpace {
            self.c1.param_space()
        }
        fn bulk(&self) -> Bulk {
            self.c1.bulk()
        }
        fn options(&self) -> SolverOptions {
            Setup::options(&self.c1)
        }
        fn build(&self) -> Result<(System, Self::Parts), FeError> {
            self.c1.build()
        }
        fn prepare(
            &self,
            sys: &mut System,
            parts: &Self::Parts,
            material: RegionMaterial,
            extra: &[f64],
        ) -> Result<(), FeError> {
            self.c1.prepare(sys, parts, material, extra)
        }
        fn observe(&self, sys: &System, _parts: &Self::Parts) -> Vec<f64> {
            let fint = sys.internal_forces();
            let bottom = sys.mesh.node_set("bottom").expect("C1 has a bottom");
            let d = sys.dofs.dim;
            vec![
                sys.channel_reaction(0),
                bottom.iter().map(|&n| fint[n * d + 1]).sum(),
            ]
        }
        fn name(&self) -> String {
            "C1 observing both platens".into()
        }
        fn outputs(&self) -> Vec<Output> {
            let mut v = vec![
                Output::new("force_N", Observable::ForceN),
                Output::new("force_bottom_N", Observable::ForceN),
            ];
            v.resize(
                self.declared,
                Output::new("force_extra_N", Observable::ForceN),
            );
            v
        }
    }

    fn both(declared: usize) -> FeModel<BothPlatens> {
        FeModel::from_setup(BothPlatens {
            c1: c1().setup().clone(),
            declared,
        })
    }

    fn c1() -> C1Fe {
        let mut c1 = C1Fe::new(Law::NeoHookean, Platens::Bonded);
        c1.elements = (4, 2);
        c1
    }

    const NH: [f64; 1] = [1101.295e-6];

    /// The FE evaluator writes every observed output per sample, row-major;
    /// the first column is the one-output prediction, bit for bit.
    #[test]
    fn fe_evaluator_writes_every_output_per_sample() {
        let m = both(2);
        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.5, 1.0, 1.5]);
        let columns = m.predict_outputs(&NH, &loading).unwrap();
        assert_eq!(columns.len(), 2);
        let one = c1().predict(&NH, &loading).unwrap();
        assert!(one[2] > one[0] && one[0] > 0.0, "{one:?}");
        assert_eq!(columns[0], one);
        assert_eq!(m.predict(&NH, &loading).unwrap(), one);
        // equilibrium: the bottom carries what the top platen pushes
        for (top, bottom) in columns[0].iter().zip(&columns[1]) {
            assert!(
                (top - bottom).abs() <= 1e-7 * top,
                "top {top} bottom {bottom}"
            );
        }
        let mut ev = m.evaluator();
        let mut rows = vec![0.0; 6];
        ev.predict_outputs_into(&NH, &loading, &mut rows).unwrap();
        for i in 0..3 {
            assert_eq!(
                [rows[2 * i], rows[2 * i + 1]],
                [columns[0][i], columns[1][i]]
            );
        }
        let err = ev
            .predict_outputs_into(&NH, &loading, &mut [0.0; 3])
            .unwrap_err();
        assert!(err.to_string().contains("3 samples x 2 outputs"), "{err}");
        drop(ev);

        // a wrapper keeps both outputs
        let offset = ZeroOffset::from_arc(Arc::new(m));
        assert_eq!(offset.outputs()[1].name, "force_bottom_N");
        let off = offset.predict_outputs(&[NH[0], 0.0], &loading).unwrap();
        assert_eq!(off, columns);
    }

    /// The parameter space follows every change of the setup: a new law, a
    /// new nodule law, friction made a parameter; the name records Q1's
    /// pure-penalty switch only when it is on.
    #[test]
    fn the_space_follows_the_setup() {
        let rp: Law = "reduced-polynomial:2".parse().unwrap();
        let mut n1 = crate::N1Needle::new(Law::NeoHookean);
        assert_eq!(n1.space().len(), 1);
        n1.set_law(rp);
        assert_eq!(n1.space().names(), ["C10", "C20"]);
        let friction = n1.enrich(Effect::Friction).unwrap();
        assert_eq!(friction.space().names(), ["C10", "C20", "friction"]);

        let ab: Law = "arruda-boyce".parse().unwrap();
        let mut r2 = crate::R2Rolling::new(ab, ab, 3.0);
        assert_eq!(r2.space().len(), 4);
        r2.set_nodule_law(Law::NeoHookean);
        assert_eq!(r2.space().names(), ["mu", "lambda_m", "nodule_C10"]);

        let mut q1 = crate::Q1Punch::new(Law::NeoHookean);
        let plain = q1.name();
        assert!(!plain.contains("penalty"), "{plain}");
        q1.pure_penalty = true;
        assert_eq!(q1.name(), format!("{plain}, pure-penalty contact"));
        let q1 = q1.with_prony_parameters(2);
        assert_eq!(q1.space().names(), ["C10", "g1", "tau1_s", "g2", "tau2_s"]);
    }

    /// A model whose `outputs` and `observe` disagree is told so.
    #[test]
    fn declared_and_observed_outputs_must_agree() {
        let m = both(3);
        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.5]);
        let err = m.predict_outputs(&NH, &loading).unwrap_err();
        assert!(
            err.to_string()
                .contains("declares 3 outputs but observes 2"),
            "{err}"
        );
    }
}
