//! The default model and candidate effects of a test kind: which
//! [`ModelSpec`] a record of a test is fitted with when the user names only
//! a law (`--benchmark`, a manifest's `law = "..."`), the base model of the
//! gap diagnosis, and the effects it looks for. Moved out of
//! [`crate::model`] (the spec and its factory), which re-exports them.

use crate::model::{C1Spec, HomogeneousSpec, Mesh, ModelSpec, N1NeedleSpec};
use crate::records::TestKind;
use palpate_core::{Effect, ForwardModel};
use palpate_fe::{N3Element, PlaneCell};
use palpate_material::Law;

/// The model of a data set's test for a law (the legacy manifest form
/// `law = "..."` and the commands' `--benchmark`): the analytic homogeneous
/// test, analytic C1, or N1 with the docs/benchmarks.md needle (friction 0.8) on
/// its default mesh ([`set_n1_mesh`]: the cheapest within 0.5 % of the
/// converged force).
pub fn for_test(test: TestKind, law: Law) -> ModelSpec {
    let law = law.to_string();
    match test {
        TestKind::Homogeneous(mode) => ModelSpec::Homogeneous(HomogeneousSpec {
            law,
            mode: mode.name().to_string(),
            axial_stretch: None,
            viscoelastic: None,
        }),
        TestKind::GeneralBiaxial | TestKind::SimpleShear => {
            ModelSpec::Homogeneous(HomogeneousSpec {
                law,
                mode: if test == TestKind::SimpleShear {
                    "simple_shear"
                } else {
                    "general_biaxial"
                }
                .to_string(),
                axial_stretch: None,
                viscoelastic: None,
            })
        }
        TestKind::C1 => ModelSpec::C1(C1Spec { law }),
        TestKind::N1 => ModelSpec::N1Needle(N1NeedleSpec {
            law,
            ..Default::default()
        }),
    }
}

/// The base model of the gap diagnosis for a record of `test`: C1 analytic
/// (lubricated platens), N1 with a frictionless needle on the coarse mesh
/// and a bonded base, so that `friction` and `boundary_condition` are
/// effects to find, or the analytic homogeneous test of the record's kind
/// (elastic: viscoelasticity is an effect to find). A record's own options
/// (a simple-shear record's axial stretch) are set by [`gap_base_for`].
pub fn gap_base(test: TestKind, law: Law) -> anyhow::Result<ModelSpec> {
    let spec_law = law.to_string();
    match test {
        TestKind::C1 => Ok(ModelSpec::C1(C1Spec { law: spec_law })),
        TestKind::N1 => Ok(ModelSpec::N1Needle(N1NeedleSpec {
            law: spec_law,
            friction: Some(0.0),
            mesh: Some(Mesh::Level(1)),
            ..Default::default()
        })),
        TestKind::Homogeneous(_) | TestKind::GeneralBiaxial | TestKind::SimpleShear => {
            Ok(for_test(test, law))
        }
    }
}

/// [`gap_base`] for one record read by [`crate::records::TestData`]:
/// a simple-shear record keeps the axial stretch it was read with.
pub fn gap_base_for(record: &crate::records::TestData, law: Law) -> anyhow::Result<ModelSpec> {
    if record.test.is_homogeneous() {
        Ok(super::record_spec(record, law, None))
    } else {
        gap_base(record.test, law)
    }
}

/// The default candidate effects of the gap diagnosis for a base model and
/// the record it is diagnosed on (`None`: every effect the model offers).
///
/// - N1: GAP.md's `friction` and `boundary_condition`; the N1 model also
///   offers `material_form` and `zero_offset`, but on one force-depth curve
///   friction and a stiffening law are confounded (docs/gap-diagnosis.md),
///   so they are candidates on request only.
/// - Homogeneous records: those of the model's effects the record can show:
///   `viscoelasticity` only on a timed record (a `time_s` column), and
///   `tension_compression_asymmetry` only when the stretches lie on both
///   sides of 1 (elsewhere its sensitivity is zero, [`spans_tension_and_compression`]).
///   `material_form` and (stretch-driven tests) `zero_offset` always.
/// - C1: every effect the model offers.
pub fn default_effects(
    base: &ModelSpec,
    model: &dyn ForwardModel,
    loading: &palpate_core::Loading,
) -> Option<Vec<Effect>> {
    match base {
        ModelSpec::N1Needle(_) => Some(vec![Effect::Friction, Effect::BoundaryCondition]),
        ModelSpec::Homogeneous(_) => Some(
            palpate_core::enrichable::effects_of(model)
                .into_iter()
                .filter(|e| match e {
                    Effect::Viscoelasticity => loading.time.is_some(),
                    Effect::TensionCompressionAsymmetry => {
                        spans_tension_and_compression(&loading.drive)
                    }
                    _ => true,
                })
                .collect(),
        ),
        _ => None,
    }
}

/// Whether a stretch history has samples in compression (< 1) and in
/// tension (> 1), two at least on each side (one sample is not a slope).
pub fn spans_tension_and_compression(stretch: &[f64]) -> bool {
    const EPS: f64 = 1e-9;
    let below = stretch.iter().filter(|&&s| s < 1.0 - EPS).count();
    let above = stretch.iter().filter(|&&s| s > 1.0 + EPS).count();
    below >= 2 && above >= 2
}

/// Checks that a model offers every requested effect; the error (`E: ...`)
/// names the first one it does not offer and lists those it does.
pub fn check_effects(model: &dyn ForwardModel, effects: &[Effect]) -> Result<(), String> {
    let offered = palpate_core::enrichable::effects_of(model);
    match effects.iter().find(|e| !offered.contains(e)) {
        None => Ok(()),
        Some(e) => {
            let names: Vec<String> = offered.iter().map(|e| e.to_string()).collect();
            Err(format!(
                "{e}: {} does not offer this effect (it offers: {})",
                model.name(),
                if names.is_empty() {
                    "none".into()
                } else {
                    names.join(", ")
                }
            ))
        }
    }
}

/// Effect names (GAP.md) parsed, the error naming the bad one.
pub fn parse_effects(names: &[String]) -> anyhow::Result<Vec<Effect>> {
    names
        .iter()
        .map(|e| e.parse::<Effect>().map_err(|m| anyhow::anyhow!("{m}")))
        .collect()
}

/// Sets the mesh and element of an N1 model from a spec's `mesh` and
/// `element` (the model's tool and friction already set).
///
/// Without `mesh`, the needle gets the mesh and element that meet 0.5 %
/// of the converged force at 2, 5 and 10 mm at the least cost:
/// [`palpate_fe::accuracy::N1_QUAD9_BENCH`], 9-node Q2/P1 cells (1.4 s of
/// CPU to 10 mm, where the Q1/P0 medium mesh takes 5 s for +0.63 %;
/// docs/validation/fe.md "N1 speed"); with `element = "quad4"`, or
/// another tool (that mesh was measured for the needle), the Q1/P0 medium
/// mesh. `mesh = "bench"` names the benchmark mesh of the element
/// (Q2/P1 by default; `quad4`: `MeshDensity::BENCH_GRADING`). A level
/// (`coarse`, `medium`, `fine`, `N`) keeps its meaning: Q1/P0 elements of
/// 0.4/N mm unless `element` says otherwise.
pub(crate) fn set_n1_mesh(
    mesh: Option<Mesh>,
    element: Option<PlaneCell>,
    m: &mut palpate_fe::N1Needle,
) {
    use palpate_fe::{accuracy::N1_QUAD9_BENCH, MeshDensity, ToolShape};
    let needle = m.tool == ToolShape::n1_needle();
    match mesh {
        None if needle && element != Some(PlaneCell::Quad4) => {
            m.element = PlaneCell::Quad9;
            m.grading = Some(N1_QUAD9_BENCH);
        }
        Some(Mesh::Bench) => {
            m.element = element.unwrap_or(PlaneCell::Quad9);
            m.grading = Some(match m.element {
                PlaneCell::Quad9 => N1_QUAD9_BENCH,
                PlaneCell::Quad4 => MeshDensity::BENCH_GRADING,
            });
        }
        None => {
            m.element = element.unwrap_or(PlaneCell::Quad4);
            m.mesh = super::DEFAULT_MESH;
        }
        Some(Mesh::Level(level)) => {
            m.element = element.unwrap_or(PlaneCell::Quad4);
            m.mesh = MeshDensity { level };
        }
    }
}

/// The default N3 element when the spec names none. With no `mesh`, for
/// the needle with friction: 27-node Q2/P1 hexahedra on the quarter O-grid
/// (level 1: +0.6 % from the extrapolated force at 10 mm, where the 8-node
/// box is +6.4 %). Otherwise the 8-node Q1/P0 box: a mesh level names the
/// box's level, and frictionless the 27-node cells stop near 5.5 mm
/// (docs/validation/fe.md "N3").
pub(crate) fn n3_default_element(m: &palpate_fe::N3Needle, mesh_given: bool) -> N3Element {
    if !mesh_given && m.friction > 0.0 && m.tool == palpate_fe::ToolShape::n1_needle() {
        N3Element::Hex27
    } else {
        N3Element::Hex8
    }
}
