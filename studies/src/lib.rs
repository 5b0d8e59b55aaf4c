//! # palpate-studies
//!
//! Everything a user touches: study manifests and their runner, the step
//! kinds, the model specs, reports and plots, two applications and the
//! `palpate` command-line tool. The folders, from the bottom up (each uses
//! only the ones above it in this list, never `cli`):
//!
//! | folder | holds |
//! |---|---|
//! | [`records`] | the record vocabulary: test kinds, a record read for one test, reading options, columns, records given as arrays |
//! | [`model`] | one model spec and one factory for every forward model, field parsers and defaults, a manifest's named models, and the calibration service (fit a law to records) |
//! | [`report`] | report text and SVG plots |
//! | [`run`] | run infrastructure blind to step kinds: the run folder and its cache of units, shards, outputs, provenance, limits, checks, the posterior surrogate's cache, and the [`run::step::Step`] trait |
//! | [`apps`] | applications: two-stage Q1 identification, R2 localisation |
//! | [`steps`] | one file per step kind, and the registry a manifest's steps are read into |
//! | [`study`] | the manifest, the runner that checks it and runs its steps, the merge of shards |
//! | [`api`] | the typed library API (typed options and results, nothing printed) that the command line and the Python package call |
//! | [`cli`] | the `palpate` command: one module per subcommand |
//!
//! A new step kind is a file in `steps/` implementing [`run::step::Step`]
//! and one line in the registry of [`steps`].

pub mod api;
pub mod apps;
pub mod cli;
pub mod model;
pub mod records;
pub mod report;
pub mod run;
pub mod steps;
pub mod study;
