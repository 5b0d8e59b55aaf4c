//! The integration tests of `palpate-fe`, one module per file, compiled into
//! one test binary: one link instead of one per file, and `cargo test` runs
//! the files' tests side by side on its threads instead of one binary after
//! another (the CI's test time; see `.ci/run`). Run one file's tests with
//! `cargo test -p palpate-fe --test integration FILE::`.

mod bad_input;
mod c1_bonded;
mod c1_frictionless;
mod c1_viscoelastic;
mod closed_form_experiments;
mod hertz;
mod mesh_gmsh;
mod n1_needle;
mod n3_needle;
mod patch;
mod q1_punch;
mod r2_rolling;
mod regions;
mod regression_original_solver;
mod sensitivity;
mod sensitivity_friction;
