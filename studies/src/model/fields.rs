//! The parsers of a model spec's text fields (`mesh`, `element`, `bulk`,
//! `tool`, `mode`, `prony`), each error naming the spec's kind and field
//! ([`ModelError`]). Split from [`crate::model`], which uses them and
//! re-exports the public ones.

use crate::model::{ModelError, DEFAULT_MESH, MAX_MESH_LEVEL};
use palpate_analytic::Mode;
use palpate_fe::{Bulk, MeshDensity, PlaneCell, Prony, ToolShape};
use serde::Deserialize;

/// A `prony = "g1=..,tau1=.."` field; errors name it.
pub(crate) fn parse_prony(
    kind: &'static str,
    text: Option<&str>,
) -> Result<Option<Prony>, ModelError> {
    text.map(|p| {
        p.parse::<Prony>()
            .map_err(|e| ModelError::new(kind, "prony", p, e.to_string()))
    })
    .transpose()
}

pub(crate) fn parse_mode(s: &str) -> Result<Mode, ModelError> {
    s.parse::<Mode>().map_err(|_| {
        ModelError::new(
            "homogeneous",
            "mode",
            s,
            "expected uniaxial, biaxial (equibiaxial), planar (pure_shear), general_biaxial or simple_shear",
        )
    })
}

/// The mesh level of `coarse` (1), `medium` (2), `fine` (3) or `N` (1..=12);
/// absent: [`DEFAULT_MESH`]. The one mesh parser of every command.
pub fn parse_mesh(kind: &'static str, s: Option<&str>) -> Result<usize, ModelError> {
    let s = s.unwrap_or(DEFAULT_MESH);
    match s {
        "coarse" => Ok(MeshDensity::COARSE.level),
        "medium" => Ok(MeshDensity::MEDIUM.level),
        "fine" => Ok(MeshDensity::FINE.level),
        n => match n.parse::<usize>() {
            Ok(k) if (1..=MAX_MESH_LEVEL).contains(&k) => Ok(k),
            _ => Err(ModelError::new(
                kind,
                "mesh",
                s,
                format!("expected coarse, medium, fine or a level 1..{MAX_MESH_LEVEL}"),
            )),
        },
    }
}

pub(crate) fn parse_element(kind: &'static str, s: Option<&str>) -> Result<PlaneCell, ModelError> {
    match s.unwrap_or("quad4") {
        "quad4" => Ok(PlaneCell::Quad4),
        "quad9" => Ok(PlaneCell::Quad9),
        other => Err(ModelError::new(
            kind,
            "element",
            other,
            "expected quad4 or quad9",
        )),
    }
}

pub(crate) fn parse_bulk(kind: &'static str, s: Option<&str>) -> Result<Bulk, ModelError> {
    let s = s.unwrap_or("exact");
    if s == "exact" {
        return Ok(Bulk::Exact);
    }
    match s.parse::<f64>() {
        // Above 1e9 (Poisson's ratio 0.4999999995) the penalty swamps the
        // shear stiffness and the stresses overflow: use `exact`.
        Ok(r) if r > 0.0 && r <= 1e9 => Ok(Bulk::Ratio(r)),
        _ => Err(ModelError::new(
            kind,
            "bulk",
            s,
            "expected `exact` or a ratio K/mu in (0, 1e9] such as 1000",
        )),
    }
}

pub(crate) fn parse_tool(kind: &'static str, s: &str) -> Result<ToolShape, ModelError> {
    let num = |v: &str| -> Result<f64, ModelError> {
        v.parse::<f64>()
            .ok()
            .filter(|r| *r > 0.0 && r.is_finite())
            .ok_or_else(|| {
                ModelError::new(
                    kind,
                    "tool",
                    s,
                    format!("`{v}` is not a positive radius in mm"),
                )
            })
    };
    match s.split_once(':') {
        None if s == "needle" => Ok(ToolShape::n1_needle()),
        None if s == "platen" => Ok(ToolShape::Platen),
        Some(("sphere", r)) => Ok(ToolShape::Sphere { radius: num(r)? }),
        Some(("punch", r)) => {
            let radius = num(r)?;
            Ok(ToolShape::FlatPunch {
                radius,
                edge_radius: (0.1f64).min(0.5 * radius),
            })
        }
        _ => Err(ModelError::new(
            kind,
            "tool",
            s,
            "expected needle, sphere:RADIUS, punch:RADIUS or platen",
        )),
    }
}

/// A TOML setting given as text or as a number (`mesh = 2`, `bulk = 1000`).
pub fn text_or_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum V {
        Int(i64),
        Float(f64),
        Text(String),
    }
    Ok(Some(match V::deserialize(d)? {
        V::Int(i) => i.to_string(),
        V::Float(x) => x.to_string(),
        V::Text(s) => s,
    }))
}
