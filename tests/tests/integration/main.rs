//! The integration tests of `palpate-tests`, one module per file, compiled into
//! one test binary: one link instead of one per file, and `cargo test` runs
//! the files' tests side by side on its threads instead of one binary after
//! another (the CI's test time; see `.ci/run`). Run one file's tests with
//! `cargo test -p palpate-tests --test integration FILE::`.

mod c1_recovery;
mod fe_mesh_convergence;
mod gap_dev;
mod gap_fe_effects;
mod gap_n1;
mod gap_sets;
mod gap_v2;
mod trait_objects;
mod treloar_fits;
