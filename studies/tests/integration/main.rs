//! The integration tests of `palpate-studies`, one module per file, compiled into
//! one test binary: one link instead of one per file, and `cargo test` runs
//! the files' tests side by side on its threads instead of one binary after
//! another (the CI's test time; see `.ci/run`). Run one file's tests with
//! `cargo test -p palpate-studies --test integration FILE::`.
//! `run_folder` stays a binary of its own: its kills are timed against a
//! running process, and tests beside it in the same binary load the machine.

mod bad_input;
mod bad_input_benchmarks;
mod bad_input_manifests;
mod bad_input_messages;
mod cli;
mod common;
mod diagnose_homogeneous;
mod experiment_calibrate;
mod experiment_cli;
mod experiment_commands;
mod experiment_diagnose;
mod experiment_thickness;
mod homogeneous_kinds;
mod localize_coverage;
mod localize_pipeline;
mod localize_units;
mod manifest_properties;
mod mesa2011;
mod models;
mod phantom_database;
mod plan_cli;
mod real_data;
mod real_data_fits;
mod run_study;
mod sample_surrogate;
mod shards;
mod two_stage_q1;
