//! One description of a forward model ([`ModelSpec`]) and one factory
//! ([`build`]) shared by `simulate`, `calibrate`, `sample`, `doe`,
//! `diagnose` and the study runner.
//!
//! A spec is plain serde data, externally tagged by the kind of model, as in
//! a study manifest:
//!
//! ```toml
//! [models.needle.n1_needle]   # N1 needle indentation (finite elements)
//! law = "neo-hookean"
//! friction = 0.8              # Coulomb coefficient needle/material
//! mesh = "coarse"             # coarse | medium | fine | N (N = 1..12)
//! bulk = "exact"              # exact | K/mu ratio such as 1000
//! element = "quad4"            # quad4 (Q1/P0) | quad9 (Q2/P1), N1 only
//! base = "bonded"             # bonded | sliding
//! tool = "needle"             # needle | sphere:R | punch:R | platen
//! prony = "g1=0.3,tau1=0.5"   # viscoelastic (as c1_fe; needs timed data)
//!
//! [models.needle3d.n3_needle] # N3 needle indentation, 3D quarter block (finite elements)
//! law = "neo-hookean"
//! friction = 0.8
//! mesh = "coarse"             # coarse (default for N3) | medium | fine | N: 0.8/N mm hexahedra under the tool
//! bulk = "exact"
//! tool = "needle"
//!
//! [models.press.c1_fe]        # C1 compression (finite elements)
//! law = "neo-hookean"
//! platens = "frictionless"    # frictionless | bonded
//! mesh = "medium"             # level N: 19N x 9N elements
//! prony = "g1=0.3,tau1=0.5"   # viscoelastic (Prony series on the isochoric stress; needs timed data)
//!
//! [models.punch.q1]         # Q1 flat-punch ramp-and-hold (finite elements)
//! law = "neo-hookean"
//! mesh = "medium"             # level N: elements of 0.2/N mm under the punch
//! element = "quad4"           # quad4 (Q1/P0) | quad9 (Q2/P1)
//! prony = "g1=0.3,tau1=0.5,g2=0.2,tau2=10"
//!
//! [models.rolling.r2]        # R2 rolling indentation over nodules, plane stress (finite elements)
//! law = "arruda-boyce"        # tissue law (default arruda-boyce: rtv6166-ab)
//! nodule_law = "arruda-boyce" # nodule law (default arruda-boyce: rubber-ab)
//! rd = 6                      # rolling depth (mm), required
//! nodules = "37.5:10,75:15,112.5:20"  # X:DEPTH list (mm) or "none"; "75:15" is R2-1
//! friction = 0                # Coulomb coefficient wheel/block (default 0)
//! mesh = "coarse"             # coarse (default) | medium | fine | N: 9-node elements of 2/N mm
//!
//! [models.press-analytic.c1]  # C1 compression (analytic, lubricated)
//! law = "neo-hookean"
//!
//! [models.disc]               # a lab's own experiment (finite elements, [`experiment`])
//! experiment = "gel"          # a table [experiments.gel] of the manifest, a preset (N1, ...) or a file
//!
//! [models.tension.homogeneous] # homogeneous test (analytic)
//! law = "mooney-rivlin"
//! mode = "uniaxial"           # uniaxial | biaxial | planar | general_biaxial | simple_shear
//! axial_stretch = 0.8         # simple_shear only: shear superposed on this axial stretch (default 1)
//! viscoelastic = "qlv:2"      # qlv:N (Prony on the nominal stress) | finite:N (on the isochoric 2nd Piola stress, uniaxial)
//! ```
//!
//! Every optional setting has one default, the same from a manifest and from
//! the command line ([`DEFAULT_FRICTION`], [`DEFAULT_MESH`], `bulk = exact`,
//! `base = bonded`, `tool = needle`, `platens = frictionless`).
//! [`ModelSpec::validate`] turns a spec into a checked [`Model`] and names
//! the offending field when a value is wrong.
//!
//! The legacy form of a manifest model, `law = "..."` alone, means "this law
//! in the model of each data set's test" ([`for_test`]); the gap diagnosis's
//! `base = "..."` means the base model of [`gap_base`].

pub mod calibration;
pub mod defaults;
pub mod entry;
pub mod experiment;
pub mod fields;

pub use entry::{ModelEntry, ModelForm};
pub use experiment::{ExperimentSource, ExperimentSpec};

use crate::records::{TestData, TestKind};
use palpate_analytic::{
    C1Compression, GeneralBiaxial, Homogeneous, Mode, SimpleShear, ViscousUniaxial,
};
use palpate_core::ForwardModel;
use palpate_fe::{
    Bulk, C1Fe, MeshDensity, N1Needle, N3Element, N3Mesh, N3Needle, Nodule, PlaneCell, Platens,
    Prony, Q1Punch, R2Rolling, Support, ToolShape,
};
use palpate_material::Law;
use serde::Deserialize;
use std::fmt;
use std::sync::Arc;

pub use defaults::{
    check_effects, default_effects, for_test, gap_base, gap_base_for, parse_effects,
    spans_tension_and_compression,
};
pub use fields::{nodules_text, parse_mesh, parse_setting, text_or_number, Mesh, Setting};
use fields::{parse_mode, setting};

/// Default Coulomb friction between the N1 needle and the material (docs/benchmarks.md).
pub const DEFAULT_FRICTION: f64 = 0.8;
/// Default mesh of the FE models (level 2: N1 0.2 mm elements under the
/// tool, C1 38 x 18 elements).
pub const DEFAULT_MESH: MeshDensity = MeshDensity::MEDIUM;
/// The finest mesh level accepted.
pub const MAX_MESH_LEVEL: usize = 12;

/// A forward model, by kind.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ModelSpec {
    /// A homogeneous test of a law (analytic).
    Homogeneous(HomogeneousSpec),
    /// Benchmark C1, lubricated compression (analytic).
    C1(C1Spec),
    /// Benchmark C1 by finite elements.
    C1Fe(C1FeSpec),
    /// Benchmark N1, needle indentation by finite elements.
    N1Needle(N1NeedleSpec),
    /// Benchmark Q1, flat-punch ramp-and-hold by finite elements.
    Q1(Q1Spec),
    /// Benchmark N3, needle indentation of a block in 3D by finite elements.
    N3Needle(N3NeedleSpec),
    /// Benchmark R2 (and R2-1), rolling indentation over bonded nodules,
    /// plane stress, by finite elements.
    R2(R2Spec),
    /// A lab's own experiment ([`experiment`]): specimen, materials, tool,
    /// supports, protocol and mesh described as data; `experiment = "NAME"`
    /// names a manifest's `[experiments.NAME]` table, a preset or a file.
    Experiment(ExperimentSpec),
}

/// `[... .r2]`
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct R2Spec {
    /// The tissue law (default `arruda-boyce`, for `rtv6166-ab`).
    #[serde(default = "arruda_boyce")]
    pub law: String,
    /// The nodules' law (default `arruda-boyce`, for `rubber-ab`); its
    /// parameters follow the tissue's, named `nodule_...`.
    #[serde(default)]
    pub nodule_law: Option<String>,
    /// Rolling depth (mm).
    pub rd: f64,
    /// `X:DEPTH,...` (mm) or `none`; default docs/benchmarks.md's three nodules.
    #[serde(default, deserialize_with = "setting")]
    pub nodules: Option<Vec<Nodule>>,
    /// Coulomb friction between wheel and block (default 0).
    #[serde(default)]
    pub friction: Option<f64>,
    /// `coarse` (default), `medium`, `fine` or a level 1..R2_MAX_LEVEL:
    /// 9-node elements of 2/N mm at the surface and around the nodules.
    #[serde(default)]
    pub mesh: Option<Mesh>,
    /// `exact` (default) or a bulk-to-shear ratio K/mu.
    #[serde(default, deserialize_with = "setting")]
    pub bulk: Option<Bulk>,
}

fn arruda_boyce() -> String {
    "arruda-boyce".into()
}

/// docs/benchmarks.md's default R2 nodules.
pub const R2_DEFAULT_NODULES: &str = "37.5:10,75:15,112.5:20";
/// The finest R2 level accepted: level 4 (0.5 mm elements) has ~150,000
/// unknowns, a rolled pass of hours on 2 cores.
pub const R2_MAX_LEVEL: usize = 3;

/// `[... .homogeneous]`
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HomogeneousSpec {
    pub law: String,
    /// `uniaxial`, `biaxial` (equibiaxial), `planar`, `general_biaxial` or `simple_shear`.
    pub mode: String,
    /// Simple shear only: the axial stretch of the plate gap the shear is
    /// superposed on (default 1, plain simple shear).
    #[serde(default)]
    pub axial_stretch: Option<f64>,
    /// A viscoelastic form ([`Viscous`]): `qlv:N` or `finite:N`; none: elastic.
    #[serde(default)]
    pub viscoelastic: Option<Viscous>,
}

/// A viscoelastic form of a homogeneous test, with its number of Prony terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Viscous {
    /// Quasi-linear viscoelasticity (Fung): the Prony series acts on the
    /// elastic nominal stress (`palpate_enrich::Viscoelastic`). Any homogeneous test.
    Qlv(usize),
    /// The Prony series acts on the isochoric second Piola stress, the
    /// pressure at the current stretch (`palpate_analytic::ViscousUniaxial`).
    /// Uniaxial records only.
    Finite(usize),
}

impl Viscous {
    /// Parses `qlv:N` or `finite:N` (N = 1..=6 Prony terms; `qlv` alone is `qlv:2`).
    pub fn parse(s: &str) -> Result<Viscous, String> {
        let (kind, n) = s.split_once(':').unwrap_or((s, "2"));
        let n: usize = n
            .trim()
            .parse()
            .ok()
            .filter(|n| (1..=6).contains(n))
            .ok_or_else(|| format!("`{s}`: the number of Prony terms must be 1 to 6"))?;
        match kind.trim().to_ascii_lowercase().as_str() {
            "qlv" => Ok(Viscous::Qlv(n)),
            "finite" | "finite-strain" | "finite_strain" => Ok(Viscous::Finite(n)),
            _ => Err(format!(
                "`{s}`: expected qlv:N (Prony series on the nominal stress) or finite:N (on the isochoric second Piola stress)"
            )),
        }
    }
}

impl fmt::Display for Viscous {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Viscous::Qlv(n) => write!(f, "qlv:{n}"),
            Viscous::Finite(n) => write!(f, "finite:{n}"),
        }
    }
}

/// `[... .c1]`
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct C1Spec {
    pub law: String,
}

/// `[... .c1_fe]`
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct C1FeSpec {
    pub law: String,
    /// `frictionless` (default) or `bonded`.
    #[serde(default, deserialize_with = "setting")]
    pub platens: Option<Platens>,
    /// `coarse`, `medium` (default), `fine` or a level 1..12: 19N x 9N elements.
    #[serde(default)]
    pub mesh: Option<Mesh>,
    /// `exact` (default) or a bulk-to-shear ratio K/mu.
    #[serde(default, deserialize_with = "setting")]
    pub bulk: Option<Bulk>,
    /// A Prony series `g1=..,tau1=..,g2=..,tau2=..` on the law's isochoric
    /// stress (`palpate_fe::Viscoelastic`); none: elastic.
    #[serde(default, deserialize_with = "setting")]
    pub prony: Option<Prony>,
}

/// `[... .n1_needle]`
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct N1NeedleSpec {
    pub law: String,
    /// Coulomb friction coefficient (default 0.8).
    #[serde(default)]
    pub friction: Option<f64>,
    /// `coarse`, `medium` (default), `fine` or a level 1..12: elements of 0.4/N mm under the tool.
    #[serde(default)]
    pub mesh: Option<Mesh>,
    /// `exact` (default) or a bulk-to-shear ratio K/mu.
    #[serde(default, deserialize_with = "setting")]
    pub bulk: Option<Bulk>,
    /// `bonded` (default) or `sliding`.
    #[serde(default, deserialize_with = "setting")]
    pub base: Option<Support>,
    /// `needle` (default), `sphere:R`, `punch:R` or `platen`.
    #[serde(default, deserialize_with = "setting")]
    pub tool: Option<ToolShape>,
    /// `quad4` (default: 4-node Q1/P0) or `quad9` (9-node Q2/P1 on the
    /// same grading, each cell made quadratic).
    #[serde(default, deserialize_with = "setting")]
    pub element: Option<PlaneCell>,
    /// A Prony series `g1=..,tau1=..,g2=..,tau2=..` on the law's isochoric
    /// stress (`palpate_fe::Viscoelastic`); none: elastic.
    #[serde(default, deserialize_with = "setting")]
    pub prony: Option<Prony>,
}

/// `[... .q1]`
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Q1Spec {
    pub law: String,
    /// `coarse`, `medium` (default), `fine` or a level 1..12: elements of 0.2/N mm under the punch.
    #[serde(default)]
    pub mesh: Option<Mesh>,
    /// `exact` (default) or a bulk-to-shear ratio K/mu.
    #[serde(default, deserialize_with = "setting")]
    pub bulk: Option<Bulk>,
    /// `quad4` (default, Q1/P0) or `quad9` (Q2/P1).
    #[serde(default, deserialize_with = "setting")]
    pub element: Option<PlaneCell>,
    /// A Prony series `g1=..,tau1=..,g2=..,tau2=..`; none: elastic.
    #[serde(default, deserialize_with = "setting")]
    pub prony: Option<Prony>,
    /// Radius of the punch's rounded edge (mm), 0 < edge_radius < 2 (the
    /// punch radius); default 0.2 (`palpate_fe::q1::DEFAULT_EDGE_RADIUS`).
    #[serde(default)]
    pub edge_radius: Option<f64>,
}

/// Why a Q1 ramp stops near one punch radius, and what reaches deeper; for
/// the message of a run that stopped (docs/validation/fe.md "Q1").
pub const Q1_STOP_HINT: &str =
    "with a 0.2 mm edge (the default) the Q1 punch stops near one punch \
radius of depth (about 2 mm; a known limit of the contact on the rounded edge, \
docs/validation/fe.md \"Q1\"); a larger --edge-radius (manifest: edge_radius) reaches deeper \
(0.5 mm: about 3.7 mm; 1 mm: the 5 mm ramp and hold with a Prony series), but it is then a \
rounded punch: its force at 0.1 mm is 0.80 (0.5 mm) or 0.57 (1 mm) of Sneddon's for the \
flat punch, against 0.94 with the 0.2 mm edge";

/// `[... .n3_needle]`
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct N3NeedleSpec {
    pub law: String,
    /// Coulomb friction coefficient (default 0.8).
    #[serde(default)]
    pub friction: Option<f64>,
    /// `coarse` (default for N3), `medium`, `fine` or a level 1..N3_MAX_LEVEL:
    /// hexahedra of 0.8/N mm under the tool.
    #[serde(default)]
    pub mesh: Option<Mesh>,
    /// `exact` (default) or a bulk-to-shear ratio K/mu.
    #[serde(default, deserialize_with = "setting")]
    pub bulk: Option<Bulk>,
    /// `needle` (default), `sphere:R`, `punch:R` or `platen`.
    #[serde(default, deserialize_with = "setting")]
    pub tool: Option<ToolShape>,
    /// `hex8` (default: 8-node Q1/P0 hexahedra on the box) or `hex27`
    /// (27-node Q2/P1 hexahedra on the quarter O-grid, cells of 1.6/N mm).
    #[serde(default, deserialize_with = "setting")]
    pub element: Option<N3Element>,
}

/// The default N3 mesh: level 1 (the box of 0.8 mm hexahedra, 2,340 cells,
/// 10,125 equations; level 2 has 17,400 cells, ~70,000 equations;
/// docs/validation/fe.md "N3").
pub const N3_DEFAULT_MESH: Mesh = Mesh::Level(1);
/// The finest N3 level accepted: level 3 (the box: ~57,000 hexahedra)
/// would need more memory and time than a 2-core, few-GiB machine has.
pub const N3_MAX_LEVEL: usize = 2;

/// A value of a spec that is wrong: the kind, the field, the value given and
/// what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{kind}.{field} = \"{value}\": {expected}")]
pub struct ModelError {
    pub kind: &'static str,
    pub field: &'static str,
    pub value: String,
    pub expected: String,
}

/// What is wrong with an experiment description: the field
/// (`tool.radius`, `specimen.layers[1].thickness`), the description's
/// source and why.
fn experiment_error(spec: &ExperimentSpec, e: impl fmt::Display) -> ModelError {
    ModelError::new("experiment", "description", &spec.source, e.to_string())
}

impl ModelError {
    pub(crate) fn new(
        kind: &'static str,
        field: &'static str,
        value: impl fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        ModelError {
            kind,
            field,
            value: value.to_string(),
            expected: expected.into(),
        }
    }

    /// The error in command-line terms (`--mesh 0: ...`).
    pub fn as_option(&self) -> String {
        format!(
            "--{} `{}`: {}",
            self.field.replace('_', "-"),
            self.value,
            self.expected
        )
    }
}

/// A checked model, ready to run.
#[derive(Debug, Clone, PartialEq)]
pub enum Model {
    Homogeneous(Homogeneous),
    GeneralBiaxial(GeneralBiaxial),
    SimpleShear(SimpleShear),
    /// A homogeneous test in quasi-linear viscoelasticity with N Prony terms.
    Qlv(Box<Model>, usize),
    ViscousUniaxial(ViscousUniaxial),
    C1(C1Compression),
    C1Fe(C1Fe),
    N1Needle(N1Needle),
    Q1(Q1Punch),
    N3Needle(N3Needle),
    R2(R2Rolling),
    Experiment(BuiltExperiment),
}

/// The model an experiment description builds, with the description (two
/// are equal when their descriptions are: the model is made from it).
#[derive(Debug, Clone)]
pub struct BuiltExperiment {
    pub spec: ExperimentSpec,
    pub model: palpate_fe::experiment::ExperimentModel,
}

impl PartialEq for BuiltExperiment {
    fn eq(&self, other: &Self) -> bool {
        self.spec == other.spec
    }
}

impl Model {
    /// The model behind the common forward-model seam.
    pub fn into_forward(self) -> Box<dyn ForwardModel> {
        match self {
            Model::Homogeneous(m) => Box::new(m),
            Model::GeneralBiaxial(m) => Box::new(m),
            Model::SimpleShear(m) => Box::new(m),
            Model::Qlv(m, terms) => {
                Box::new(palpate_enrich::Viscoelastic::new(m.into_forward(), terms))
            }
            Model::ViscousUniaxial(m) => Box::new(m),
            Model::C1(m) => Box::new(m),
            Model::C1Fe(m) => Box::new(m),
            Model::N1Needle(m) => Box::new(m),
            Model::Q1(m) => Box::new(m),
            Model::N3Needle(m) => Box::new(m),
            Model::R2(m) => Box::new(m),
            Model::Experiment(m) => m.model.boxed(),
        }
    }
}

/// Builds the forward model a spec describes (the one factory).
pub fn build(spec: &ModelSpec) -> Result<Box<dyn ForwardModel>, ModelError> {
    Ok(spec.validate()?.into_forward())
}

impl ModelSpec {
    /// The kinds, as spelled in manifests.
    pub const KINDS: [&'static str; 8] = [
        "homogeneous",
        "c1",
        "c1_fe",
        "n1_needle",
        "n3_needle",
        "q1",
        "r2",
        "experiment",
    ];

    /// The kind, as spelled in manifests.
    pub fn kind(&self) -> &'static str {
        match self {
            ModelSpec::Homogeneous(_) => "homogeneous",
            ModelSpec::C1(_) => "c1",
            ModelSpec::C1Fe(_) => "c1_fe",
            ModelSpec::N1Needle(_) => "n1_needle",
            ModelSpec::Q1(_) => "q1",
            ModelSpec::N3Needle(_) => "n3_needle",
            ModelSpec::R2(_) => "r2",
            ModelSpec::Experiment(_) => "experiment",
        }
    }

    /// The law as written.
    pub fn law_text(&self) -> &str {
        match self {
            ModelSpec::Homogeneous(s) => &s.law,
            ModelSpec::C1(s) => &s.law,
            ModelSpec::C1Fe(s) => &s.law,
            ModelSpec::N1Needle(s) => &s.law,
            ModelSpec::Q1(s) => &s.law,
            ModelSpec::N3Needle(s) => &s.law,
            ModelSpec::R2(s) => &s.law,
            ModelSpec::Experiment(s) => s.law_text(),
        }
    }

    /// The parsed law.
    pub fn law(&self) -> Result<Law, ModelError> {
        let t = self.law_text();
        t.parse::<Law>()
            .map_err(|e| ModelError::new(self.kind(), "law", t, e.to_string()))
    }

    /// The test whose records this model predicts.
    pub fn test(&self) -> Result<TestKind, ModelError> {
        Ok(match self {
            ModelSpec::Homogeneous(s) => match homogeneous_kind(&s.mode)? {
                HomogeneousKind::Mode(m) => TestKind::Homogeneous(m),
                HomogeneousKind::GeneralBiaxial => TestKind::GeneralBiaxial,
                HomogeneousKind::SimpleShear => TestKind::SimpleShear,
            },
            ModelSpec::C1(_) | ModelSpec::C1Fe(_) => TestKind::C1,
            // force records (displacement_mm, force_N), as N1's
            ModelSpec::N1Needle(_) | ModelSpec::N3Needle(_) | ModelSpec::Experiment(_) => {
                TestKind::N1
            }
            ModelSpec::Q1(_) => {
                return Err(ModelError::new(
                    "q1",
                    "test",
                    "Q1",
                    "Q1 records are not a test kind of calibrate/sample yet",
                ))
            }
            ModelSpec::R2(_) => {
                return Err(ModelError::new(
                    "r2",
                    "test",
                    "R2",
                    "R2 rolling records are not a test kind of calibrate/sample yet",
                ))
            }
        })
    }

    /// Checks every field and builds the model; errors name the field.
    pub fn validate(&self) -> Result<Model, ModelError> {
        // (its laws are checked with their fields by the description)
        if let ModelSpec::Experiment(s) = self {
            return experiment_model(s);
        }
        let law = self.law()?;
        Ok(match self {
            ModelSpec::Homogeneous(s) => homogeneous_model(law, s)?,
            ModelSpec::C1(_) => Model::C1(C1Compression::new(law)),
            ModelSpec::C1Fe(s) => {
                const K: &str = "c1_fe";
                let mut m = C1Fe::new(law, s.platens.unwrap_or(Platens::Frictionless));
                let level = mesh_level(K, s.mesh)?;
                m.elements = (19 * level, 9 * level);
                m.bulk = s.bulk.unwrap_or(Bulk::Exact);
                m.prony = s.prony.clone();
                Model::C1Fe(m)
            }
            ModelSpec::Q1(s) => {
                const K: &str = "q1";
                let mut m = Q1Punch::new(law);
                m.level = mesh_level(K, s.mesh)?;
                m.bulk = s.bulk.unwrap_or(Bulk::Exact);
                m.element = s.element.unwrap_or(PlaneCell::Quad4);
                m.prony = s.prony.clone();
                if let Some(rho) = s.edge_radius {
                    m.set_edge_radius(rho)
                        .map_err(|e| ModelError::new(K, "edge_radius", rho, e))?;
                }
                Model::Q1(m)
            }
            ModelSpec::N1Needle(s) => {
                const K: &str = "n1_needle";
                let mut m = N1Needle::new(law);
                let friction = s.friction.unwrap_or(DEFAULT_FRICTION);
                if !(friction >= 0.0 && friction.is_finite()) {
                    return Err(ModelError::new(
                        K,
                        "friction",
                        friction,
                        "expected a coefficient >= 0",
                    ));
                }
                m.friction = friction;
                m.bulk = s.bulk.unwrap_or(Bulk::Exact);
                m.base = s.base.unwrap_or(Support::Bonded);
                m.tool = s.tool.unwrap_or_else(ToolShape::n1_needle);
                defaults::set_n1_mesh(s.mesh, s.element, &mut m);
                m.prony = s.prony.clone();
                Model::N1Needle(m)
            }
            ModelSpec::N3Needle(s) => {
                const K: &str = "n3_needle";
                let mut m = N3Needle::new(law);
                let friction = s.friction.unwrap_or(DEFAULT_FRICTION);
                if !(friction >= 0.0 && friction.is_finite()) {
                    return Err(ModelError::new(
                        K,
                        "friction",
                        friction,
                        "expected a coefficient >= 0",
                    ));
                }
                m.friction = friction;
                let mesh = s.mesh.unwrap_or(N3_DEFAULT_MESH);
                let level = mesh.level(K)?;
                if level > N3_MAX_LEVEL {
                    return Err(ModelError::new(
                        K,
                        "mesh",
                        mesh,
                        format!(
                            "N3 accepts levels 1..{N3_MAX_LEVEL} (coarse, medium): level {level} has {} equations, beyond this machine's memory and time (docs/validation/fe.md, N3)",
                            n3_equations(level)
                        ),
                    ));
                }
                m.level = level;
                m.bulk = s.bulk.unwrap_or(Bulk::Exact);
                m.tool = s.tool.unwrap_or_else(ToolShape::n1_needle);
                m.element = s
                    .element
                    .unwrap_or_else(|| defaults::n3_default_element(&m, s.mesh.is_some()));
                if m.element == N3Element::Hex27 {
                    m.mesh = N3Mesh::OGrid;
                }
                Model::N3Needle(m)
            }
            ModelSpec::R2(s) => Model::R2(r2_model(s, law)?),
            ModelSpec::Experiment(s) => experiment_model(s)?,
        })
    }
}

/// The model of an experiment description, checked first
/// ([`Experiment::check`](palpate_fe::experiment::Experiment)).
fn experiment_model(s: &ExperimentSpec) -> Result<Model, ModelError> {
    s.experiment.check().map_err(|e| experiment_error(s, e))?;
    let model = s.experiment.model().map_err(|e| experiment_error(s, e))?;
    Ok(Model::Experiment(BuiltExperiment {
        spec: s.clone(),
        model,
    }))
}

/// The level of a spec's mesh (absent: [`DEFAULT_MESH`]) for a kind that
/// has levels only.
fn mesh_level(kind: &'static str, mesh: Option<Mesh>) -> Result<usize, ModelError> {
    mesh.map_or(Ok(DEFAULT_MESH.level), |m| m.level(kind))
}

/// The R2 model of a spec: every field checked, the geometry (nodules
/// inside the block, not overlapping, RD) by building the mesh once.
fn r2_model(s: &R2Spec, law: Law) -> Result<R2Rolling, ModelError> {
    const K: &str = "r2";
    let nodule_law = match &s.nodule_law {
        None => Law::ArrudaBoyce,
        Some(t) => t
            .parse::<Law>()
            .map_err(|e| ModelError::new(K, "nodule_law", t, e.to_string()))?,
    };
    if !(s.rd > 0.0 && s.rd.is_finite()) {
        return Err(ModelError::new(
            K,
            "rd",
            s.rd,
            "expected a rolling depth > 0 mm",
        ));
    }
    let mut m = R2Rolling::new(law, nodule_law, s.rd);
    m.nodules = match &s.nodules {
        Some(n) => n.clone(),
        None => Nodule::parse_list(R2_DEFAULT_NODULES)
            .map_err(|e| ModelError::new(K, "nodules", R2_DEFAULT_NODULES, e))?,
    };
    let text = fields::nodules_text(&m.nodules);
    let friction = s.friction.unwrap_or(0.0);
    if !(friction >= 0.0 && friction.is_finite()) {
        return Err(ModelError::new(
            K,
            "friction",
            friction,
            "expected a coefficient >= 0",
        ));
    }
    m.friction = friction;
    let mesh = s.mesh.unwrap_or(Mesh::Level(1));
    let level = mesh.level(K)?;
    if level > R2_MAX_LEVEL {
        return Err(ModelError::new(
            K,
            "mesh",
            mesh,
            format!(
                "R2 accepts levels 1..{R2_MAX_LEVEL} (elements of 2, 1, 0.67 mm); finer meshes are for the mesh study `cargo run --release -p palpate-tools --bin convergence_r2`"
            ),
        ));
    }
    m.level = level;
    m.bulk = s.bulk.unwrap_or(Bulk::Exact);
    // the scalars and the geometry, named (rd deeper than the wheel allows,
    // a nodule outside the block or overlapping another)
    palpate_fe::r2::check_model(&m).map_err(|(field, reason)| {
        let value = match field.as_str() {
            "rd" => s.rd.to_string(),
            "friction" => friction.to_string(),
            _ => text.to_string(),
        };
        let field: &'static str = match field.as_str() {
            "rd" => "rd",
            "friction" => "friction",
            _ => "nodules",
        };
        ModelError::new(K, field, value, reason)
    })?;
    Ok(m)
}

/// The equations of N3 mesh `level` (the default box), counted from its
/// grading without building the mesh.
fn n3_equations(level: usize) -> usize {
    let mut m = N3Needle::new(Law::NeoHookean);
    m.level = level;
    m.mesh_size().map_or(0, |(_, _, e)| e)
}

/// What a `homogeneous` spec's `mode` names.
enum HomogeneousKind {
    Mode(Mode),
    GeneralBiaxial,
    SimpleShear,
}

fn homogeneous_kind(s: &str) -> Result<HomogeneousKind, ModelError> {
    match s.trim().to_ascii_lowercase().replace('-', "_").as_str() {
        "general_biaxial" => Ok(HomogeneousKind::GeneralBiaxial),
        "simple_shear" => Ok(HomogeneousKind::SimpleShear),
        _ => parse_mode(s).map(HomogeneousKind::Mode),
    }
}

/// The model of a `homogeneous` spec: the test, its axial stretch, its viscoelastic form.
fn homogeneous_model(law: Law, s: &HomogeneousSpec) -> Result<Model, ModelError> {
    const K: &str = "homogeneous";
    let kind = homogeneous_kind(&s.mode)?;
    if let Some(a) = s.axial_stretch {
        if !matches!(kind, HomogeneousKind::SimpleShear) {
            return Err(ModelError::new(
                K,
                "axial_stretch",
                a,
                "only a simple_shear test has an axial stretch",
            ));
        }
    }
    let elastic = match kind {
        HomogeneousKind::Mode(m) => Model::Homogeneous(Homogeneous::new(law, m)),
        HomogeneousKind::GeneralBiaxial => Model::GeneralBiaxial(GeneralBiaxial::new(law)),
        HomogeneousKind::SimpleShear => {
            let a = s.axial_stretch.unwrap_or(1.0);
            Model::SimpleShear(
                SimpleShear::new(law, a)
                    .map_err(|e| ModelError::new(K, "axial_stretch", a, e.to_string()))?,
            )
        }
    };
    let Some(v) = s.viscoelastic else {
        return Ok(elastic);
    };
    Ok(match (v, &elastic) {
        (_, Model::GeneralBiaxial(_)) => {
            return Err(ModelError::new(
                K,
                "viscoelastic",
                v,
                "a general biaxial record pairs two stretches per row, not a time history",
            ))
        }
        (Viscous::Qlv(n), _) => Model::Qlv(Box::new(elastic), n),
        (Viscous::Finite(n), Model::Homogeneous(h)) if h.mode == Mode::Uniaxial => {
            Model::ViscousUniaxial(
                ViscousUniaxial::new(law, n)
                    .map_err(|e| ModelError::new(K, "viscoelastic", v, e.to_string()))?,
            )
        }
        (Viscous::Finite(_), _) => {
            return Err(ModelError::new(
                K,
                "viscoelastic",
                v,
                "finite:N is written for uniaxial records; use qlv:N for other tests",
            ))
        }
    })
}

/// The forward model of a test for a law ([`for_test`]).
pub fn test_model(test: TestKind, law: Law) -> anyhow::Result<Arc<dyn ForwardModel>> {
    let m = build(&for_test(test, law)).map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(Arc::from(m))
}

/// The model of a record's test for `law` ([`for_test`]), with its axial
/// stretch and, if given, a viscoelastic form.
pub fn record_spec(record: &TestData, law: Law, viscous: Option<Viscous>) -> ModelSpec {
    let mut spec = for_test(record.test, law);
    if let ModelSpec::Homogeneous(h) = &mut spec {
        if record.test == TestKind::SimpleShear && record.axial_stretch != 1.0 {
            h.axial_stretch = Some(record.axial_stretch);
        }
        h.viscoelastic = viscous;
    }
    spec
}

#[cfg(test)]
#[path = "models_tests.rs"]
mod tests;
