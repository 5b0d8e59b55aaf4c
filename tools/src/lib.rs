//! Helpers shared by the developer programs in `src/bin/` (see `Cargo.toml`
//! for what each is): where the repository is, and the CPU time of the
//! running process.

use std::path::PathBuf;

/// CPU time of the running process (the same function the FE benches use).
#[path = "../../forward/fe/examples/common/cpu.rs"]
pub mod cpu;

/// A path inside the repository, from its root (`rel` such as
/// `"tests/data/gap-n1"`), whatever the working directory.
pub fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(rel)
}
