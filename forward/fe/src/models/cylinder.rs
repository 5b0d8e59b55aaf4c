//! The axisymmetric cylinder of an experiment description
//! ([`crate::experiment::Experiment`] with `specimen.shape = "cylinder"`):
//! N1's setup ([`N1Setup`]) with the description's size, layers,
//! materials, tool, friction, support and mesh. N1 is one preset of it
//! ([`CylinderSetup`] is the same type under the general name).
//!
//! What a description sets:
//!
//! * **Tools** (on the axis): a sphere, a cone (a needle profile: a
//!   spherical tip tangent to the cone; `tip_radius` defaults to 1e-3 of
//!   the design depth, a sharp cone), N1's needle, a flat punch (edge radius
//!   default a tenth of the radius), or a platen over the whole top (in contact with the top and the free side, onto which the side folds at large compression). The
//!   tool's Coulomb friction is a number, a parameter (`friction`), or
//!   `"bonded"`: an infinite coefficient, so that a surface point sticks to
//!   the tool where it first touches it and never slips (the return map
//!   never leaves its stick branch).
//! * **Supports** of the base: `bonded` (fixed), `sliding` (`u_z = 0`),
//!   `symmetry` (a mirror plane: also `u_z = 0` with `u_r` free; with
//!   platens, a cylinder compressed between two identical platens: the
//!   description gives the whole specimen's `height` and the platens'
//!   travel, and the model is the upper half above the mid-plane, moved by
//!   half the travel), or `{ friction = .. }`: the base rests on a fixed rigid plane
//!   (unilateral contact) with Coulomb friction, a number or a parameter
//!   (`base_friction`; `"bonded"` is the bonded support).
//! * **Materials**: the first material (in [`Experiment::material_order`])
//!   is the setup's law; the others are [`BandMaterial`]s whose
//!   parameters follow (as R2's nodule's do). Layers are horizontal bands
//!   from the top down, each its own region `layer{i}` with mesh lines at
//!   the interfaces. Prony terms given as numbers are a fixed series; given
//!   as parameters they are read from the parameter vector
//!   ([`crate::model::Setup::prony_for`]).
//! * **Mesh** ([`Sizing`]): graded from the axis and from the top, fine
//!   under the tool over a zone sized from the tool and the design depth
//!   `d` (the deepest protocol segment, else a default below), at
//!   `mesh.level` (default 2; sizes scale as `1 / level`), 9-node Q2/P1
//!   elements unless `mesh.element = "quad4"`. Level-1 rules (`a` the
//!   expected contact radius; growth `1 + 0.2 / level` beyond the zone):
//!
//!   | tool | `a` | fine zone | fine size (level 1) | default `d` |
//!   |---|---|---|---|---|
//!   | needle (tip `rho`) | | `5 rho / 2.5` | `0.4 rho / 2.5` (N1's [`MeshDensity`]) | |
//!   | sphere `R` | `sqrt(R d)` (at most `R`) | `2 a` | `a / 5` | `R / 10` |
//!   | cone `alpha`, tip `rho` | `2 d tan(alpha) / pi + rho` | `2 a` | `a / 5` | `height / 10` |
//!   | flat punch `a`, edge `rho` | `a` | `1.5 a` | `a / 5` (growth `1 + 0.4 / level`), and about the rim `min(rho / 2, a / 40)` | `a / 10` |
//!   | platens | | the whole body | `min(radius, height) / 8`, uniform (`height` the modelled half's when mirrored) | `0.3 height` |
//!
//!   A zone larger than the body is the whole body. About a flat punch's
//!   rim the mesh has a window of half-width `a / 2` ([`crate::mesh::rim`]:
//!   nested rings of elements growing from the rim's size by `1 + 0.5`
//!   per ring, radially and in depth), so that the small elements stay
//!   near the rim instead of running along whole mesh lines.

use palpate_material::Law;

use crate::experiment::build::bulk_of;
use crate::experiment::params::material_law;
use crate::experiment::{
    CylinderKinematics, ElementSpec, Experiment, MaterialSpec, Specimen, SupportSpec, Tool, Value,
};
use crate::model::{FeModel, PlaneCell, Setup, Support};
use crate::n1::{prony_of, BandMaterial, EdgeBand, N1Needle, N1Setup, Sizing};
use crate::tool::ToolShape;
use crate::viscoelastic::Prony;
use crate::FeError;

/// The axisymmetric cylinder's setup (N1's, generalised).
pub type CylinderSetup = N1Setup;
/// The axisymmetric cylinder as a forward model.
pub type Cylinder = N1Needle;

/// The growth of the elements away from a flat punch's rim per unit
/// distance ([`EdgeBand::slope`]).
pub const EDGE_SLOPE: f64 = 0.5;

/// A flat punch's element size at level 1 outside its rim's window, per
/// unit punch radius: the contact's interior and the far field converge on
/// elements twice N1's relative size; the rim's singular pressure is
/// resolved by the window ([`crate::mesh::rim`]; docs/validation/fe.md,
/// "Sneddon's flat punch").
pub const PUNCH_SIZE: f64 = 0.2;

/// A flat punch's element growth beyond its fine zone ([`Sizing::growth`]:
/// `1 + 0.4 / level`).
pub const PUNCH_GROWTH: f64 = 0.4;

/// The default mesh level of a description without `mesh.level`.
pub const DEFAULT_LEVEL: f64 = 2.0;

fn bad(field: impl Into<String>, reason: impl Into<String>) -> FeError {
    FeError::InvalidConfig {
        field: field.into(),
        reason: reason.into(),
    }
}

/// A friction coefficient of the description: (value, is a parameter).
/// `"bonded"` is an infinite coefficient, `"frictionless"` zero.
fn friction_value(field: &str, v: &Value) -> Result<(f64, bool), FeError> {
    match v {
        Value::Fixed(mu) if *mu >= 0.0 && mu.is_finite() => Ok((*mu, false)),
        Value::Fixed(mu) => Err(bad(field, format!("{mu}: a friction coefficient is >= 0"))),
        Value::Param(p) => Ok((p.start, true)),
        Value::Keyword(k) if k == "bonded" => Ok((f64::INFINITY, false)),
        Value::Keyword(k) if k == "frictionless" => Ok((0.0, false)),
        Value::Keyword(k) => Err(bad(
            field,
            format!(
                "`{k}`: expected a number >= 0, {{ start = .. }}, \"frictionless\" or \"bonded\""
            ),
        )),
    }
}

fn positive(field: &str, v: f64) -> Result<f64, FeError> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(bad(field, format!("{v} mm: expected a finite length > 0")))
    }
}

/// A material's Prony series: (fixed series, number of terms taken from the
/// parameters).
fn prony_spec(name: &str, m: &MaterialSpec) -> Result<(Option<Prony>, usize), FeError> {
    if m.prony.is_empty() {
        return Ok((None, 0));
    }
    let any_param = m
        .prony
        .iter()
        .any(|t| matches!(t.g, Value::Param(_)) || matches!(t.tau, Value::Param(_)));
    if any_param {
        return Ok((None, m.prony.len()));
    }
    let mut flat = Vec::new();
    for (i, t) in m.prony.iter().enumerate() {
        for (what, v) in [("g", &t.g), ("tau", &t.tau)] {
            match v {
                Value::Fixed(x) => flat.push(*x),
                _ => {
                    return Err(bad(
                        format!("materials.{name}.prony[{i}].{what}"),
                        "expected a number or { start = .. }",
                    ))
                }
            }
        }
    }
    prony_of(&flat)
        .map(|p| (Some(p), 0))
        .map_err(|e| bad(format!("materials.{name}.prony"), e.to_string()))
}

/// The deepest depth the protocol's segments reach (mm), if it has any.
fn protocol_depth(e: &Experiment) -> Option<f64> {
    e.protocol
        .segments
        .iter()
        .flat_map(|s| [s.ramp_to, s.unload_to, s.press_to])
        .flatten()
        .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))))
}

impl N1Setup {
    /// The axisymmetric cylinder of an experiment description (specimen,
    /// materials, tool, supports, mesh) as this setup; the model's
    /// parameter space is [`Experiment::param_space`]. Errors name the
    /// field and say what would be valid.
    pub fn from_experiment(e: &Experiment) -> Result<N1Setup, FeError> {
        let c = match &e.specimen {
            Specimen::Cylinder(c) => c,
            _ => {
                return Err(bad(
                    "specimen.shape",
                    "the axisymmetric setup builds a cylinder (shape = \"cylinder\")",
                ))
            }
        };
        if c.kinematics != CylinderKinematics::Axisymmetric {
            return Err(bad(
                "specimen.kinematics",
                "a 3D cylinder is not an axisymmetric model; use kinematics = \"axisymmetric\"",
            ));
        }
        if !c.inclusions.is_empty() {
            return Err(bad(
                "specimen.inclusions",
                "inclusions are not supported on an axisymmetric cylinder yet; model them on a \
                 block (shape = \"block\") or a Gmsh mesh",
            ));
        }
        let radius = positive("specimen.radius", c.radius)?;
        // materials in parameter order; the first is the setup's law
        let order = e.material_order()?;
        let space = e.param_space()?;
        let index = |name: &str| order.iter().position(|m| m == name);
        let mut layers = Vec::new();
        for (i, l) in c.layers.iter().enumerate() {
            let t = positive(&format!("specimen.layers[{i}].thickness"), l.thickness)?;
            let k = index(&l.material).ok_or_else(|| {
                bad(
                    format!("specimen.layers[{i}].material"),
                    format!("`{}` is not declared", l.material),
                )
            })?;
            layers.push((t, k));
        }
        let height = match (c.height, layers.is_empty()) {
            (Some(h), true) => positive("specimen.height", h)?,
            (None, true) => {
                return Err(bad(
                    "specimen.height",
                    "give the cylinder's height (mm) or its layers",
                ))
            }
            (h, false) => {
                let sum: f64 = layers.iter().map(|l| l.0).sum();
                if let Some(h) = h {
                    if (h - sum).abs() > 1e-9 * sum {
                        return Err(bad(
                            "specimen.height",
                            format!("{h} mm, but the layers add up to {sum} mm; give one or make them agree"),
                        ));
                    }
                }
                sum
            }
        };
        let first = &order[0];
        let spec0 = &e.materials[first];
        let law: Law = material_law(first, spec0)?;
        let bulk = bulk_of(first, spec0)?;
        let (prony, prony_parameters) = prony_spec(first, spec0)?;
        let mut materials = Vec::new();
        for name in &order[1..] {
            let m = &e.materials[name];
            let b = bulk_of(name, m)?;
            if b.exact() != bulk.exact() {
                return Err(bad(
                    format!("materials.{name}.bulk"),
                    format!(
                        "{b:?}, but `{first}` is {bulk:?}: the materials of one body are all exactly incompressible or all given a bulk ratio"
                    ),
                ));
            }
            let (p, n) = prony_spec(name, m)?;
            materials.push(BandMaterial {
                name: name.clone(),
                law: material_law(name, m)?,
                bulk: b,
                prony: p,
                prony_parameters: n,
            });
        }
        if layers.is_empty() && !materials.is_empty() {
            return Err(bad(
                "specimen.layers",
                "several materials on a cylinder without layers",
            ));
        }
        // the tool
        let depth = protocol_depth(e);
        if let Some(d) = depth {
            if !(d < height) {
                return Err(bad(
                    "protocol.segments",
                    format!("a depth of {d} mm reaches the base of a {height} mm specimen"),
                ));
            }
        }
        let at_axis = |at: &Option<[f64; 2]>| -> Result<(), FeError> {
            match at {
                Some(p) if *p != [0.0, 0.0] => Err(bad(
                    "tool.at",
                    format!(
                        "{p:?}: on an axisymmetric cylinder the tool is on the axis; an off-axis tool needs kinematics = \"3d\""
                    ),
                )),
                _ => Ok(()),
            }
        };
        // two identical platens: the upper half above a mirror plane
        let mirror =
            matches!(c.support, SupportSpec::Symmetry) && matches!(e.tool, Tool::Platens(_));
        if mirror && !layers.is_empty() {
            return Err(bad(
                "specimen.support",
                "symmetry between platens mirrors the upper half of a uniform cylinder; a layered one needs its lower platen as its support (bonded, sliding or { friction = .. })",
            ));
        }
        let level = match e.mesh.level {
            None => DEFAULT_LEVEL,
            Some(0) => return Err(bad("mesh.level", "0: levels are 1, 2, 3, ...")),
            Some(l) => l as f64,
        };
        let (tool, friction, sizing, max_step) = match &e.tool {
            Tool::Needle(t) | Tool::Cone(t) => {
                at_axis(&t.at)?;
                let is_needle = matches!(e.tool, Tool::Needle(_));
                let alpha = match (t.half_angle, is_needle) {
                    (Some(a), _) => a,
                    (None, true) => 15.0,
                    (None, false) => {
                        return Err(bad(
                            "tool.half_angle",
                            "a cone needs its half-angle (degrees, between 0 and 90)",
                        ))
                    }
                };
                if !(alpha > 0.0 && alpha < 90.0) {
                    return Err(bad(
                        "tool.half_angle",
                        format!("{alpha} degrees: expected between 0 and 90"),
                    ));
                }
                let d = depth.unwrap_or(0.1 * height);
                let tip = match (t.tip_radius, is_needle) {
                    (Some(r), _) => positive("tool.tip_radius", r)?,
                    (None, true) => 2.5,
                    (None, false) => 1e-3 * d,
                };
                let tool = ToolShape::Needle {
                    tip_radius: tip,
                    half_angle_deg: alpha,
                };
                let (sizing, max_step) = if is_needle {
                    let scale = tip / 2.5;
                    (
                        Sizing {
                            h: 0.4 * scale,
                            fine_zone: 5.0 * scale,
                            growth: 0.2,
                            level,
                        },
                        0.25 * scale,
                    )
                } else {
                    let a = 2.0 * d * alpha.to_radians().tan() / std::f64::consts::PI + tip;
                    (contact_sizing(a, level), d / 5.0)
                };
                (tool, &t.friction, sizing, max_step)
            }
            Tool::Sphere(t) => {
                at_axis(&t.at)?;
                let r = positive("tool.radius", t.radius)?;
                if !(r < radius) {
                    return Err(bad(
                        "tool.radius",
                        format!("{r} mm: the sphere must be smaller than the specimen (radius {radius} mm)"),
                    ));
                }
                let d = depth.unwrap_or((0.1 * r).min(0.1 * height));
                let a = (r * d).sqrt().min(r);
                (
                    ToolShape::Sphere { radius: r },
                    &t.friction,
                    contact_sizing(a, level),
                    d / 5.0,
                )
            }
            Tool::FlatPunch(t) => {
                at_axis(&t.at)?;
                let a = positive("tool.radius", t.radius)?;
                if !(a < radius) {
                    return Err(bad(
                        "tool.radius",
                        format!("{a} mm: the punch must be narrower than the specimen (radius {radius} mm)"),
                    ));
                }
                let rho = match t.edge_radius {
                    Some(r) => positive("tool.edge_radius", r)?,
                    None => 0.1 * a,
                };
                if !(rho < a) {
                    return Err(bad(
                        "tool.edge_radius",
                        format!("{rho} mm: expected below the punch radius {a} mm"),
                    ));
                }
                let d = depth.unwrap_or(0.1 * a);
                (
                    ToolShape::FlatPunch {
                        radius: a,
                        edge_radius: rho,
                    },
                    &t.friction,
                    // coarse away from the rim, whose window
                    // (`edge_band`) takes the small elements
                    Sizing {
                        h: PUNCH_SIZE * a,
                        fine_zone: 1.5 * a,
                        growth: PUNCH_GROWTH,
                        level,
                    },
                    d / 5.0,
                )
            }
            Tool::Platens(t) => {
                // a mirrored specimen: the upper half, half the travel
                let k = if mirror { 0.5 } else { 1.0 };
                let (h, d) = (k * height, k * depth.unwrap_or(0.3 * height));
                (
                    ToolShape::Platen,
                    &t.friction,
                    Sizing {
                        h: radius.min(h) / 8.0,
                        fine_zone: radius.max(h),
                        growth: 0.0,
                        level,
                    },
                    d / 10.0,
                )
            }
            Tool::Wheel(_) => {
                return Err(bad(
                    "tool.shape",
                    "a wheel rolls over a plane block (specimen shape = \"block\"), not an axisymmetric cylinder; here: sphere, cone, needle, flat_punch or platens",
                ))
            }
        };
        tool.check().map_err(|r| bad("tool", r))?;
        let (friction, friction_is_parameter) = friction_value("tool.friction", friction)?;
        let (base, base_friction, base_friction_is_parameter) = match &c.support {
            SupportSpec::Bonded => (Support::Bonded, None, false),
            SupportSpec::Sliding | SupportSpec::Symmetry => (Support::Sliding, None, false),
            SupportSpec::Friction(v) => match friction_value("specimen.support.friction", v)? {
                (mu, false) if mu.is_infinite() => (Support::Bonded, None, false),
                (mu, p) => (Support::Sliding, Some(mu), p),
            },
        };
        let element = match e.mesh.element {
            None | Some(ElementSpec::Quad9) => PlaneCell::Quad9,
            Some(ElementSpec::Quad4) => PlaneCell::Quad4,
            Some(other) => {
                return Err(bad(
                    "mesh.element",
                    format!("{other:?} is a 3D element; an axisymmetric cylinder takes quad9 (default) or quad4"),
                ))
            }
        };
        let mut m = N1Needle::new(law).setup().clone();
        m.bulk = bulk;
        m.friction = friction;
        m.friction_is_parameter = friction_is_parameter;
        m.tool = tool;
        m.base = base;
        m.base_friction = base_friction;
        m.base_friction_is_parameter = base_friction_is_parameter;
        m.radius = radius;
        m.height = if mirror { 0.5 * height } else { height };
        m.mirror = mirror;
        m.fine_zone = sizing.fine_zone;
        m.sizing = Some(sizing);
        m.element = element;
        // the punch's rim: a window about it graded to half its rounding
        // (at most a fortieth of the punch's radius) at level 1
        if let ToolShape::FlatPunch {
            radius: a,
            edge_radius: rho,
        } = tool
        {
            m.edge_band = Some(EdgeBand {
                r: a,
                h: (0.5 * rho).min(0.025 * a),
                slope: EDGE_SLOPE,
            });
        }
        m.prony = prony;
        m.prony_parameters = prony_parameters;
        m.layers = layers;
        m.materials = materials;
        m.first_material = first.clone();
        m.options.max_step = max_step;
        m.options.first_step = max_step / 5.0;
        // (N1's 2e-3 mm for its 0.25 mm steps; used by an inner
        // augmentation loop only)
        m.penetration_tol = 2e-3 * max_step / 0.25;
        // one layer of the law's material is the plain cylinder
        if m.layers.len() == 1 {
            m.layers.clear();
        }
        let derived = m.param_space();
        if derived.names() != space.names() {
            return Err(bad(
                "parameters",
                format!(
                    "the model reads {:?} but the description names {:?}",
                    derived.names(),
                    space.names()
                ),
            ));
        }
        m.space = Some(space);
        Ok(m)
    }
}

/// The level-1 sizing around a contact of radius `a` (mm).
fn contact_sizing(a: f64, level: f64) -> Sizing {
    Sizing {
        h: a / 5.0,
        fine_zone: 2.0 * a,
        growth: 0.2,
        level,
    }
}

impl Cylinder {
    /// The model of an axisymmetric cylinder description
    /// ([`N1Setup::from_experiment`]).
    pub fn from_experiment(e: &Experiment) -> Result<Cylinder, FeError> {
        Ok(FeModel::from_setup(N1Setup::from_experiment(e)?))
    }

    /// For a cylinder between platens meshed by its description's rule:
    /// the levels of that rule whose forces estimate a run's
    /// discretisation error, and which is the run
    /// ([`crate::accuracy::levels_about`], [`crate::accuracy::from_levels`]).
    /// Between platens the needle's order of convergence does not hold: the
    /// side rolling onto the platen's edge makes the force converge
    /// unevenly (at friction 0.28, level 1 is 8.4 % below level 2 at 60 %
    /// compression, docs/notes/2026-11-29-platen-friction-level1.md), so
    /// the estimate is made from the tool's own levels. `None` for other
    /// tools and for a mesh given as a grading.
    pub fn own_levels(&self) -> Option<([f64; 3], usize)> {
        match (self.tool, self.sizing, self.grading) {
            (ToolShape::Platen, Some(s), None) => Some(crate::accuracy::levels_about(s.level)),
            _ => None,
        }
    }
}
