//! # palpate-studies
//!
//! Everything a user touches: study manifests and their runner, reports,
//! SVG plots, VTK output wiring, and the `palpate` command-line tool (one
//! module per subcommand under [`cli`]).

pub mod calibration;
pub mod cli;
pub mod limits;
pub mod manifest;
pub mod models;
pub mod output;
pub mod plot;
pub mod provenance;
pub mod report;
pub mod runner;
pub mod surrogate;
