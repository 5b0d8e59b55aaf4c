//! `provenance.json`: what a run was made from, so it can be reproduced and
//! audited (manifest and data hashes, git commit, crate versions, seed,
//! thread count). Timestamps and timings live here, never in `results.json`,
//! which must be byte-identical on a rerun.

use serde::Serialize;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::Path;

/// The lock file the binary was built with, for the versions of the key crates.
const CARGO_LOCK: &str = include_str!("../../../Cargo.lock");

/// Crates whose versions are recorded.
const KEY_CRATES: [&str; 9] = [
    "faer", "nalgebra", "argmin", "statrs", "rand", "rayon", "serde", "toml", "clap",
];

/// Provenance of one run.
#[derive(Debug, Clone, Serialize)]
pub struct Provenance {
    pub palpate_version: String,
    pub manifest: FileHash,
    pub data: Vec<FileHash>,
    pub git_commit: String,
    pub git_dirty: bool,
    pub crate_versions: BTreeMap<String, String>,
    pub seed: u64,
    pub threads: usize,
    pub started_unix_s: u64,
    pub wall_time_s: f64,
    pub command_line: Vec<String>,
}

/// A file and the SHA-256 of its bytes.
#[derive(Debug, Clone, Serialize)]
pub struct FileHash {
    pub path: String,
    pub sha256: String,
}

/// Hashes a file; the error names it.
pub fn hash_file(path: &Path) -> anyhow::Result<FileHash> {
    let bytes =
        std::fs::read(path).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    Ok(FileHash {
        path: path.display().to_string(),
        sha256: hex(&Sha256::digest(&bytes)),
    })
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The versions of the key crates from the embedded Cargo.lock.
pub fn crate_versions() -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let mut name: Option<&str> = None;
    for line in CARGO_LOCK.lines() {
        if let Some(n) = line.strip_prefix("name = ") {
            name = Some(n.trim_matches('"'));
        } else if let Some(v) = line.strip_prefix("version = ") {
            if let Some(n) = name.take() {
                if KEY_CRATES.contains(&n) || n.starts_with("palpate-") {
                    // Several versions of one crate may be locked; keep them all.
                    let v = v.trim_matches('"').to_string();
                    out.entry(n.to_string())
                        .and_modify(|e: &mut String| {
                            if !e.split(", ").any(|x| x == v) {
                                e.push_str(", ");
                                e.push_str(&v);
                            }
                        })
                        .or_insert(v);
                }
            }
        }
    }
    out
}

/// The git commit of the working directory (or "unknown") and whether it has
/// uncommitted changes.
pub fn git_state() -> (String, bool) {
    let run = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let commit = run(&["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
    let dirty =
        run(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
    (commit, dirty)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn lock_file_versions_are_found() {
        let v = crate_versions();
        assert!(
            v.contains_key("faer") && v.contains_key("palpate-core"),
            "{v:?}"
        );
    }
    #[test]
    fn hash_is_sha256() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a");
        std::fs::write(&p, b"abc").unwrap();
        assert_eq!(
            hash_file(&p).unwrap().sha256,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
