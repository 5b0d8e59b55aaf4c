//! Designed experiments: full factorial designs with any number of factors
//! and levels, two-level fractional factorials 2^(k-p) from generators with
//! their defining relation, resolution and alias structure, replicates, and a
//! run order randomised from a seed.
//!
//! A [`Design`] is a list of [`Run`]s, each holding a level index per factor;
//! level names come from the [`Factor`]s. Running a design (mapping each run
//! to a configuration and collecting a response) belongs to the studies layer.

mod design;
mod error;
mod factor;
mod fractional;

pub use design::{Design, Run, MAX_RUNS};
pub use error::DoeError;
pub use factor::Factor;
pub use fractional::{AliasChain, Generator, Word};
