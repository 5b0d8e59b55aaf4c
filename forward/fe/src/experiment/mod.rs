//! A lab's own experiment as data: the specimen, its materials, the tool,
//! the supports, the protocol and the mesh's accuracy, the same from a TOML
//! file (`--experiment FILE`), a study manifest's `[experiments.NAME]`
//! table, command-line options and Python (a dict). The reference problems
//! of docs/benchmarks.md are named presets of it ([`Experiment::preset`]).
//!
//! Units: mm, N, MPa, s. Forces are positive in compression (the tool
//! pushing into the specimen).
//!
//! ```toml
//! [specimen]
//! shape = "cylinder"            # axisymmetric
//! radius = 20.0
//! height = 10.0
//! support = "bonded"            # bonded | sliding | { friction = 0.3 }
//! material = "gel"
//!
//! [materials.gel]
//! law = "neo-hookean"
//! C10 = { start = 2e-3 }        # fitted; `C10 = 2e-3` fixes it
//!
//! [tool]
//! shape = "sphere"
//! radius = 2.5
//! friction = 0.0
//!
//! [mesh]
//! accuracy = 0.01               # relative discretisation error of the force
//! ```
//!
//! The types say what each kind of specimen and tool can carry: a field that
//! has no place in a kind (a tip radius on platens, layers on a 3D block) is
//! refused by the parser with the names that are valid there. What the
//! parser cannot see (a tool larger than the specimen, an inclusion cut by
//! the surface, a parameter named twice, a protocol deeper than the
//! specimen) is refused by [`Experiment::check`], naming the field.

pub mod build;
mod check;
#[cfg(test)]
mod description_tests;
mod io;
pub mod params;
pub mod presets;
mod value;

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

pub use build::ExperimentModel;
pub use params::Parameter;

/// One experiment: what is tested, with what, how, and meshed how finely.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// A name for reports (default: the file's stem or the preset's name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub specimen: Specimen,
    /// Named materials; the specimen, its layers and inclusions refer to
    /// them by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    pub tool: Tool,
    #[serde(default, skip_serializing_if = "Protocol::is_from_record")]
    pub protocol: Protocol,
    #[serde(default, skip_serializing_if = "MeshSpec::is_default")]
    pub mesh: MeshSpec,
}

/// The specimen, by its shape (`shape = "cylinder" | "block" | "mesh"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum Specimen {
    /// A cylinder on its base, modelled axisymmetric (the tool on the axis)
    /// unless `kinematics = "3d"`.
    Cylinder(CylinderSpecimen),
    /// A rectangular block: plane stress, plane strain or 3D.
    Block(BlockSpecimen),
    /// A Gmsh `.msh` 4.1 file whose physical groups name the regions and
    /// boundary sets.
    Mesh(MeshSpecimen),
}

/// `shape = "cylinder"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderSpecimen {
    /// mm.
    pub radius: f64,
    /// mm; the sum of the layers' thicknesses when `layers` are given; may
    /// come from a record's metadata (then omitted here).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    /// `axisymmetric` (default) or `3d`.
    #[serde(default, skip_serializing_if = "CylinderKinematics::is_default")]
    pub kinematics: CylinderKinematics,
    /// The material of the whole cylinder (when there are no layers; may be
    /// omitted when only one material is declared).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// Layers from the top (the tool's side) down; their thicknesses add up
    /// to the height.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub layers: Vec<Layer>,
    #[serde(default)]
    pub support: SupportSpec,
    /// Spheres on the axis (axisymmetric) or anywhere (3D).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inclusions: Vec<Inclusion>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CylinderKinematics {
    #[default]
    Axisymmetric,
    #[serde(rename = "3d")]
    ThreeD,
}

impl CylinderKinematics {
    fn is_default(&self) -> bool {
        *self == CylinderKinematics::Axisymmetric
    }
}

/// One layer of a layered cylinder (from the top down).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    /// mm, > 0.
    pub thickness: f64,
    pub material: String,
}

/// `shape = "block"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSpecimen {
    pub kinematics: BlockKinematics,
    /// Plane: length along x and height (mm); out-of-plane `thickness`
    /// (plane stress) or per unit thickness (plane strain, forces per mm).
    /// 3D: `size = [x, y, z]` instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// 3D: the block's extent along x, y and z (z up), mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    #[serde(default)]
    pub support: SupportSpec,
    /// Circles (plane) or spheres (3D).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inclusions: Vec<Inclusion>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BlockKinematics {
    PlaneStress,
    PlaneStrain,
    #[serde(rename = "3d")]
    ThreeD,
}

/// `shape = "mesh"`: a Gmsh file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpecimen {
    /// Path of the `.msh` 4.1 file (relative to the experiment file).
    pub file: String,
    pub kinematics: MeshKinematics,
    /// Physical group name -> material name; default: each region's
    /// material of the same name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub regions: BTreeMap<String, String>,
    /// The supported boundary: a physical group and how it is held.
    pub support: GroupSupport,
    /// The physical group the tool may touch.
    pub contact_surface: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeshKinematics {
    Axisymmetric,
    PlaneStress,
    PlaneStrain,
    #[serde(rename = "3d")]
    ThreeD,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupSupport {
    pub group: String,
    pub kind: SupportSpec,
}

/// How the specimen's base is held: `"bonded"` (default), `"sliding"`
/// (frictionless), `{ friction = 0.3 }` (Coulomb against a rigid base; the
/// coefficient may be a parameter: `{ friction = { start = 0.3 } }`) or
/// `"symmetry"` (a mirror plane).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SupportSpec {
    #[default]
    Bonded,
    Sliding,
    Symmetry,
    Friction(Value),
}

/// An inclusion, meshed conformingly: `circle` in plane models, `sphere`
/// in 3D and on the axis of an axisymmetric cylinder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inclusion {
    pub shape: InclusionShape,
    /// Centre (mm): `[x, z]` in a plane block, `[x, y, z]` in 3D; on an
    /// axisymmetric cylinder only the depth is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre: Option<Vec<f64>>,
    /// Depth of the centre below the top surface (mm), instead of the
    /// centre's last coordinate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<f64>,
    /// Plane blocks: position along the block (mm), with `depth`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    pub radius: f64,
    pub material: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InclusionShape {
    Circle,
    Sphere,
}

/// A named material: a law and its parameters, fixed or fitted, with an
/// optional Prony series. Parameter names are the law's (`C10`, `C01`,
/// `mu`, `lambda_m`, `mu1`, `alpha1`, ...).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialSpec {
    /// `neo-hookean`, `mooney-rivlin`, `yeoh`, `reduced-polynomial:N`,
    /// `arruda-boyce`, `ogden:N`, `gent`, `veronda-westmann`, `humphrey`.
    pub law: String,
    /// Incompressibility: `"exact"` (default) or a bulk-to-shear ratio
    /// (`K / mu0`, e.g. 1000 as in CalculiX decks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bulk: Option<BulkSpec>,
    /// Prony terms on the isochoric stress: `[{ g = 0.3, tau = 0.5 }, ...]`;
    /// each `g` and `tau` a value or a parameter.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub prony: Vec<PronyTerm>,
    /// The law's parameters by name; any not given starts at the law's
    /// default and is fitted.
    #[serde(flatten)]
    pub params: BTreeMap<String, Value>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum BulkSpec {
    /// `K / mu0`.
    Ratio(f64),
    /// `"exact"`.
    Keyword(String),
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PronyTerm {
    pub g: Value,
    pub tau: Value,
}

/// A number that is either fixed (`0.3`) or a parameter to estimate
/// (`{ start = 0.3 }`, optionally with `lower`, `upper`, and `fit = false`
/// to keep it at `start`); `"bonded"` where a friction coefficient may be
/// infinite (no slip).
///
/// A bad value is refused with what is valid (a number, `{ start = .. }`
/// with optional `fit`, `lower`, `upper`, `nuisance`, or a keyword) and an
/// unknown key of `{ .. }` by its name (`value.rs`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Value {
    Fixed(f64),
    Param(ParamValue),
    /// `"bonded"` (friction only).
    Keyword(String),
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamValue {
    pub start: f64,
    /// Default true.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub fit: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
    /// A nuisance parameter: estimated but not reported as a result.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub nuisance: bool,
}

fn yes() -> bool {
    true
}
fn is_true(b: &bool) -> bool {
    *b
}

/// The tool, by its shape. Every tool has a Coulomb `friction` with the
/// specimen (default 0: frictionless; `"bonded"`: no slip; a parameter:
/// `{ start = 0.3 }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum Tool {
    /// A rigid sphere (Hertz).
    Sphere(SphereTool),
    /// A cone of `half_angle` (degrees) with a spherical tip of
    /// `tip_radius` tangent to it (Sneddon's cone as `tip_radius -> 0`).
    Cone(ConeTool),
    /// The sphere-cone needle of the N1/N3 references (tip 2.5 mm, 15
    /// degrees unless given).
    Needle(ConeTool),
    /// A flat-ended cylindrical punch with a rounded edge.
    FlatPunch(PunchTool),
    /// Two platens compressing the specimen between them (the base's
    /// support becomes the lower platen's).
    Platens(PlatensTool),
    /// A wheel (cylinder in plane models) pressed, then rolled.
    Wheel(WheelTool),
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereTool {
    pub radius: f64,
    #[serde(default, skip_serializing_if = "Value::is_zero")]
    pub friction: Value,
    /// 3D: the tool's position on the top face `[x, y]` (default the
    /// centre).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<[f64; 2]>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConeTool {
    /// Degrees (needle default 15).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_angle: Option<f64>,
    /// mm (needle default 2.5; cone default: a sharp tip, 1e-3 of the
    /// protocol's depth).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Value::is_zero")]
    pub friction: Value,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<[f64; 2]>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PunchTool {
    pub radius: f64,
    /// mm (default a tenth of the radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Value::is_zero")]
    pub friction: Value,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<[f64; 2]>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlatensTool {
    /// Between the upper platen and the specimen; the lower platen is the
    /// specimen's `support`.
    #[serde(default, skip_serializing_if = "Value::is_zero")]
    pub friction: Value,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WheelTool {
    pub radius: f64,
    #[serde(default, skip_serializing_if = "Value::is_zero")]
    pub friction: Value,
    /// Press, then roll: `[{ press_to = 6.0, at_x = 10.0 }, { roll_to_x = 140.0 }]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub path: Vec<Segment>,
    /// Forces reported: `["vertical"]` (default) or `["vertical", "horizontal"]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub report: Vec<ForceAxis>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ForceAxis {
    Vertical,
    Horizontal,
}

/// How the tool moves: from a record's columns (default), or segments.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Protocol {
    /// A record whose displacement (and time, wheel position) columns drive
    /// the tool; `None` with no segments: the data given to the command.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from_record: Option<String>,
    /// Segments in order, from the tool just touching the specimen.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub segments: Vec<Segment>,
    /// Samples per segment (ramp, hold, roll) when segments are given
    /// (default 20), after the start: a ramp to 10 mm with 40 samples is
    /// sampled every 0.25 mm from 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<usize>,
}

impl Protocol {
    fn is_from_record(&self) -> bool {
        self.from_record.is_none() && self.segments.is_empty() && self.samples.is_none()
    }
}

/// One protocol segment; exactly one of its kinds' fields sets:
/// `{ ramp_to = 2.0, time = 1.0 }` (depth in mm, duration in s, optional
/// for an elastic model), `{ hold = 10.0 }` (s), `{ unload_to = 0.0, time
/// = 1.0 }`, `{ press_to = 6.0, at_x = 10.0 }` (a wheel), `{ roll_to_x =
/// 140.0, time = 5.0 }`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_to: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unload_to: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub press_to: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_x: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll_to_x: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<f64>,
    /// Samples of this ramp, hold or roll (default `protocol.samples`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<usize>,
}

/// The mesh: made for a stated accuracy (default), or at a given level.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Target relative discretisation error of the force at the deepest
    /// sample (default 0.01); the mesh is chosen from a convergence
    /// estimate on this experiment and its estimated error is reported.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<f64>,
    /// A mesh level instead of `accuracy` (1 coarse, 2 medium, 3 fine, ...:
    /// element sizes divided by the level).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level: Option<usize>,
    /// `quad9` (default in 2D: 9-node Q2/P1) | `quad4` | `hex27` (default
    /// in 3D) | `hex8`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element: Option<ElementSpec>,
}

impl MeshSpec {
    fn is_default(&self) -> bool {
        *self == MeshSpec::default()
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementSpec {
    Quad4,
    Quad9,
    Hex8,
    Hex27,
}

impl Default for Value {
    fn default() -> Self {
        Value::Fixed(0.0)
    }
}

impl Value {
    fn is_zero(&self) -> bool {
        *self == Value::Fixed(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GEL: &str = r#"
[specimen]
shape = "cylinder"
radius = 20.0
height = 10.0
support = { friction = { start = 0.3, fit = false } }

[materials.gel]
law = "neo-hookean"
C10 = { start = 2e-3 }
prony = [{ g = 0.3, tau = 0.5 }]

[tool]
shape = "sphere"
radius = 2.5
friction = 0.1
"#;

    #[test]
    fn parameters_follow_the_documented_order_and_names() {
        let e: Experiment = toml::from_str(GEL).unwrap();
        let p = e.parameters().unwrap();
        let names: Vec<&str> = p.iter().map(|p| p.spec.name.as_str()).collect();
        // the Prony series and the tool's friction are numbers: part of
        // the model; the base's friction is a parameter held fixed
        assert_eq!(names, ["C10", "base_friction"]);
        let fit: Vec<bool> = p.iter().map(|p| p.fit).collect();
        assert_eq!(fit, [true, false]);
        assert_eq!(p[0].spec.initial, 2e-3);
        assert_eq!(
            e.fixed_parameters().unwrap(),
            vec![("base_friction".to_string(), 0.3)]
        );
        let e: Experiment = toml::from_str(
            &GEL.replace("g = 0.3", "g = { start = 0.3 }")
                .replace("friction = 0.1", "friction = { start = 0.1 }"),
        )
        .unwrap();
        let names: Vec<String> = e
            .parameters()
            .unwrap()
            .into_iter()
            .map(|p| p.spec.name)
            .collect();
        assert_eq!(names, ["C10", "g1", "tau1_s", "friction", "base_friction"]);
        assert_eq!(
            e.fixed_parameters().unwrap(),
            vec![
                ("tau1_s".to_string(), 0.5),
                ("base_friction".to_string(), 0.3)
            ]
        );
    }

    #[test]
    fn a_parameter_the_law_lacks_is_named() {
        let e: Experiment = toml::from_str(&GEL.replace("C10 =", "C01 =")).unwrap();
        let err = e.parameters().unwrap_err().to_string();
        assert!(err.contains("materials.gel.C01"), "{err}");
        assert!(err.contains("C10"), "{err}");
    }

    #[test]
    fn several_materials_are_prefixed_and_must_be_used() {
        let layered = GEL
            .replace("height = 10.0", "layers = [{ thickness = 2.0, material = \"skin\" }, { thickness = 8.0, material = \"gel\" }]")
            + "\n[materials.skin]\nlaw = \"neo-hookean\"\n";
        let e: Experiment = toml::from_str(&layered).unwrap();
        let names: Vec<String> = e
            .parameters()
            .unwrap()
            .into_iter()
            .map(|p| p.spec.name)
            .collect();
        assert_eq!(names[..2], ["skin_C10".to_string(), "gel_C10".to_string()]);
        let unused = GEL.to_string() + "\n[materials.skin]\nlaw = \"neo-hookean\"\n";
        let e: Experiment = toml::from_str(&unused).unwrap();
        let err = e.parameters().unwrap_err().to_string();
        assert!(err.contains("specimen.material"), "{err}");
    }
}
