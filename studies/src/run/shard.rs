//! Shards of a study: `palpate run STUDY.toml --shard I/N` computes the
//! I-th of N deterministic slices of the study's independent units (the
//! fits of a calibrate step, the records of a diagnose step, the model runs
//! of a predict step, a two-stage identification, the FE runs and chains of
//! a sample step, the FE runs and posteriors of a localize step) into the
//! run folder's cache ([`crate::run::run_folder`]); `palpate merge RUN_DIR` then
//! runs the study over the filled cache and writes the same bytes as a run
//! in one process (a unit's record is the same JSON whichever process computed
//! it, and the results are assembled in the manifest's order).
//!
//! The slice: the k-th unit (in manifest order) of step s belongs to shard
//! (s + k) mod N, a round robin that depends on nothing but the manifest,
//! so every shard, on any machine, agrees on who computes what without
//! talking to the others. A step that needs the results of another step
//! (predict after calibrate, anova after predict) runs only when that
//! step's units are all in the cache: its units are spread over the shards
//! of a second pass (run the N shards again), or computed by the merge.
//!
//! Shards share the run folder under a shared lock (a full run or a merge
//! takes it exclusively); each leaves `.palpate/shards/I-of-N.json` with
//! what it computed, which `merge` checks before it runs.

use crate::run::output::write_json;
use crate::run::run_folder::STATE;
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One slice of N: `index` in `0..count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// `I/N` with `0 <= I < N` (the numbering of a Slurm job array,
    /// `--array=0-(N-1)`, `$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`).
    fn from_str(s: &str) -> Result<Shard, String> {
        let (i, n) = s.split_once('/').ok_or_else(|| {
            format!("`{s}`: expected I/N, the shard index I of N shards (0 <= I < N), e.g. 0/4")
        })?;
        let parse = |t: &str, what: &str| {
            t.trim().parse::<usize>().map_err(|_| {
                format!("`{s}`: the {what} `{t}` is not a whole number (expected I/N, e.g. 0/4)")
            })
        };
        let (index, count) = (parse(i, "shard index")?, parse(n, "shard count")?);
        if count == 0 {
            return Err(format!("`{s}`: the shard count must be at least 1"));
        }
        if index >= count {
            return Err(format!(
                "`{s}`: the shard index {index} is not below the shard count {count} (shards are numbered 0 to {})",
                count - 1
            ));
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// Whether this shard computes unit `k` of step `step`.
    pub fn owns(&self, step: usize, k: usize) -> bool {
        (step + k) % self.count == self.index
    }

    /// The file name of this shard's record (`I-of-N`).
    pub fn stem(&self) -> String {
        format!("{}-of-{}", self.index, self.count)
    }
}

/// The folder of the shards' records in a run folder.
pub fn records_dir(out: &Path) -> PathBuf {
    out.join(STATE).join("shards")
}

/// What one shard did (`.palpate/shards/I-of-N.json`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ShardRecord {
    /// `I/N`.
    pub shard: String,
    /// The manifest, as given on the command line (the cache keys hold the
    /// data paths as the manifest gives them, relative to this path).
    pub manifest: PathBuf,
    /// The shard's working directory (the merge runs from the same one).
    pub cwd: PathBuf,
    /// SHA-256 of the manifest's bytes.
    pub manifest_sha256: String,
    /// Units this shard computed.
    pub computed: usize,
    /// Units it found in the cache.
    pub cached: usize,
    /// Units of other shards it did not find in the cache.
    pub others: usize,
    /// Steps it could not run for want of another step's results.
    pub deferred_steps: Vec<String>,
}

impl ShardRecord {
    pub fn write(&self, out: &Path, shard: Shard) -> anyhow::Result<()> {
        write_json(
            &records_dir(out).join(format!("{}.json", shard.stem())),
            self,
        )
    }
}

/// The record of shard 0 of the largest N whose shards have all finished
/// (their records agreeing on the manifest), and N.
pub fn check_complete(out: &Path) -> anyhow::Result<(ShardRecord, usize)> {
    let dir = records_dir(out);
    let shown = out.display();
    anyhow::ensure!(
        out.is_dir(),
        "run folder {shown}: does not exist (give the --out of the shards)"
    );
    let mut records: Vec<(Shard, ShardRecord)> = Vec::new();
    if let Ok(entries) = std::fs::read_dir(&dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let Some(stem) = name.strip_suffix(".json") else {
                continue;
            };
            let Some(shard) = stem
                .split_once("-of-")
                .and_then(|(i, n)| format!("{i}/{n}").parse::<Shard>().ok())
            else {
                continue;
            };
            let text = std::fs::read(e.path())
                .with_context(|| format!("cannot read {}", e.path().display()))?;
            let record: ShardRecord = serde_json::from_slice(&text)
                .with_context(|| format!("{}: not a shard record", e.path().display()))?;
            records.push((shard, record));
        }
    }
    anyhow::ensure!(
        !records.is_empty(),
        "run folder {shown}: no shard has finished in it (no {}/I-of-N.json); run the shards first: \
         palpate run STUDY.toml --out {shown} --shard I/N for I = 0 .. N-1",
        dir.display()
    );
    // The largest N whose shards are all there (an earlier sharding of the
    // same folder with another N may have left records too).
    let mut counts: Vec<usize> = records.iter().map(|(s, _)| s.count).collect();
    counts.sort_unstable();
    counts.dedup();
    let mut missing_text = Vec::new();
    for &n in counts.iter().rev() {
        let mut of_n: Vec<&(Shard, ShardRecord)> =
            records.iter().filter(|(s, _)| s.count == n).collect();
        of_n.sort_by_key(|(s, _)| s.index);
        let missing: Vec<String> = (0..n)
            .filter(|i| !of_n.iter().any(|(s, _)| s.index == *i))
            .map(|i| format!("{i}/{n}"))
            .collect();
        if !missing.is_empty() {
            missing_text.push(format!(
                "of {n} shards, {} not finished ({})",
                missing.len(),
                missing.join(", ")
            ));
            continue;
        }
        let first = &of_n[0].1;
        for (s, r) in &of_n {
            anyhow::ensure!(
                r.manifest == first.manifest
                    && r.cwd == first.cwd
                    && r.manifest_sha256 == first.manifest_sha256,
                "run folder {shown}: shard {s} ran {} (sha256 {}) from {}, shard 0/{n} ran {} (sha256 {}) from {}; \
                 the shards of one folder run one manifest",
                r.manifest.display(),
                r.manifest_sha256,
                r.cwd.display(),
                first.manifest.display(),
                first.manifest_sha256,
                first.cwd.display()
            );
        }
        return Ok((first.clone(), n));
    }
    anyhow::bail!(
        "run folder {shown}: {}; run them (palpate run STUDY.toml --out {shown} --shard I/N) before merging",
        missing_text.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_refuses_with_the_reason() {
        assert_eq!(
            "1/3".parse::<Shard>().unwrap(),
            Shard { index: 1, count: 3 }
        );
        for (bad, says) in [
            ("3/2", "not below the shard count 2"),
            ("2/2", "numbered 0 to 1"),
            ("0/0", "at least 1"),
            ("x", "expected I/N"),
            ("a/2", "shard index `a`"),
            ("1/-2", "shard count `-2`"),
            ("", "expected I/N"),
        ] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn every_unit_has_exactly_one_owner_and_the_load_is_even() {
        for n in 1..6 {
            let shards: Vec<Shard> = (0..n).map(|index| Shard { index, count: n }).collect();
            let mut load = vec![0; n];
            for step in 0..4 {
                for k in 0..13 {
                    let owners: Vec<usize> = shards
                        .iter()
                        .filter(|s| s.owns(step, k))
                        .map(|s| s.index)
                        .collect();
                    assert_eq!(owners.len(), 1);
                    load[owners[0]] += 1;
                }
            }
            let (lo, hi) = (load.iter().min().unwrap(), load.iter().max().unwrap());
            assert!(hi - lo <= 4, "{load:?}");
        }
    }
}
