//! Run infrastructure, blind to step kinds: the run folder and its cache of
//! units ([`run_folder`]), shards ([`shard`]), atomic outputs ([`output`]),
//! provenance ([`provenance`]), size limits and progress ([`limits`]),
//! plausibility checks of user values ([`checks`]), the posterior
//! surrogate's cache ([`surrogate`]), and what a study step is ([`step`]:
//! the [`step::Step`] trait and the [`step::Run`] every step runs in).

pub mod checks;
pub mod limits;
pub mod output;
pub mod provenance;
pub mod run_folder;
pub mod shard;
pub mod step;
pub mod surrogate;
