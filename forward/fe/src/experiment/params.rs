//! The parameter vector of an experiment: its names, order, bounds and
//! starts, and which are fitted. Every model built from an [`Experiment`]
//! has this list as its parameter space, so a fit, a posterior or a report
//! reads the same names whatever the specimen.
//!
//! Order and names:
//!
//! 1. each material in the order the specimen first uses it (the specimen's
//!    `material`, its layers from the top down, then its inclusions): the
//!    law's parameters (`C10`, `C01`, `mu1`, `alpha1`, ...), then its Prony
//!    terms (`g1`, `tau1_s`, `g2`, ...) when at least one of them is given
//!    as a parameter (`{ start = .. }`). With one material the names are
//!    the law's; with several, each is prefixed by the material's name
//!    (`skin_C10`, `fat_C10`, `nodule_g1`).
//! 2. `friction`, the tool's Coulomb coefficient, when it is a parameter;
//! 3. `base_friction`, the support's, when it is a parameter.
//!
//! A law parameter is always in the space; it is fitted unless the
//! description gives it as a number or with `fit = false` (then the
//! estimators hold it: [`Experiment::fixed_parameters`]); one not named
//! starts at the law's default and is fitted. A friction coefficient or a
//! Prony series given as numbers is part of the model, not a parameter
//! (as `friction = 0.8` is part of N1).

use palpate_core::{ParamRole, ParamSpace, ParamSpec};
use palpate_enrich::prony_params;
use palpate_material::Law;

use super::{Experiment, MaterialSpec, Specimen, SupportSpec, Tool, Value};
use crate::model::friction_param;
use crate::FeError;

/// One parameter of an experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Name, unit, bounds and role; `spec.initial` is the start (or the
    /// fixed value).
    pub spec: ParamSpec,
    /// Estimated (true) or held at `spec.initial` (false).
    pub fit: bool,
    /// Estimated but not a result of interest.
    pub nuisance: bool,
    /// The material it belongs to (`None`: a friction coefficient).
    pub material: Option<String>,
}

fn bad(field: impl Into<String>, reason: impl Into<String>) -> FeError {
    FeError::InvalidConfig {
        field: field.into(),
        reason: reason.into(),
    }
}

impl Experiment {
    /// The materials in the order the specimen first uses them (see the
    /// module's doc); an error names a material that is used but not
    /// declared, or declared but not used.
    pub fn material_order(&self) -> Result<Vec<String>, FeError> {
        let mut used: Vec<(String, String)> = Vec::new(); // (name, field)
        let single =
            || -> Result<String, FeError> {
                match self.materials.len() {
                    1 => Ok(self.materials.keys().next().expect("one").clone()),
                    0 => Err(bad("materials", "no material is declared")),
                    _ => {
                        Err(bad(
                            "specimen.material",
                            format!(
                        "several materials are declared ({}): say which one the specimen is",
                        self.materials.keys().cloned().collect::<Vec<_>>().join(", ")
                    ),
                        ))
                    }
                }
            };
        match &self.specimen {
            Specimen::Cylinder(c) => {
                if c.layers.is_empty() {
                    let m = match &c.material {
                        Some(m) => m.clone(),
                        None => single()?,
                    };
                    used.push((m, "specimen.material".into()));
                } else {
                    if c.material.is_some() {
                        return Err(bad(
                            "specimen.material",
                            "a layered cylinder takes its materials from `layers`",
                        ));
                    }
                    for (i, l) in c.layers.iter().enumerate() {
                        used.push((l.material.clone(), format!("specimen.layers[{i}].material")));
                    }
                }
                for (i, inc) in c.inclusions.iter().enumerate() {
                    used.push((
                        inc.material.clone(),
                        format!("specimen.inclusions[{i}].material"),
                    ));
                }
            }
            Specimen::Block(b) => {
                let m = match &b.material {
                    Some(m) => m.clone(),
                    None => single()?,
                };
                used.push((m, "specimen.material".into()));
                for (i, inc) in b.inclusions.iter().enumerate() {
                    used.push((
                        inc.material.clone(),
                        format!("specimen.inclusions[{i}].material"),
                    ));
                }
            }
            Specimen::Mesh(m) => {
                if m.regions.is_empty() {
                    for name in self.materials.keys() {
                        used.push((name.clone(), format!("materials.{name}")));
                    }
                } else {
                    for (group, mat) in &m.regions {
                        used.push((mat.clone(), format!("specimen.regions.{group}")));
                    }
                }
            }
        }
        let mut order: Vec<String> = Vec::new();
        for (name, field) in used {
            if !self.materials.contains_key(&name) {
                return Err(bad(
                    field,
                    format!(
                        "material `{name}` is not declared; declared: {}",
                        declared(self)
                    ),
                ));
            }
            if !order.contains(&name) {
                order.push(name);
            }
        }
        for name in self.materials.keys() {
            if !order.contains(name) {
                return Err(bad(
                    format!("materials.{name}"),
                    "declared but not used by the specimen",
                ));
            }
        }
        Ok(order)
    }

    /// Every parameter of the experiment, in the model's order (see the
    /// module's doc). An error names the field of an unknown law, an
    /// unknown or badly bounded parameter, or a start outside its bounds.
    pub fn parameters(&self) -> Result<Vec<Parameter>, FeError> {
        let order = self.material_order()?;
        let prefixed = order.len() > 1;
        let mut out = Vec::new();
        for name in &order {
            let m = &self.materials[name];
            for (spec, fit, nuisance) in material_parameters(name, m)? {
                let spec = if prefixed {
                    ParamSpec {
                        name: format!("{name}_{}", spec.name),
                        ..spec
                    }
                } else {
                    spec
                };
                out.push(Parameter {
                    spec,
                    fit,
                    nuisance,
                    material: Some(name.clone()),
                });
            }
        }
        if let Some(f) = tool_friction(&self.tool) {
            if let Some(p) = friction_parameter("friction", "tool.friction", f)? {
                out.push(p);
            }
        }
        if let Some(SupportSpec::Friction(f)) = self.support() {
            if let Some(p) = friction_parameter("base_friction", "specimen.support.friction", f)? {
                out.push(p);
            }
        }
        let mut seen = std::collections::HashSet::new();
        for p in &out {
            if !seen.insert(p.spec.name.clone()) {
                return Err(bad(
                    p.spec.name.clone(),
                    "this parameter name occurs twice; rename one of the materials",
                ));
            }
        }
        Ok(out)
    }

    /// The parameter space of every model built from this experiment.
    pub fn param_space(&self) -> Result<ParamSpace, FeError> {
        Ok(ParamSpace::new(
            self.parameters()?.into_iter().map(|p| p.spec).collect(),
        ))
    }

    /// The parameters held fixed, by name, with their values.
    pub fn fixed_parameters(&self) -> Result<Vec<(String, f64)>, FeError> {
        Ok(self
            .parameters()?
            .into_iter()
            .filter(|p| !p.fit)
            .map(|p| (p.spec.name, p.spec.initial))
            .collect())
    }

    /// The specimen's support (`None` for a Gmsh specimen's group support,
    /// which is the same type under `specimen.support.kind`).
    pub fn support(&self) -> Option<&SupportSpec> {
        match &self.specimen {
            Specimen::Cylinder(c) => Some(&c.support),
            Specimen::Block(b) => Some(&b.support),
            Specimen::Mesh(m) => Some(&m.support.kind),
        }
    }
}

fn declared(e: &Experiment) -> String {
    if e.materials.is_empty() {
        "none".into()
    } else {
        e.materials.keys().cloned().collect::<Vec<_>>().join(", ")
    }
}

/// The tool's friction value (`None`: the tool has none to give).
pub fn tool_friction(tool: &Tool) -> Option<&Value> {
    Some(match tool {
        Tool::Sphere(t) => &t.friction,
        Tool::Cone(t) | Tool::Needle(t) => &t.friction,
        Tool::FlatPunch(t) => &t.friction,
        Tool::Platens(t) => &t.friction,
        Tool::Wheel(t) => &t.friction,
    })
}

/// The law of a material; an error names `materials.NAME.law`.
pub fn material_law(name: &str, m: &MaterialSpec) -> Result<Law, FeError> {
    m.law.parse::<Law>().map_err(|e| {
        bad(
            format!("materials.{name}.law"),
            format!(
                "{e}; valid: neo-hookean, mooney-rivlin, yeoh, reduced-polynomial:N, arruda-boyce, ogden:N, gent, veronda-westmann, humphrey"
            ),
        )
    })
}

/// (spec, fit, nuisance) of a material's law parameters then Prony terms.
fn material_parameters(
    name: &str,
    m: &MaterialSpec,
) -> Result<Vec<(ParamSpec, bool, bool)>, FeError> {
    let law = material_law(name, m)?;
    let mut specs: Vec<ParamSpec> = law
        .params()
        .into_iter()
        .map(|p| {
            ParamSpec::new(p.name, p.unit, p.lower, p.upper, p.initial).with_role(if p.modulus {
                ParamRole::Modulus
            } else {
                ParamRole::Shape
            })
        })
        .collect();
    let law_names: Vec<String> = specs.iter().map(|s| s.name.clone()).collect();
    for key in m.params.keys() {
        if !law_names.contains(key) {
            return Err(bad(
                format!("materials.{name}.{key}"),
                format!(
                    "not a parameter of {law}; its parameters are {} (and `law`, `bulk`, `prony`)",
                    law_names.join(", ")
                ),
            ));
        }
    }
    let mut values: Vec<(String, Option<&Value>)> = law_names
        .iter()
        .map(|n| (format!("materials.{name}.{n}"), m.params.get(n)))
        .collect();
    if m.prony
        .iter()
        .any(|t| matches!(t.g, Value::Param(_)) || matches!(t.tau, Value::Param(_)))
    {
        specs.extend(prony_params(m.prony.len()));
        for (i, t) in m.prony.iter().enumerate() {
            values.push((format!("materials.{name}.prony[{i}].g"), Some(&t.g)));
            values.push((format!("materials.{name}.prony[{i}].tau"), Some(&t.tau)));
        }
    }
    specs
        .into_iter()
        .zip(values)
        .map(|(spec, (field, value))| apply_value(spec, &field, value))
        .collect()
}

/// A spec with the description's value applied: (spec, fit, nuisance).
fn apply_value(
    mut spec: ParamSpec,
    field: &str,
    value: Option<&Value>,
) -> Result<(ParamSpec, bool, bool), FeError> {
    let (fit, nuisance) = match value {
        None => (true, false),
        Some(Value::Fixed(v)) => {
            spec.initial = *v;
            (false, false)
        }
        Some(Value::Param(p)) => {
            spec.initial = p.start;
            if let Some(l) = p.lower {
                spec.lower = l;
            }
            if let Some(u) = p.upper {
                spec.upper = u;
            }
            (p.fit, p.nuisance)
        }
        Some(Value::Keyword(k)) => {
            return Err(bad(
                field,
                format!("`{k}`: expected a number or {{ start = .. }}"),
            ))
        }
    };
    if !spec.initial.is_finite() {
        return Err(bad(field, format!("{} is not finite", spec.initial)));
    }
    if !(spec.lower < spec.upper) {
        return Err(bad(
            field,
            format!("lower {} must be below upper {}", spec.lower, spec.upper),
        ));
    }
    if !(spec.initial >= spec.lower && spec.initial <= spec.upper) {
        return Err(bad(
            field,
            format!(
                "{} is outside the bounds [{}, {}]",
                spec.initial, spec.lower, spec.upper
            ),
        ));
    }
    Ok((spec, fit, nuisance))
}

/// A friction coefficient as a parameter, or `None` when it is a number
/// (part of the model) or bonded.
fn friction_parameter(
    name: &str,
    field: &str,
    value: &Value,
) -> Result<Option<Parameter>, FeError> {
    if let Value::Keyword(k) = value {
        return match k.as_str() {
            "bonded" => Ok(None),
            "frictionless" => friction_parameter(name, field, &Value::Fixed(0.0)),
            _ => Err(bad(
                field,
                format!("`{k}`: expected a number >= 0, {{ start = .. }}, \"frictionless\" or \"bonded\""),
            )),
        };
    }
    if let Value::Fixed(v) = value {
        if !(*v >= 0.0 && v.is_finite()) {
            return Err(bad(field, format!("{v}: a friction coefficient is >= 0")));
        }
        return Ok(None);
    }
    let base = ParamSpec {
        name: name.into(),
        ..friction_param(0.0)
    };
    let (spec, fit, nuisance) = apply_value(base, field, Some(value))?;
    Ok(Some(Parameter {
        spec,
        fit,
        nuisance,
        material: None,
    }))
}
