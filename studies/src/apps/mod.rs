//! Applications built on the models and the estimators, each with its own
//! step kind and command: the staged inverse FE identification of a Q1
//! record ([`two_stage`]) and the localisation of nodules under a rolling
//! wheel ([`localize`]).

pub mod localize;
pub mod two_stage;
