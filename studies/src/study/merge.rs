//! `palpate merge RUN_DIR`: once every shard of a run folder has finished
//! ([`crate::run::shard`]), runs the study over the cache they filled.

use crate::run::shard::check_complete;
use crate::run::step::RunObserver;
use crate::study::runner::{run_study_counted, RunOptions};
use anyhow::Context;
use std::path::{Path, PathBuf};

/// What a merge found and did.
#[derive(Debug, Clone)]
pub struct Merged {
    pub folder: PathBuf,
    pub shards: usize,
    /// Units the merge took from the cache.
    pub cached: usize,
    /// Units the merge computed itself (those of deferred steps).
    pub computed: usize,
}

/// Merges the shards of the run folder `out`: once every shard of one
/// count N has left its record and the manifest is unchanged since, runs
/// the study into `out` over the cache the shards filled (computing only
/// the units of steps the shards deferred). Errors say which shards are
/// missing, with the command that runs them.
pub fn merge(out: &Path, observer: &dyn RunObserver) -> anyhow::Result<Merged> {
    let (record, shards) = check_complete(out)?;
    let shown = out.display();
    let here = std::env::current_dir().context("cannot read the working directory")?;
    if record.manifest.is_relative() && here != record.cwd {
        anyhow::bail!(
            "run folder {shown}: the shards ran {} from {}; run `palpate merge` from there too \
             (the cache keys hold the data paths as the manifest gives them)",
            record.manifest.display(),
            record.cwd.display()
        );
    }
    let hash = crate::run::provenance::hash_file(&record.manifest)
        .with_context(|| format!("run folder {shown}: the shards' manifest"))?;
    anyhow::ensure!(
        record.manifest_sha256 == hash.sha256,
        "run folder {shown}: the shards ran {} with sha256 {}, but it now has sha256 {}; \
         run the shards again with the manifest as it is",
        record.manifest.display(),
        record.manifest_sha256,
        hash.sha256
    );
    let options = RunOptions {
        out: Some(out.to_path_buf()),
        fresh: false,
        shard: None,
    };
    let summary = run_study_counted(&record.manifest, &options, observer)?;
    Ok(Merged {
        folder: summary.folder,
        shards,
        cached: summary.units.cached,
        computed: summary.units.computed,
    })
}
