//! # palpate-studies
//!
//! Everything a user touches: study manifests and their runner, reports,
//! SVG plots, VTK output wiring, and the `palpate` command-line tool (one
//! module per subcommand under [`cli`]).

pub mod anova_step;
pub mod arrays;
pub mod calibrate_step;
pub mod calibration;
pub mod checks;
pub mod cli;
pub mod columns;
pub mod diagnose_step;
pub mod limits;
pub mod localize;
pub mod localize_step;
pub mod manifest;
pub mod model_defaults;
pub mod model_fields;
pub mod models;
pub mod output;
pub mod plot;
pub mod predict_step;
pub mod provenance;
pub mod report;
pub mod run_folder;
pub mod runner;
pub mod sample_step;
pub mod shard;
pub mod surrogate;
pub mod two_stage;
pub mod two_stage_mesh_check;
pub mod two_stage_profile;
pub mod two_stage_ramp;
pub mod two_stage_report;
pub mod two_stage_step;
