//! Physical plausibility of values a user types, checked before any work so
//! that an absurd value is refused by its option and value, with the valid
//! range, instead of failing deep in a solver ("element 18446744073709551615:
//! non-finite stress", "element 646 inverted").
//!
//! * A law parameter in MPa lies within `±MAX_MODULUS_MPA` (1 TPa: stiffer
//!   than diamond, whose Young's modulus is about 1.05 TPa), and the law's
//!   moduli are not all below `MIN_MODULUS_MPA` (1 Pa; the softest tissues,
//!   brain and fat, are near 1 kPa = 1e-3 MPa).
//! * A tool displacement stays inside the body: below the height of the C1
//!   specimen (the platens would meet), of the N1 and Q1 cylinders and of the
//!   N3 block (the tool would reach the fixed base).
//! * A sphere or punch is not wider than the body under it.
//! * A viscoelastic history takes at most `MAX_INCREMENTS` time increments.
//! * Parameters held fixed in a fit are parameters of the law, inside their
//!   bounds and of a plausible size, and leave something to fit.

use crate::model::Model;
use crate::run::limits::fmt_value;
use palpate_material::Law;

/// Largest magnitude of a law parameter in MPa (1 TPa).
pub const MAX_MODULUS_MPA: f64 = 1e6;
/// Smallest largest modulus of a law in MPa (1 Pa).
pub const MIN_MODULUS_MPA: f64 = 1e-6;

/// Checks a law's parameter values (in the law's order). `option` names
/// where a parameter was given from its name and value as typed, e.g.
/// `|n, v| format!("--param {n}={v}")`.
pub fn check_law_values(
    law: &Law,
    values: &[f64],
    option: impl Fn(&str, &str) -> String,
) -> anyhow::Result<()> {
    let specs = law.params();
    let mut largest: f64 = 0.0;
    for (spec, &v) in specs.iter().zip(values) {
        if !v.is_finite() {
            anyhow::bail!(
                "{}: not a finite number; give a value in {}",
                option(&spec.name, &fmt_value(v)),
                spec.unit
            );
        }
        if v < spec.lower || v > spec.upper {
            anyhow::bail!(
                "{}: outside the range of {} in {law}, [{}, {}] {}",
                option(&spec.name, &fmt_value(v)),
                spec.name,
                fmt_value(spec.lower),
                fmt_value(spec.upper),
                spec.unit
            );
        }
        if spec.unit == "MPa" {
            if v.abs() > MAX_MODULUS_MPA {
                anyhow::bail!(
                    "{}: {v:e} MPa is beyond any solid (diamond: about 1e6 MPa; soft tissue: 1e-4 to 1 MPa); \
                     a parameter in MPa must lie within ±{MAX_MODULUS_MPA:e} (is the unit Pa instead of MPa?)",
                    option(&spec.name, &fmt_value(v))
                );
            }
            largest = largest.max(v.abs());
        }
    }
    let moduli: Vec<(&str, f64)> = specs
        .iter()
        .zip(values)
        .filter(|(s, _)| s.unit == "MPa")
        .map(|(s, v)| (s.name.as_str(), *v))
        .collect();
    if !moduli.is_empty() && largest < MIN_MODULUS_MPA {
        let given: Vec<String> = moduli
            .iter()
            .map(|(n, v)| option(n, &fmt_value(*v)))
            .collect();
        anyhow::bail!(
            "{}: every modulus of {law} is below {MIN_MODULUS_MPA:e} MPa (1 Pa); nothing solid is that soft \
             (soft tissue: 1e-4 to 1 MPa; is the unit GPa instead of MPa?)",
            given.join(" ")
        );
    }
    Ok(())
}

/// Checks parameters held fixed in a fit (`(name, value)`, as given by
/// `option`, e.g. `--fix`): each is a parameter of the law, strictly inside
/// its bounds (the fit starts there), of a plausible size, and at least one
/// parameter is left to fit.
pub fn check_fixed(law: &Law, fixed: &[(String, f64)], option: &str) -> anyhow::Result<()> {
    let specs = law.params();
    for (name, v) in fixed {
        let shown = format!("{option} {name}={}", fmt_value(*v));
        let Some(spec) = specs.iter().find(|s| &s.name == name) else {
            let names: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
            anyhow::bail!(
                "{shown}: {law} has no parameter `{name}` (its parameters: {})",
                names.join(", ")
            );
        };
        if !(v.is_finite() && *v > spec.lower && *v < spec.upper) {
            anyhow::bail!(
                "{shown}: {name} must lie strictly inside ({}, {}) {}",
                fmt_value(spec.lower),
                fmt_value(spec.upper),
                spec.unit
            );
        }
        if spec.unit == "MPa" && v.abs() > MAX_MODULUS_MPA {
            anyhow::bail!(
                "{shown}: {} MPa is beyond any solid (diamond: about 1e6 MPa); a parameter in MPa must lie within ±{MAX_MODULUS_MPA:e} (is the unit Pa instead of MPa?)",
                fmt_value(*v)
            );
        }
    }
    if !specs.is_empty()
        && specs
            .iter()
            .all(|s| fixed.iter().any(|(n, _)| n == &s.name))
    {
        let all: Vec<String> = fixed
            .iter()
            .map(|(n, v)| format!("{option} {n}={}", fmt_value(*v)))
            .collect();
        anyhow::bail!(
            "{}: every parameter of {law} is fixed; nothing is left to fit (leave at least one free)",
            all.join(" ")
        );
    }
    // A fit must be able to start inside the law's domain with these values.
    crate::model::calibration::admissible_start(law, fixed).map_err(|e| {
        let all: Vec<String> = fixed
            .iter()
            .map(|(n, v)| format!("{option} {n}={}", fmt_value(*v)))
            .collect();
        anyhow::anyhow!("{}: {e}", all.join(" "))
    })?;
    Ok(())
}

/// Most time increments a viscoelastic run may take (each is a Newton solve).
pub const MAX_INCREMENTS: f64 = 1e5;

/// Checks a viscoelastic history before it is stepped: increments of at
/// most a tenth of the shortest relaxation time over `duration` seconds
/// (the ramp and the hold) must stay within [`MAX_INCREMENTS`].
pub fn check_increments(model: &Model, duration: f64) -> anyhow::Result<()> {
    let prony = match model {
        Model::C1Fe(m) => m.prony.as_ref(),
        Model::Q1(m) => m.prony.as_ref(),
        _ => None,
    };
    let Some(prony) = prony else {
        return Ok(());
    };
    let tau = prony.shortest_time();
    let steps = duration / (0.1 * tau);
    if steps.is_nan() || steps > MAX_INCREMENTS {
        anyhow::bail!(
            "--prony with --ramp/--hold: the shortest relaxation time {} s is stepped at most {} s at a time, so {} s of history take {:.3e} increments; at most {MAX_INCREMENTS:e} (give a longer relaxation time or a shorter --ramp/--hold)",
            fmt_value(tau),
            fmt_value(0.1 * tau),
            fmt_value(duration),
            steps.ceil()
        );
    }
    Ok(())
}

/// Checks the size of a rigid tool against the body under it: a sphere or
/// punch wider than the body (whose radius, or half-width for N3, it would
/// overhang) is refused; `option` names where the tool was given.
pub fn check_tool(option: &str, model: &Model) -> anyhow::Result<()> {
    use palpate_fe::tool::ToolShape;
    let (tool, body, what) = match model {
        Model::N1Needle(m) => (m.tool, m.radius, "the N1 cylinder's radius"),
        Model::N3Needle(m) => (
            m.tool,
            m.size[0].min(m.size[1]),
            "the N3 block's half-width",
        ),
        _ => return Ok(()),
    };
    let radius = match tool {
        ToolShape::Sphere { radius } | ToolShape::FlatPunch { radius, .. } => radius,
        _ => return Ok(()),
    };
    if radius > body {
        anyhow::bail!(
            "{option}: a tool of radius {} mm overhangs the body ({what} is {body} mm); give a radius up to {body} mm, or `platen` for a plate wider than the body",
            fmt_value(radius)
        );
    }
    Ok(())
}

/// A body dimension along the tool's travel: (height in mm, what it is).
pub fn travel_limit(model: &Model) -> Option<(f64, &'static str)> {
    match model {
        Model::Homogeneous(_)
        | Model::GeneralBiaxial(_)
        | Model::SimpleShear(_)
        | Model::ViscousUniaxial(_) => None,
        Model::Qlv(inner, _) => travel_limit(inner),
        // the rolling depth is checked against the wheel and the block by
        // palpate_fe::r2::check_model; the travel is along the surface
        Model::R2(_) => None,
        // the description checks its protocol against its specimen
        Model::Experiment(_) => None,
        Model::C1(m) => Some((
            m.geometry.height_mm,
            "the C1 specimen is that high: the platens would meet",
        )),
        Model::C1Fe(m) => Some((
            m.height,
            "the C1 specimen is that high: the platens would meet",
        )),
        Model::N1Needle(m) => Some((
            m.height,
            "the N1 cylinder is that high: the tool would reach its base",
        )),
        Model::Q1(m) => Some((
            m.height,
            "the Q1 cylinder is that high: the punch would reach its base",
        )),
        Model::N3Needle(m) => Some((
            m.size[2],
            "the N3 block is that high: the needle would reach its base",
        )),
    }
}

/// Checks a tool displacement (mm) against the body: `option` names it.
pub fn check_travel(option: &str, depth: f64, model: &Model) -> anyhow::Result<()> {
    if let Some((h, what)) = travel_limit(model) {
        if depth >= h {
            anyhow::bail!(
                "{option} {}: the tool cannot travel that far into a body {h} mm high ({what}); \
                 give a displacement below {h} mm",
                fmt_value(depth)
            );
        }
    }
    Ok(())
}

/// Checks a significance level (`what` names the option or field): a
/// probability strictly between 0 and 1.
pub fn check_alpha(what: &str, alpha: f64) -> anyhow::Result<()> {
    anyhow::ensure!(
        alpha > 0.0 && alpha < 1.0,
        "{what} {alpha}: expected a significance level strictly between 0 and 1, such as 0.05"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opt(n: &str, v: &str) -> String {
        format!("--param {n}={v}")
    }

    #[test]
    fn absurd_moduli_are_named_with_the_valid_range() {
        let nh: Law = "neo-hookean".parse().unwrap();
        check_law_values(&nh, &[1.1e-3], opt).unwrap();
        let e = check_law_values(&nh, &[1e300], opt)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--param C10=1e300") && e.contains("1e6"),
            "{e}"
        );
        let e = check_law_values(&nh, &[1e-300], opt)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--param C10=1e-300") && e.contains("1e-6"),
            "{e}"
        );
        let e = check_law_values(&nh, &[f64::NAN], opt)
            .unwrap_err()
            .to_string();
        assert!(e.contains("finite"), "{e}");
        // Mooney-Rivlin with C01 = 0 is fine: the largest modulus counts.
        let mr: Law = "mooney-rivlin".parse().unwrap();
        check_law_values(&mr, &[1e-3, 0.0], opt).unwrap();
    }

    #[test]
    fn fixed_parameters_are_checked_by_name_bounds_and_size() {
        let mr: Law = "mooney-rivlin".parse().unwrap();
        check_fixed(&mr, &[("C01".into(), 0.0)], "--fix").unwrap();
        for (fixed, needle) in [
            (vec![("C11".to_string(), 0.0)], "no parameter `C11`"),
            (vec![("C01".to_string(), 1e300)], "--fix C01=1e300"),
            (
                vec![("C10".to_string(), 1e-3), ("C01".to_string(), 0.0)],
                "nothing is left to fit",
            ),
        ] {
            let e = check_fixed(&mr, &fixed, "--fix").unwrap_err().to_string();
            assert!(e.starts_with("--fix ") && e.contains(needle), "{e}");
        }
        let nh: Law = "neo-hookean".parse().unwrap();
        let e = check_fixed(&nh, &[("C10".into(), -1.0)], "--fix")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--fix C10=-1") && e.contains("strictly inside (0, inf)"),
            "{e}"
        );
    }

    #[test]
    fn a_displacement_through_the_body_is_refused() {
        let spec = crate::model::ModelSpec::C1Fe(crate::model::C1FeSpec {
            law: "neo-hookean".into(),
            ..Default::default()
        });
        let model = spec.validate().unwrap();
        check_travel("--depth", 8.0, &model).unwrap();
        let e = check_travel("--depth", 20.0, &model)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--depth 20") && e.contains("below 9 mm"),
            "{e}"
        );
    }
}
