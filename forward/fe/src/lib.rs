//! # palpate-fe
//!
//! Large-deformation finite elements with frictional rigid-tool contact, as
//! one composable layer (docs/architecture.md has the map and how to add a
//! model, kernel, surface or effect), and the forward models built on it
//! ([`models`]).
//!
//! The layer:
//!
//! * [`mesh`] — meshes of any cell type with node sets, facet sets and
//!   regions; generators (graded, O-grid, conforming inclusions), a Gmsh
//!   reader, VTU output of the mesh.
//! * [`kinematics`] — the kinematic idealisation (3D, axisymmetric, plane
//!   strain, plane stress) owning F and its variations.
//! * [`kernel`] — element kernels behind one trait (Q1/P0 and Q2/P1
//!   quadrilaterals, hexahedra Q1/P0 and Q2/P1, plane-stress quadrilaterals),
//!   [`shape`] and [`quadrature`] per cell type.
//! * [`material`] — the pointwise material seen by the kernels;
//!   [`viscoelastic`] — a Prony series around any of them.
//! * [`dofs`], [`contribution`], [`body`], [`contact`] — boundary
//!   conditions as data and the contributions a step sums, with
//!   trial/commit/rollback history; [`contact_split`] — the contact
//!   quadrature that splits an edge where the force stops being smooth.
//! * [`self_contact`] — a 2D boundary's contact with itself (creases).
//! * [`surface`], [`motion`], [`tool`] — rigid tool surfaces in 2D and 3D
//!   and their motion along loading channels.
//! * [`system`], [`stepper`] — Newton (chord steps, [`line_search`],
//!   proximal stabilisation) on faer sparse factorisations that keep their
//!   symbolic analysis ([`sparse`], [`gmres`]), with typed handles to the
//!   contributions; the stepper runs channels along a path with time,
//!   cut-back and partial results; [`predictor`] — starting states of an
//!   increment.
//! * [`model`] — what every model shares: a [`Setup`] (what an experiment
//!   builds, what its parameters set, what it observes), [`FeModel`], the
//!   one `ForwardModel` of any setup, and the vocabulary of setups
//!   ([`Bulk`], [`PlaneCell`], [`Support`]).
//! * [`discretisation`] — the Richardson estimate of a model's
//!   discretisation error from one coarser solve; [`vtu`] — a solved
//!   system's fields for ParaView; [`error`] — [`FeError`].
//!
//! The models (`docs/benchmarks.md`), each a [`Setup`] behind an alias of
//! [`FeModel`] unless said otherwise:
//!
//! * [`N1Needle`] — needle indentation of a cylinder (axisymmetric);
//! * [`N3Needle`] — the same needle on a block in 3D (quarter model);
//! * [`C1Fe`] — compression of a short cylinder between platens;
//! * [`Q1Punch`] — flat-punch ramp-and-hold indentation; [`Q1Viscous`],
//!   Q1 with its Prony weight and time constant as parameters (a model over
//!   [`Q1Punch`]);
//! * [`R2Rolling`] — a wheel rolled over a block with stiff nodules (plane
//!   stress); [`R2Gap`], R2 as a base model of the gap diagnosis, and
//!   [`r2_scan::R2NoduleScan`], the force of the wheel rolled past one
//!   nodule (models over [`R2Rolling`]).

// Index loops mirror the index notation of the equations; negated comparisons
// (`!(x > 0.0)`) deliberately treat NaN as failure.
#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::nonminimal_bool,
    clippy::collapsible_match
)]

pub mod accuracy;
pub mod body;
pub mod contact;
pub mod contact_split;
pub mod contribution;
pub mod discretisation;
pub mod dofs;
pub mod error;
pub mod experiment;
pub mod gmres;
pub mod kernel;
pub mod kinematics;
pub mod line_search;
pub mod material;
pub mod mesh;
pub mod model;
pub mod models;
pub mod motion;
pub mod predictor;
pub mod quadrature;
pub mod self_contact;
pub mod sensitivity;
pub mod shape;
pub mod sparse;
pub mod stepper;
pub mod surface;
pub mod system;
pub mod tool;
pub mod viscoelastic;
pub mod vtu;

pub use models::{c1, cylinder, n1, n3, q1, r2, r2_gap, r2_scan};

pub use c1::{C1Fe, C1Setup, Platens};
pub use contact::ContactPoints;
pub use cylinder::{Cylinder, CylinderSetup};
pub use discretisation::{Coarser, ConvergenceOrder, ErrorEstimate};
pub use error::FeError;
pub use line_search::LineSearch;
pub use material::LawMaterial;
pub use model::{Bulk, FeModel, PlaneCell, Setup, Simulation, Support};
pub use n1::{BandMaterial, EdgeBand, MeshDensity, N1Needle, N1Setup, Sizing};
pub use n3::{
    n3_core_cells, n3_grading, n3_quadratic_grading, N3Element, N3Mesh, N3Needle, N3Setup,
};
pub use q1::viscous::Q1Viscous;
pub use q1::{Q1Punch, Q1Setup};
pub use r2::{r2_element_size, Nodule, R2Rolling, R2Setup};
pub use r2_gap::R2Gap;
pub use stepper::{LoadPath, Progress};
pub use surface::{
    Cylinder3d, Floor2d, Profile2d, Revolution3d, RigidSurface, SurfacePoint, Wheel2d,
};
pub use system::{RunStats, SolverOptions, System};
pub use tool::ToolShape;
pub use viscoelastic::{Prony, Viscoelastic};
