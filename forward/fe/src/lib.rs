//! # palpate-fe
//!
//! Axisymmetric large-deformation finite elements with frictional rigid-tool
//! contact, for the N1 needle-indentation and C1 compression benchmarks
//! (`BENCHMARKS.md`).
//!
//! See docs/architecture.md for the module map and how to add a model, kernel, surface or effect.
//! * [`kinematics`] — the kinematic idealisation (an enum owned by the element).
//! * [`element`] — the Q1/P0 (Simo-Taylor-Pister) mixed element.
//! * [`surface`] — rigid tool surfaces for 2D and 3D models behind one
//!   trait (revolved profiles, wheels, platens).
//! * [`motion`] — rigid tool motion (translation, rotation, rolling
//!   without slip) driven by loading channels, and the global projection.
//! * [`tool`] / [`contact`] — analytic rigid tools and augmented-Lagrangian
//!   Coulomb contact at surface nodes or edge Gauss points, with
//!   trial/commit history.
//! * [`material`] — the pointwise material seen by the element, with a
//!   five-component fast path for the laws written in invariants.
//! * [`solver`] — Newton-Raphson (modified: the LU is reused while it
//!   contracts the residual) with line search and automatic increments on a
//!   faer sparse LU that keeps its symbolic factorisation.
//! * [`n1`], [`c1`] — the forward models.

// Index loops mirror the index notation of the equations; negated comparisons
// (`!(x > 0.0)`) deliberately treat NaN as failure.
#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::nonminimal_bool,
    clippy::collapsible_match
)]

pub mod body;
pub mod c1;
pub mod contact;
pub mod contribution;
pub mod dofs;
pub mod error;
pub mod kernel;
pub mod kinematics;
pub mod material;
pub mod mesh;
pub mod model;
pub mod motion;
pub mod n1;
pub mod quadrature;
pub mod shape;
pub mod sparse;
pub mod stepper;
pub mod surface;
pub mod system;
pub mod tool;
pub mod vtu;

pub use c1::{C1Fe, Platens};
pub use contact::ContactPoints;
pub use error::FeError;
pub use material::LawMaterial;
pub use model::{Bulk, Simulation};
pub use n1::{Base, MeshDensity, N1Needle};
pub use stepper::{LoadPath, Progress};
pub use surface::{Cylinder3d, Profile2d, Revolution3d, RigidSurface, SurfacePoint, Wheel2d};
pub use system::{RunStats, SolverOptions, System};
pub use tool::ToolShape;
