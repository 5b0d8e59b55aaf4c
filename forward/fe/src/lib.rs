//! # palpate-fe
//!
//! Large-deformation finite elements with frictional rigid-tool contact, as
//! one composable layer (docs/architecture.md has the map and how to add a
//! model, kernel, surface or effect), and the forward models built on it:
//! N1 and N3 needle indentation, C1 compression and Q1 flat-punch
//! ramp-and-hold (`BENCHMARKS.md`).
//!
//! * [`mesh`] — meshes of any cell type with node sets, facet sets and
//!   regions; generators, a Gmsh reader, VTU output.
//! * [`kinematics`] — the kinematic idealisation (3D, axisymmetric, plane
//!   strain, plane stress) owning F and its variations.
//! * [`kernel`] — element kernels behind one trait (Q1/P0, Q2/P1, hex
//!   Q1/P0, plane-stress quads), [`shape`] and [`quadrature`] per cell type.
//! * [`material`] — the pointwise material seen by the kernels.
//! * [`dofs`], [`contribution`], [`body`], [`contact`] — boundary
//!   conditions as data and the contributions a step sums, with
//!   trial/commit/rollback history.
//! * [`self_contact`] — a 2D boundary's contact with itself (creases).
//! * [`surface`], [`motion`], [`tool`] — rigid tool surfaces in 2D and 3D
//!   and their motion along loading channels.
//! * [`system`], [`stepper`] — Newton (chord steps, line search) on a faer
//!   sparse LU that keeps its symbolic factorisation, apart from the
//!   stepper (channels along a path with time, cut-back, partial results).
//! * [`n1`], [`n3`], [`c1`], [`q1`] — the forward models; [`discretisation`] — the
//!   Richardson estimate of their discretisation error from one coarser solve.

// Index loops mirror the index notation of the equations; negated comparisons
// (`!(x > 0.0)`) deliberately treat NaN as failure.
#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::nonminimal_bool,
    clippy::collapsible_match
)]

pub mod body;
pub mod contact;
pub mod contact_split;
pub mod contribution;
pub mod discretisation;
pub mod dofs;
pub mod error;
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
pub mod shape;
pub mod sparse;
pub mod stepper;
pub mod surface;
pub mod system;
pub mod tool;
pub mod viscoelastic;
pub mod vtu;

pub use models::{c1, n1, n3, q1, r2, r2_gap, r2_scan};

pub use c1::{C1Fe, Platens};
pub use contact::ContactPoints;
pub use discretisation::{Coarser, ConvergenceOrder, ErrorEstimate};
pub use error::FeError;
pub use line_search::LineSearch;
pub use material::LawMaterial;
pub use model::{Bulk, Simulation};
pub use n1::{Base, MeshDensity, N1Element, N1Needle};
pub use n3::{n3_core_cells, n3_grading, n3_quadratic_grading, N3Element, N3Mesh, N3Needle};
pub use q1::viscous::Q1Viscous;
pub use q1::Q1Punch;
pub use r2::{r2_element_size, Nodule, R2Rolling};
pub use r2_gap::R2Gap;
pub use stepper::{LoadPath, Progress};
pub use surface::{Cylinder3d, Profile2d, Revolution3d, RigidSurface, SurfacePoint, Wheel2d};
pub use system::{RunStats, SolverOptions, System};
pub use tool::ToolShape;
pub use viscoelastic::{Prony, Viscoelastic};
