//! From a description to a forward model: the setup its specimen and tool
//! call for, configured from the description's fields, with the
//! description's parameter space ([`Experiment::param_space`]), and the
//! loading of its protocol's segments.
//!
//! | specimen | tool | setup |
//! |---|---|---|
//! | axisymmetric cylinder, one material | platens, friction 0 on a sliding base or `"bonded"` on a bonded one | [`crate::C1Setup`] (displacement platens) |
//! | axisymmetric cylinder, one material, bonded base | flat punch, frictionless | [`crate::Q1Setup`] |
//! | axisymmetric cylinder | any other | [`crate::N1Setup::from_experiment`] |
//! | 3D block, one material, bonded base | needle, cone, sphere, flat punch at the centre | [`crate::N3Setup`] (quarter model) |
//! | plane-stress block with nodules of one material and radius | wheel pressed, then rolled | [`crate::R2Setup`] |

use palpate_core::{
    Drive, Enrichable, Evaluator, ForwardModel, Loading, Observable, Output, ParamSpace,
    Sensitivities,
};
use palpate_material::Law;

use super::params::material_law;
use super::{BulkSpec, ElementSpec, Experiment, MaterialSpec, Specimen, SupportSpec, Tool, Value};
use crate::model::{Bulk, FeModel, PlaneCell, Support};
use crate::n3::{N3Element, N3Mesh};
use crate::r2::Nodule;
use crate::tool::ToolShape;
use crate::viscoelastic::Prony;
use crate::{C1Fe, FeError, N1Needle, N3Needle, Platens, Q1Punch, R2Rolling};

fn bad(field: impl Into<String>, reason: impl Into<String>) -> FeError {
    FeError::InvalidConfig {
        field: field.into(),
        reason: reason.into(),
    }
}

/// A model with the parameter space of the description it was built from
/// (the names, order, bounds and starts of [`Experiment::param_space`]);
/// it dereferences to the model, whose setup's fields are its settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Described<M> {
    model: M,
    space: ParamSpace,
    loading: Option<Loading>,
}

impl<M: ForwardModel> Described<M> {
    /// `model` with `space`, which must have as many parameters as the
    /// model's own (an error says which differ).
    pub fn new(model: M, space: ParamSpace) -> Result<Self, FeError> {
        let own = model.space().names();
        if own.len() != space.len() {
            return Err(bad(
                "materials",
                format!(
                    "the model takes the parameters {} but the description has {}",
                    own.join(", "),
                    space.names().join(", ")
                ),
            ));
        }
        Ok(Described {
            model,
            space,
            loading: None,
        })
    }

    /// The same with the loading of the description's protocol.
    pub fn with_loading(mut self, loading: Option<Loading>) -> Self {
        self.loading = loading;
        self
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The loading of the description's protocol segments (`None`: the
    /// protocol is a record's).
    pub fn loading(&self) -> Option<&Loading> {
        self.loading.as_ref()
    }
}

impl<M> std::ops::Deref for Described<M> {
    type Target = M;
    fn deref(&self) -> &M {
        &self.model
    }
}

impl<M: ForwardModel> ForwardModel for Described<M> {
    fn name(&self) -> String {
        self.model.name()
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        self.model.observable()
    }
    fn outputs(&self) -> Vec<Output> {
        self.model.outputs()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        self.model.evaluator()
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        self.model.as_enrichable()
    }
    fn expensive(&self) -> bool {
        self.model.expensive()
    }
    /// The model's own: the description's parameters are the model's, in
    /// its order (as the evaluator takes them).
    fn as_sensitivities(&self) -> Option<&dyn Sensitivities> {
        self.model.as_sensitivities()
    }
}

/// The model of an experiment: the FE setup its specimen and tool call
/// for (the table in the module's doc), with the description's parameter
/// space.
#[derive(Debug, Clone)]
pub enum ExperimentModel {
    /// An axisymmetric cylinder (N1's setup, generalised).
    Cylinder(Described<N1Needle>),
    /// A one-material cylinder between platens that are both frictionless
    /// or both bonded (C1's setup).
    Compression(Described<C1Fe>),
    /// A flat punch on a one-material cylinder with a bonded base (Q1's
    /// setup).
    Punch(Described<Q1Punch>),
    /// A tool at the centre of a 3D block (N3's quarter model).
    Block(Described<N3Needle>),
    /// A wheel pressed into a plane-stress block, then rolled (R2's setup).
    Rolling(Described<R2Rolling>),
}

/// The model built, with the experiment's name and loading.
impl ExperimentModel {
    /// The model behind the forward trait.
    pub fn as_forward(&self) -> &dyn ForwardModel {
        match self {
            ExperimentModel::Cylinder(m) => m,
            ExperimentModel::Compression(m) => m,
            ExperimentModel::Punch(m) => m,
            ExperimentModel::Block(m) => m,
            ExperimentModel::Rolling(m) => m,
        }
    }
    /// The model boxed.
    pub fn boxed(self) -> Box<dyn ForwardModel> {
        match self {
            ExperimentModel::Cylinder(m) => Box::new(m),
            ExperimentModel::Compression(m) => Box::new(m),
            ExperimentModel::Punch(m) => Box::new(m),
            ExperimentModel::Block(m) => Box::new(m),
            ExperimentModel::Rolling(m) => Box::new(m),
        }
    }
    /// The model's name (its settings, as provenance records them).
    pub fn name(&self) -> String {
        self.as_forward().name()
    }
    /// The loading of the description's `protocol.segments` (a wheel's
    /// `tool.path`), so that a description runs without a record
    /// ([`Experiment::loading`]); `None` when the protocol is a record's.
    pub fn loading(&self) -> Option<Loading> {
        match self {
            ExperimentModel::Cylinder(m) => m.loading().cloned(),
            ExperimentModel::Compression(m) => m.loading().cloned(),
            ExperimentModel::Punch(m) => m.loading().cloned(),
            ExperimentModel::Block(m) => m.loading().cloned(),
            ExperimentModel::Rolling(m) => m.loading().cloned(),
        }
    }
    /// Which setup it is: `cylinder`, `compression`, `punch`, `block`,
    /// `rolling`.
    pub fn kind(&self) -> &'static str {
        match self {
            ExperimentModel::Cylinder(_) => "cylinder",
            ExperimentModel::Compression(_) => "compression",
            ExperimentModel::Punch(_) => "punch",
            ExperimentModel::Block(_) => "block",
            ExperimentModel::Rolling(_) => "rolling",
        }
    }
}

impl Experiment {
    /// The forward model of this experiment (the module's table), after
    /// [`Experiment::check`]; its parameter space is
    /// [`Experiment::param_space`]. What no setup can model yet is an error
    /// naming the field that asks for it.
    pub fn model(&self) -> Result<ExperimentModel, FeError> {
        self.check()?;
        let space = self.param_space()?;
        let loading = self.loading()?;
        Ok(match (&self.specimen, &self.tool) {
            (Specimen::Mesh(m), _) => {
                return Err(bad(
                    "specimen.file",
                    format!(
                        "{}: a model on a Gmsh mesh is not supported yet; describe the specimen by its shape (cylinder or block)",
                        m.file
                    ),
                ))
            }
            (Specimen::Cylinder(c), _) if c.kinematics == super::CylinderKinematics::ThreeD => {
                return Err(bad(
                    "specimen.kinematics",
                    "a cylinder in 3D is not supported yet: \"axisymmetric\" (the tool on the axis), or a 3D block",
                ))
            }
            (Specimen::Cylinder(_), Tool::Platens(_)) if self.is_c1() => {
                ExperimentModel::Compression(Described::new(c1_from(self)?, space)?.with_loading(loading))
            }
            (Specimen::Cylinder(_), Tool::FlatPunch(_)) if self.is_q1() => {
                ExperimentModel::Punch(Described::new(q1_from(self)?, space)?.with_loading(loading))
            }
            (Specimen::Cylinder(_), _) => ExperimentModel::Cylinder(Described::new(
                FeModel::from_setup(crate::N1Setup::from_experiment(self)?),
                space,
            )?
            .with_loading(loading)),
            (Specimen::Block(_), Tool::Wheel(_)) => {
                ExperimentModel::Rolling(Described::new(r2_from(self)?, space)?.with_loading(loading))
            }
            (Specimen::Block(_), _) => {
                ExperimentModel::Block(Described::new(n3_from(self)?, space)?.with_loading(loading))
            }
        })
    }

    /// The loading of `protocol.segments` (a wheel's `tool.path`), `None`
    /// when the protocol is a record's. Each ramp, unload, hold or roll
    /// adds its `samples` (default `protocol.samples`, else 20) after the
    /// start, which is the first sample (depth 0, time 0): displacements
    /// (mm) for a tool pressed in, with times when the segments give them;
    /// wheel positions (mm) from `at_x` for a wheel.
    pub fn loading(&self) -> Result<Option<Loading>, FeError> {
        self.check()?;
        let segments = self.segments();
        if segments.is_empty() {
            return Ok(None);
        }
        let default = self.protocol.samples.unwrap_or(20);
        if let Tool::Wheel(_) = self.tool {
            let mut x = vec![segments[0].at_x.unwrap_or(0.0)];
            for s in &segments[1..] {
                let n = s.samples.unwrap_or(default).max(1);
                if let Some(to) = s.roll_to_x {
                    let from = *x.last().unwrap_or(&0.0);
                    x.extend((1..=n).map(|k| from + (to - from) * k as f64 / n as f64));
                }
            }
            return Ok(Some(Loading::quasi_static(Drive::PositionMm, x)));
        }
        let timed = segments
            .iter()
            .any(|s| s.time.is_some() || s.hold.is_some());
        let (mut d, mut t) = (vec![0.0], vec![0.0]);
        for s in segments {
            let n = s.samples.unwrap_or(default).max(1);
            let (d0, t0) = (*d.last().unwrap_or(&0.0), *t.last().unwrap_or(&0.0));
            let (to, dt) = match (s.ramp_to.or(s.unload_to), s.hold) {
                (Some(to), _) => (to, s.time.unwrap_or(0.0)),
                (None, Some(h)) => (d0, h),
                (None, None) => continue,
            };
            for k in 1..=n {
                let f = k as f64 / n as f64;
                d.push(d0 + (to - d0) * f);
                t.push(t0 + dt * f);
            }
        }
        Ok(Some(if timed {
            Loading::timed(Drive::DisplacementMm, t, d)
        } else {
            Loading::quasi_static(Drive::DisplacementMm, d)
        }))
    }

    /// Sizes the mesh for records reaching `depth` (mm) when the protocol
    /// is the record's: a description without segments (and not a wheel's)
    /// takes one ramp to `depth` as its protocol, the design depth of the
    /// cylinder's mesh rule (`models/cylinder.rs`), instead of the tool's
    /// default. A description with segments is left as it is (its mesh is
    /// designed for them), as is a non-positive or non-finite depth.
    pub fn size_for_depth(&mut self, depth: f64) {
        let wheel = matches!(self.tool, Tool::Wheel(_));
        if !wheel
            && self.protocol.segments.is_empty()
            && self.protocol.from_record.is_none()
            && depth > 0.0
            && depth.is_finite()
        {
            self.protocol.segments = vec![super::Segment {
                ramp_to: Some(depth),
                ..Default::default()
            }];
        }
    }

    /// Whether C1's setup models this experiment: one material on the
    /// axisymmetric cylinder, no inclusions, platens both frictionless (a
    /// sliding base, tool friction 0) or both bonded.
    fn is_c1(&self) -> bool {
        let (Specimen::Cylinder(c), Tool::Platens(p)) = (&self.specimen, &self.tool) else {
            return false;
        };
        let plain = c.layers.is_empty() && c.inclusions.is_empty() && self.materials.len() == 1;
        let q1p0 = !matches!(self.mesh.element, Some(ElementSpec::Quad9));
        let matched = matches!(
            (&c.support, fixed_friction(&p.friction)),
            (SupportSpec::Sliding, Some(Fr::Value(0.0))) | (SupportSpec::Bonded, Some(Fr::Bonded))
        );
        plain && q1p0 && matched
    }

    /// Whether Q1's setup models this experiment: a frictionless flat
    /// punch on the axis of a one-material cylinder with a bonded base.
    fn is_q1(&self) -> bool {
        let (Specimen::Cylinder(c), Tool::FlatPunch(p)) = (&self.specimen, &self.tool) else {
            return false;
        };
        c.layers.is_empty()
            && c.inclusions.is_empty()
            && self.materials.len() == 1
            && c.support == SupportSpec::Bonded
            && matches!(fixed_friction(&p.friction), Some(Fr::Value(0.0)))
    }

    /// The one material of a single-material specimen: name, spec, law.
    fn only_material(&self) -> Result<(&str, &MaterialSpec, Law), FeError> {
        let order = self.material_order()?;
        if order.len() != 1 {
            return Err(bad(
                "materials",
                format!(
                    "this model has one material; the description uses {}",
                    order.join(", ")
                ),
            ));
        }
        let (name, m) = self
            .materials
            .get_key_value(&order[0])
            .ok_or_else(|| bad("materials", "no material"))?;
        Ok((name, m, material_law(name, m)?))
    }
}

/// A friction coefficient that is not a parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fr {
    Value(f64),
    Bonded,
}

fn fixed_friction(v: &Value) -> Option<Fr> {
    match v {
        Value::Fixed(f) => Some(Fr::Value(*f)),
        Value::Keyword(k) if k == "bonded" => Some(Fr::Bonded),
        Value::Keyword(k) if k == "frictionless" => Some(Fr::Value(0.0)),
        _ => None,
    }
}

/// A tool's friction for a setup with a coefficient: (value, is a
/// parameter); `"bonded"` is refused naming `field`.
fn friction_of(v: &Value, field: &str) -> Result<(f64, bool), FeError> {
    match v {
        Value::Param(p) => Ok((p.start, true)),
        other => match fixed_friction(other) {
            Some(Fr::Value(f)) => Ok((f, false)),
            _ => Err(bad(
                field,
                "\"bonded\" (no slip) is not supported by this model: a coefficient (e.g. 0.8) or { start = .. }",
            )),
        },
    }
}

/// A material's volumetric treatment; an error names `materials.NAME.bulk`.
pub fn bulk_of(name: &str, m: &MaterialSpec) -> Result<Bulk, FeError> {
    match &m.bulk {
        None => Ok(Bulk::Exact),
        Some(BulkSpec::Keyword(k)) if k == "exact" => Ok(Bulk::Exact),
        Some(BulkSpec::Ratio(r)) if *r > 0.0 && r.is_finite() => Ok(Bulk::Ratio(*r)),
        Some(other) => Err(bad(
            format!("materials.{name}.bulk"),
            format!("{other:?}: expected \"exact\" or a bulk-to-shear ratio K / mu0 > 0"),
        )),
    }
}

/// A material's Prony series given as numbers (`None`: elastic), and the
/// number of its terms that are parameters (0 when they are numbers).
pub fn prony_of(name: &str, m: &MaterialSpec) -> Result<(Option<Prony>, usize), FeError> {
    if m.prony.is_empty() {
        return Ok((None, 0));
    }
    if m.prony
        .iter()
        .any(|t| matches!(t.g, Value::Param(_)) || matches!(t.tau, Value::Param(_)))
    {
        return Ok((None, m.prony.len()));
    }
    let num = |v: &Value| match v {
        Value::Fixed(x) => *x,
        _ => f64::NAN,
    };
    let terms = m.prony.iter().map(|t| (num(&t.g), num(&t.tau))).collect();
    Prony::new(terms)
        .map(|p| (Some(p), 0))
        .map_err(|e| bad(format!("materials.{name}.prony"), e.to_string()))
}

/// The refusal of a Prony series by a model that is elastic.
fn elastic_only(name: &str, m: &MaterialSpec, model: &str) -> Result<(), FeError> {
    if m.prony.is_empty() {
        Ok(())
    } else {
        Err(bad(
            format!("materials.{name}.prony"),
            format!("{model} is elastic here: a Prony series is not supported yet"),
        ))
    }
}

/// The 2D element of the description (`default` when not given).
fn plane_cell(e: &Experiment, default: PlaneCell) -> PlaneCell {
    match e.mesh.element {
        Some(ElementSpec::Quad4) => PlaneCell::Quad4,
        Some(ElementSpec::Quad9) => PlaneCell::Quad9,
        _ => default,
    }
}

/// The deepest depth of the protocol's segments (mm; 0 without segments).
fn deepest(e: &Experiment) -> f64 {
    e.segments()
        .iter()
        .filter_map(|s| s.ramp_to.or(s.press_to))
        .fold(0.0, f64::max)
}

/// The tool's profile for an axisymmetric or revolved setup: needle and
/// cone (a sharp cone's tip is 1e-3 of the protocol's deepest depth),
/// sphere, flat punch (edge a tenth of the radius unless given), platen.
pub fn tool_shape(e: &Experiment) -> Result<ToolShape, FeError> {
    Ok(match &e.tool {
        Tool::Needle(t) => ToolShape::Needle {
            tip_radius: t.tip_radius.unwrap_or(2.5),
            half_angle_deg: t.half_angle.unwrap_or(15.0),
        },
        Tool::Cone(t) => {
            let half_angle_deg = t.half_angle.ok_or_else(|| {
                bad(
                    "tool.half_angle",
                    "missing: the cone's half-angle in degrees",
                )
            })?;
            let tip_radius = match t.tip_radius {
                Some(r) if r > 0.0 => r,
                _ => {
                    let d = deepest(e);
                    if d > 0.0 {
                        1e-3 * d
                    } else {
                        return Err(bad(
                            "tool.tip_radius",
                            "missing: a sharp cone's tip is rounded to 1e-3 of the protocol's depth, and the protocol gives none; give tip_radius (mm)",
                        ));
                    }
                }
            };
            ToolShape::Needle {
                tip_radius,
                half_angle_deg,
            }
        }
        Tool::Sphere(t) => ToolShape::Sphere { radius: t.radius },
        Tool::FlatPunch(t) => ToolShape::FlatPunch {
            radius: t.radius,
            edge_radius: t.edge_radius.unwrap_or(t.radius / 10.0),
        },
        Tool::Platens(_) => ToolShape::Platen,
        Tool::Wheel(_) => {
            return Err(bad(
                "tool.shape",
                "a wheel has no axisymmetric profile: it rolls on a plane block",
            ))
        }
    })
}

fn height_of(e: &Experiment) -> Result<f64, FeError> {
    e.height().ok_or_else(|| {
        bad(
            "specimen.height",
            "missing: give the height (mm), or the record's metadata must",
        )
    })
}

/// C1's setup from a one-material cylinder between matched platens; mesh
/// level L has 1/L mm elements (the reference's 19 x 9 at level 1).
pub fn c1_from(e: &Experiment) -> Result<C1Fe, FeError> {
    let Specimen::Cylinder(c) = &e.specimen else {
        return Err(bad("specimen.shape", "the compression model is a cylinder"));
    };
    let (name, m, law) = e.only_material()?;
    let platens = match &c.support {
        SupportSpec::Bonded => Platens::Bonded,
        _ => Platens::Frictionless,
    };
    let mut model = C1Fe::new(law, platens);
    let height = height_of(e)?;
    let level = e.mesh.level.unwrap_or(1) as f64;
    model.diameter = 2.0 * c.radius;
    model.height = height;
    model.elements = (
        ((c.radius * level).round() as usize).max(1),
        ((height * level).round() as usize).max(1),
    );
    model.bulk = bulk_of(name, m)?;
    let (prony, params) = prony_of(name, m)?;
    if params > 0 {
        return Err(bad(
            format!("materials.{name}.prony"),
            "Prony terms as parameters are not supported between platens yet: give them as numbers",
        ));
    }
    model.prony = prony;
    Ok(model)
}

/// Q1's setup from a frictionless flat punch on a one-material cylinder
/// with a bonded base (mesh level 2 unless given).
pub fn q1_from(e: &Experiment) -> Result<Q1Punch, FeError> {
    let (Specimen::Cylinder(c), Tool::FlatPunch(p)) = (&e.specimen, &e.tool) else {
        return Err(bad(
            "tool.shape",
            "the punch model is a flat punch on a cylinder",
        ));
    };
    let (name, m, law) = e.only_material()?;
    let mut model = Q1Punch::new(law);
    model.punch_radius = p.radius;
    model.edge_radius = p.edge_radius.unwrap_or(p.radius / 10.0);
    model.radius = c.radius;
    model.height = height_of(e)?;
    if let Some(l) = e.mesh.level {
        model.level = l;
    }
    model.element = plane_cell(e, PlaneCell::Quad4);
    model.bulk = bulk_of(name, m)?;
    let (prony, params) = prony_of(name, m)?;
    model.prony = prony;
    Ok(if params > 0 {
        model.with_prony_parameters(params)
    } else {
        model
    })
}

/// N3's quarter model from a tool at the centre of a one-material 3D
/// block with a bonded base (mesh level 1 unless given; `hex27` on the
/// O-grid).
pub fn n3_from(e: &Experiment) -> Result<N3Needle, FeError> {
    let Specimen::Block(b) = &e.specimen else {
        return Err(bad("specimen.shape", "the 3D model is a block"));
    };
    let size = b.size.ok_or_else(|| {
        bad(
            "specimen.size",
            "missing: the block's size = [x, y, z] (mm)",
        )
    })?;
    if !b.inclusions.is_empty() {
        return Err(bad(
            "specimen.inclusions",
            "inclusions in a 3D block are not supported yet",
        ));
    }
    if b.support != SupportSpec::Bonded {
        return Err(bad(
            "specimen.support",
            "the 3D block's base is bonded (\"bonded\"); other supports are not supported yet",
        ));
    }
    let (name, m, law) = e.only_material()?;
    elastic_only(name, m, "the 3D block")?;
    let (at, friction) = match &e.tool {
        Tool::Sphere(t) => (t.at, &t.friction),
        Tool::Cone(t) | Tool::Needle(t) => (t.at, &t.friction),
        Tool::FlatPunch(t) => (t.at, &t.friction),
        _ => {
            return Err(bad(
                "tool.shape",
                "on a 3D block: needle, cone, sphere or flat_punch",
            ))
        }
    };
    if let Some(a) = at {
        if a != [0.0, 0.0] {
            return Err(bad(
                "tool.at",
                "the 3D model is a quarter of the block with the tool at the centre of the top face (at = [0, 0]); off the centre is not supported yet",
            ));
        }
    }
    let mut model = N3Needle::new(law);
    model.tool = tool_shape(e)?;
    let (f, is_param) = friction_of(friction, "tool.friction")?;
    model.friction = f;
    model.set_friction_parameter(is_param);
    model.size = [size[0] / 2.0, size[1] / 2.0, size[2]];
    model.bulk = bulk_of(name, m)?;
    if let Some(l) = e.mesh.level {
        model.level = l;
    }
    if e.mesh.element == Some(ElementSpec::Hex27) {
        model.element = N3Element::Hex27;
        model.mesh = N3Mesh::OGrid;
    }
    Ok(model)
}

/// R2's setup from a plane-stress block with nodules (circles of one
/// material and one radius) and a wheel pressed at `at_x`, then rolled
/// (mesh level 1 unless given, 9-node elements).
pub fn r2_from(e: &Experiment) -> Result<R2Rolling, FeError> {
    let (Specimen::Block(b), Tool::Wheel(w)) = (&e.specimen, &e.tool) else {
        return Err(bad("tool.shape", "the rolling model is a wheel on a block"));
    };
    if b.kinematics != super::BlockKinematics::PlaneStress {
        return Err(bad(
            "specimen.kinematics",
            "the rolling wheel is modelled in plane stress (\"plane_stress\"); plane strain is not supported yet",
        ));
    }
    if e.mesh.element == Some(ElementSpec::Quad4) {
        return Err(bad(
            "mesh.element",
            "the rolling model uses 9-node elements (\"quad9\")",
        ));
    }
    let order = e.material_order()?;
    let placed = e.placed_inclusions()?;
    if placed.is_empty() || order.len() != 2 {
        return Err(bad(
            "specimen.inclusions",
            "the rolling model has nodules of one material (a block without nodules, or nodules of several materials, is not supported yet)",
        ));
    }
    let radius = placed[0].radius;
    if let Some(i) = placed.iter().position(|p| p.radius != radius) {
        return Err(bad(
            format!("specimen.inclusions[{i}].radius"),
            format!("the rolling model's nodules have one radius ({radius} mm here)"),
        ));
    }
    let (tissue, nodule) = (&e.materials[&order[0]], &e.materials[&order[1]]);
    for (n, m) in [(&order[0], tissue), (&order[1], nodule)] {
        elastic_only(n, m, "the rolling model")?;
    }
    if bulk_of(&order[0], tissue)? != bulk_of(&order[1], nodule)? {
        return Err(bad(
            format!("materials.{}.bulk", order[1]),
            "the rolling model treats incompressibility alike in the block and the nodules: give both the same bulk",
        ));
    }
    let path = e.segments();
    let (press, roll) = match path {
        [p, r] if p.press_to.is_some() && r.roll_to_x.is_some() => (p, r),
        _ => {
            return Err(bad(
                if w.path.is_empty() { "protocol.segments" } else { "tool.path" },
                "the rolling model is pressed once, then rolled: [{ press_to = .., at_x = .. }, { roll_to_x = .. }]",
            ))
        }
    };
    let (friction, is_param) = friction_of(&w.friction, "tool.friction")?;
    if is_param {
        return Err(bad(
            "tool.friction",
            "the wheel's friction as a parameter is not supported yet: give a coefficient",
        ));
    }
    let mut model = R2Rolling::new(
        material_law(&order[0], tissue)?,
        material_law(&order[1], nodule)?,
        press.press_to.unwrap_or(0.0),
    );
    model.nodules = placed
        .iter()
        .map(|p| Nodule {
            x: p.horizontal.first().copied().unwrap_or(0.0),
            depth: p.depth,
        })
        .collect();
    model.nodule_radius = radius;
    model.wheel_radius = w.radius;
    model.length = b.length.unwrap_or(0.0);
    model.height = b.height.unwrap_or(0.0);
    model.thickness = b.thickness.unwrap_or(0.0);
    model.press_x = press.at_x.unwrap_or(0.0);
    model.roll_to = roll.roll_to_x.unwrap_or(0.0);
    model.friction = friction;
    model.base = match b.support {
        SupportSpec::Bonded => Support::Bonded,
        SupportSpec::Sliding => Support::Sliding,
        _ => {
            return Err(bad(
                "specimen.support",
                "the rolling model's base is \"bonded\" or \"sliding\"",
            ))
        }
    };
    model.bulk = bulk_of(&order[0], tissue)?;
    if let Some(l) = e.mesh.level {
        model.level = l;
    }
    crate::r2::check_model(&model).map_err(|(field, reason)| {
        let field = match field.as_str() {
            "rd" => "tool.path[0].press_to",
            "press_x" => "tool.path[0].at_x",
            "friction" => "tool.friction",
            _ => "specimen.inclusions",
        };
        bad(field, reason)
    })?;
    Ok(model)
}
