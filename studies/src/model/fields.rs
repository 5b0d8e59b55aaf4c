//! The typed settings of a model spec (`mesh`, `bulk`, `base`, `tool`,
//! `element`, `platens`, `prony`, `viscoelastic`): each parsed once, from a
//! manifest by serde or from a command-line option by [`parse_setting`],
//! and each error naming the field, the value given and what is valid.
//! Split from [`crate::model`], which uses them and re-exports the public ones.

use crate::model::{ModelError, Viscous, DEFAULT_MESH, MAX_MESH_LEVEL};
use palpate_analytic::Mode;
use palpate_fe::{
    Bulk, MeshDensity, N3Element, Nodule, PlaneCell, Platens, Prony, Support, ToolShape,
};
use serde::Deserialize;
use std::fmt;

/// A setting of a model spec written as text (or a number) in a manifest
/// and on the command line: its field name and its parser, whose error
/// says what is valid.
pub trait Setting: Sized {
    /// The field, as spelled in manifests.
    const FIELD: &'static str;
    /// The setting `text` names; the error says what is valid.
    fn from_text(text: &str) -> Result<Self, String>;
}

/// A setting given as text on the command line (`--mesh fine`), for a spec
/// of `kind`; the error names the field and the value ([`ModelError::as_option`]).
pub fn parse_setting<T: Setting>(
    kind: &'static str,
    text: Option<&str>,
) -> Result<Option<T>, ModelError> {
    text.map(|t| T::from_text(t).map_err(|e| ModelError::new(kind, T::FIELD, t, e)))
        .transpose()
}

/// The serde reader of an optional setting of a spec (`#[serde(default,
/// deserialize_with = "...")]`): text or a number (`mesh = 2`, `bulk =
/// 1000`), parsed by [`Setting::from_text`]; the error reads
/// `FIELD = "VALUE": what is valid`, and the TOML reader adds the line.
pub fn setting<'de, D: serde::Deserializer<'de>, T: Setting>(d: D) -> Result<Option<T>, D::Error> {
    read(d).map(Some)
}

/// A setting read by serde ([`setting`]).
fn read<'de, D: serde::Deserializer<'de>, T: Setting>(d: D) -> Result<T, D::Error> {
    let text = TextOrNumber::deserialize(d)
        .map_err(|e| {
            serde::de::Error::custom(format!("{}: {}", T::FIELD, e.to_string().trim_end()))
        })?
        .0;
    T::from_text(&text)
        .map_err(|e| serde::de::Error::custom(format!("{} = \"{text}\": {e}", T::FIELD)))
}

/// A TOML value given as text or as a number, as text.
struct TextOrNumber(String);

impl<'de> Deserialize<'de> for TextOrNumber {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum V {
            Int(i64),
            Float(f64),
            Text(String),
        }
        Ok(TextOrNumber(
            match V::deserialize(d)
                .map_err(|_| serde::de::Error::custom("expected text or a number"))?
            {
                V::Int(i) => i.to_string(),
                V::Float(x) => x.to_string(),
                V::Text(s) => s,
            },
        ))
    }
}

/// A TOML setting given as text or as a number (`mesh = 2`), as text: for
/// the settings of other tables that are stored as given (a design's
/// default mesh, whose levels are text).
pub fn text_or_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
    Ok(Some(TextOrNumber::deserialize(d)?.0))
}

/// A mesh: a level (`coarse` 1, `medium` 2, `fine` 3 or `N`, 1..=12) or,
/// N1 only, `bench`, the benchmark mesh of the element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mesh {
    Level(usize),
    Bench,
}

impl Mesh {
    /// The N1 mesh name of the Q2/P1 benchmark mesh (and, for `quad4`, the
    /// Q1/P0 one, `MeshDensity::BENCH_GRADING`).
    pub const BENCH: &'static str = "bench";

    /// The level of a model that has levels only (every kind but
    /// `n1_needle`); `bench` is refused, naming the field.
    pub fn level(self, kind: &'static str) -> Result<usize, ModelError> {
        match self {
            Mesh::Level(l) => Ok(l),
            Mesh::Bench => Err(ModelError::new(
                kind,
                "mesh",
                self,
                format!(
                    "expected coarse, medium, fine or a level 1..{MAX_MESH_LEVEL} (bench is a mesh of n1_needle)"
                ),
            )),
        }
    }
}

impl Setting for Mesh {
    const FIELD: &'static str = "mesh";
    fn from_text(s: &str) -> Result<Mesh, String> {
        match s {
            "coarse" => Ok(Mesh::Level(MeshDensity::COARSE.level)),
            "medium" => Ok(Mesh::Level(MeshDensity::MEDIUM.level)),
            "fine" => Ok(Mesh::Level(MeshDensity::FINE.level)),
            Mesh::BENCH => Ok(Mesh::Bench),
            n => match n.parse::<usize>() {
                Ok(k) if (1..=MAX_MESH_LEVEL).contains(&k) => Ok(Mesh::Level(k)),
                _ => Err(format!(
                    "expected coarse, medium, fine or a level 1..{MAX_MESH_LEVEL}"
                )),
            },
        }
    }
}

impl fmt::Display for Mesh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Mesh::Level(1) => f.write_str("coarse"),
            Mesh::Level(2) => f.write_str("medium"),
            Mesh::Level(3) => f.write_str("fine"),
            Mesh::Level(n) => write!(f, "{n}"),
            Mesh::Bench => f.write_str(Mesh::BENCH),
        }
    }
}

impl<'de> Deserialize<'de> for Mesh {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        read(d)
    }
}

/// The mesh level of `coarse` (1), `medium` (2), `fine` (3) or `N` (1..=12);
/// absent: [`DEFAULT_MESH`]. The one mesh-level parser of every command.
pub fn parse_mesh(kind: &'static str, s: Option<&str>) -> Result<usize, ModelError> {
    match parse_setting::<Mesh>(kind, s)? {
        None => Ok(DEFAULT_MESH.level),
        Some(m) => m.level(kind),
    }
}

impl Setting for Bulk {
    const FIELD: &'static str = "bulk";
    fn from_text(s: &str) -> Result<Bulk, String> {
        if s == "exact" {
            return Ok(Bulk::Exact);
        }
        match s.parse::<f64>() {
            // Above 1e9 (Poisson's ratio 0.4999999995) the penalty swamps the
            // shear stiffness and the stresses overflow: use `exact`.
            Ok(r) if r > 0.0 && r <= 1e9 => Ok(Bulk::Ratio(r)),
            _ => Err("expected `exact` or a ratio K/mu in (0, 1e9] such as 1000".into()),
        }
    }
}

impl Setting for PlaneCell {
    const FIELD: &'static str = "element";
    fn from_text(s: &str) -> Result<PlaneCell, String> {
        match s {
            "quad4" => Ok(PlaneCell::Quad4),
            "quad9" => Ok(PlaneCell::Quad9),
            _ => Err("expected quad4 or quad9".into()),
        }
    }
}

impl Setting for N3Element {
    const FIELD: &'static str = "element";
    fn from_text(s: &str) -> Result<N3Element, String> {
        match s {
            "hex8" => Ok(N3Element::Hex8),
            "hex27" => Ok(N3Element::Hex27),
            _ => Err("expected hex8 or hex27".into()),
        }
    }
}

impl Setting for Support {
    const FIELD: &'static str = "base";
    fn from_text(s: &str) -> Result<Support, String> {
        match s {
            "bonded" => Ok(Support::Bonded),
            "sliding" => Ok(Support::Sliding),
            _ => Err("expected bonded or sliding".into()),
        }
    }
}

impl Setting for Platens {
    const FIELD: &'static str = "platens";
    fn from_text(s: &str) -> Result<Platens, String> {
        match s {
            "frictionless" => Ok(Platens::Frictionless),
            "bonded" => Ok(Platens::Bonded),
            _ => Err("expected frictionless or bonded".into()),
        }
    }
}

impl Setting for Prony {
    const FIELD: &'static str = "prony";
    fn from_text(s: &str) -> Result<Prony, String> {
        s.parse::<Prony>().map_err(|e| e.to_string())
    }
}

impl Setting for Viscous {
    const FIELD: &'static str = "viscoelastic";
    fn from_text(s: &str) -> Result<Viscous, String> {
        Viscous::parse(s)
    }
}

impl<'de> Deserialize<'de> for Viscous {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        read(d)
    }
}

impl Setting for ToolShape {
    const FIELD: &'static str = "tool";
    /// `needle`, `sphere:R`, `punch:R` (a 0.1 mm edge, at most half the
    /// radius) or `platen`.
    fn from_text(s: &str) -> Result<ToolShape, String> {
        let num = |v: &str| -> Result<f64, String> {
            v.parse::<f64>()
                .ok()
                .filter(|r| *r > 0.0 && r.is_finite())
                .ok_or_else(|| format!("`{v}` is not a positive radius in mm"))
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
            _ => Err("expected needle, sphere:RADIUS, punch:RADIUS or platen".into()),
        }
    }
}

impl Setting for Vec<Nodule> {
    const FIELD: &'static str = "nodules";
    /// `X:DEPTH,...` (mm) or `none`.
    fn from_text(s: &str) -> Result<Vec<Nodule>, String> {
        Nodule::parse_list(s)
    }
}

/// Nodules as `X:DEPTH,...` (mm) or `none`, as [`Nodule::parse_list`] reads them.
pub fn nodules_text(nodules: &[Nodule]) -> String {
    if nodules.is_empty() {
        return "none".into();
    }
    let items: Vec<String> = nodules
        .iter()
        .map(|n| format!("{}:{}", n.x, n.depth))
        .collect();
    items.join(",")
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
