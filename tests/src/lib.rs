//! Cross-crate verification of palpate: the integration tests in `tests/`
//! check forward models against each other and against independent
//! references, through the same trait objects the estimators use.
//!
//! Helpers shared by those tests live here.

use std::path::PathBuf;

/// Path of a file in the shared folder beside the workspace (`../shared`).
pub fn shared(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared")
        .join(rel)
}
