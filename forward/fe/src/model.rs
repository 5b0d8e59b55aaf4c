//! What the FE forward models share: the volumetric treatment, the
//! parameter space of a law, the per-thread evaluator that keeps its solver
//! (mesh, pattern, symbolic factorisation, scratch) between calls, and the
//! conversion of solver failures into [`ForwardError`].

use palpate_core::{
    check_output_slots, Drive, Evaluator, ForwardError, Loading, ParamRole, ParamSpace, ParamSpec,
};
use palpate_material::{Law, Volumetric};

use std::sync::Arc;

use crate::body::RegionMaterial;
use crate::material::LawMaterial;
use crate::material::PointMaterial;
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
}

/// Something that builds a system for given extra (non-material)
/// parameters and applies those parameters before a run.
pub(crate) trait Setup: Send + Sync {
    fn law(&self) -> &Law;
    fn bulk(&self) -> Bulk;
    fn options(&self) -> SolverOptions;
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
    /// The outputs of a converged state: as many as the model's
    /// [`palpate_core::ForwardModel::outputs`], in that order (the
    /// evaluator checks); the first is the force a one-output consumer sees.
    fn observe(&self, sys: &System) -> Vec<f64>;
}

/// A loading as the stepper runs it: the path, and the number of its first
/// stations that are a preload (run, not reported as samples).
pub(crate) struct Path {
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

/// Runs one loading history on `sys` (built by `setup`); a
/// [`ForwardError::NotConverged`] keeps the first output of the converged
/// samples.
pub(crate) fn simulate(
    setup: &dyn Setup,
    space: &ParamSpace,
    sys: &mut System,
    theta: &[f64],
    loading: &Loading,
    progress: Option<&mut dyn FnMut(&Progress)>,
) -> Result<Simulation, ForwardError> {
    simulate_with(setup, space, sys, theta, loading, progress, false)
}

/// [`simulate`]; with `all_outputs`, a failure keeps every output of the
/// converged samples (samples x outputs, row-major).
fn simulate_with(
    setup: &dyn Setup,
    space: &ParamSpace,
    sys: &mut System,
    theta: &[f64],
    loading: &Loading,
    progress: Option<&mut dyn FnMut(&Progress)>,
    all_outputs: bool,
) -> Result<Simulation, ForwardError> {
    space.check(theta)?;
    loading.validate().map_err(ForwardError::InvalidLoading)?;
    let law = setup.law();
    let n_law = law.params().len();
    let mat = LawMaterial::new(*law, theta[..n_law].to_vec()).map_err(to_forward)?;
    let mu = law.shear_modulus(&theta[..n_law]);
    let mut opts = setup.options();
    let point: Arc<dyn PointMaterial> =
        match setup.prony_for(&theta[n_law..]).map_err(to_forward)? {
            None => Arc::new(mat),
            Some(prony) => {
                if loading.time.is_none() {
                    return Err(ForwardError::InvalidLoading(
                        "a viscoelastic material needs the time of each sample".into(),
                    ));
                }
                if opts.max_time_step.is_none() {
                    opts.max_time_step = Some(0.1 * prony.shortest_time());
                }
                Arc::new(Viscoelastic::new(mat, prony))
            }
        };
    let material = RegionMaterial {
        material: point,
        volumetric: setup.bulk().volumetric(mu),
    };
    setup
        .prepare(sys, material, &theta[n_law..])
        .map_err(to_forward)?;
    let Path { path, preload } = setup.path(loading, &opts)?;
    let mut observe = |s: &System| setup.observe(s);
    let mut outputs = stepper::run(sys, &path, &opts, &mut observe, progress)
        .map_err(|f| failure(f, all_outputs, preload))?;
    outputs.drain(..preload.min(outputs.len()));
    Ok(Simulation {
        forces: outputs.iter().map(|o| o[0]).collect(),
        outputs,
        stats: sys.stats,
    })
}

/// The per-thread evaluator of an FE model: the system is built on first use
/// and kept (pattern, symbolic LU, scratch) for every later call. Every
/// output [`Setup::observe`] returns is read at each sample;
/// `predict_into` gives the first, `predict_outputs_into` all of them.
pub(crate) struct FeEvaluator<'a> {
    pub setup: &'a dyn Setup,
    pub space: &'a ParamSpace,
    /// The number of outputs the model declares
    /// ([`palpate_core::ForwardModel::outputs`]), which `observe` returns.
    pub outputs: usize,
    pub system: Option<System>,
}

impl FeEvaluator<'_> {
    /// The simulation of `loading`, on the system built at first use.
    fn run(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        all_outputs: bool,
    ) -> Result<Simulation, ForwardError> {
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
        simulate_with(
            self.setup,
            self.space,
            sys,
            theta,
            loading,
            None,
            all_outputs,
        )
    }
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
    use palpate_core::{ForwardModel, Observable, Output};
    use palpate_enrich::ZeroOffset;

    /// Bonded C1 observing both platens: the reaction of the driven top
    /// platen (C1's force) and the sum of the internal forces along y on the
    /// bottom face, which equilibrium makes equal to it. `declared` is the
    /// number of outputs it claims (2, or wrong on purpose).
    struct BothPlatens {
        c1: C1Fe,
        declared: usize,
    }

    impl Setup for BothPlatens {
        fn law(&self) -> &Law {
            self.c1.law()
        }
        fn bulk(&self) -> Bulk {
            self.c1.bulk()
        }
        fn options(&self) -> SolverOptions {
            Setup::options(&self.c1)
        }
        fn build(&self) -> Result<System, FeError> {
            self.c1.build()
        }
        fn prepare(
            &self,
            sys: &mut System,
            material: RegionMaterial,
            extra: &[f64],
        ) -> Result<(), FeError> {
            self.c1.prepare(sys, material, extra)
        }
        fn observe(&self, sys: &System) -> Vec<f64> {
            let fint = sys.internal_forces();
            let bottom = sys.mesh.node_set("bottom").expect("C1 has a bottom");
            let d = sys.dofs.dim;
            vec![
                sys.channel_reaction(0),
                bottom.iter().map(|&n| fint[n * d + 1]).sum(),
            ]
        }
    }

    impl ForwardModel for BothPlatens {
        fn name(&self) -> String {
            "C1 observing both platens".into()
        }
        fn space(&self) -> &ParamSpace {
            self.c1.space()
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
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
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(FeEvaluator {
                setup: self,
                space: self.c1.space(),
                outputs: self.outputs().len(),
                system: None,
            })
        }
        fn expensive(&self) -> bool {
            true
        }
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
        let m = BothPlatens {
            c1: c1(),
            declared: 2,
        };
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

    /// A model whose `outputs` and `observe` disagree is told so.
    #[test]
    fn declared_and_observed_outputs_must_agree() {
        let m = BothPlatens {
            c1: c1(),
            declared: 3,
        };
        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.5]);
        let err = m.predict_outputs(&NH, &loading).unwrap_err();
        assert!(
            err.to_string()
                .contains("declares 3 outputs but observes 2"),
            "{err}"
        );
    }
}
