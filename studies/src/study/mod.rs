//! A study from its manifest to its run folder: the manifest ([`manifest`]),
//! the runner that checks it and runs its steps in order ([`runner`]), and
//! the merge of a sharded run ([`merge`]).

pub mod manifest;
pub mod merge;
pub mod runner;
