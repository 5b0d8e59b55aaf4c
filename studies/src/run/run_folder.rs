//! The run folder of `palpate run`: staged, locked, marked when incomplete,
//! and resumable.
//!
//! ```text
//! runs/<study>/
//!   results.json report.md provenance.json plots/*.svg   the last complete run
//!   INCOMPLETE            present while the folder does not hold a complete run
//!   .palpate/lock         held (flock) by the run writing the folder; holds its pid
//!   .palpate/staging/     the run in progress (removed when it is swapped in)
//!   .palpate/cache/       one file per finished unit (a fit, a diagnosed record),
//!                         named by the SHA-256 of the unit's inputs
//!   .palpate/files.json   the files of the last complete run
//! ```
//!
//! The folder holds a complete run when `.palpate/files.json` exists and
//! `INCOMPLETE` does not ([`RunFolder::is_complete`]); `INCOMPLETE` is the
//! mark a person sees (a run killed in the few instructions before it is
//! written leaves no result file and no `files.json`).
//!
//! A run writes everything into the staging folder and, at the end, moves its
//! files into the folder and removes those of the previous run that it did
//! not write again (a smaller study into the same folder leaves no file of
//! the larger one). While it computes, the previous complete run stays as it
//! was; `INCOMPLETE` marks the folder from the start of the swap until its
//! end, and from the start when there was no complete run. A run killed at
//! any point (SIGINT, SIGKILL) leaves its finished units in the cache: the
//! same command resumes from them and writes a byte-identical results.json.
//! The lock is an advisory `flock`, released by the system when its process
//! dies, so a killed run never leaves a stale lock.

use crate::run::output::{check_writable, is_temp_name, write_atomic, write_json};
use anyhow::Context;
use sha2::{Digest, Sha256};
use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The hidden state folder inside a run folder.
pub const STATE: &str = ".palpate";
/// The marker of a folder that does not hold a complete run.
pub const INCOMPLETE: &str = "INCOMPLETE";
/// The prefix of a shard's scratch folder in [`STATE`] (its plots and
/// report, thrown away).
pub const SHARD_SCRATCH: &str = "shard-scratch";
/// Bumped when the cached records change shape (old entries are then unused).
const CACHE_FORMAT: u32 = 1;

/// An open run folder: locked for this process until it is dropped.
pub struct RunFolder {
    out: PathBuf,
    staging: PathBuf,
    cache: PathBuf,
    files: PathBuf,
    // Held for the life of the run; released on drop or when the process dies.
    _lock: File,
}

impl RunFolder {
    /// Opens (creating it if needed) and locks the run folder `out`, removes
    /// what an interrupted run left there (its staging folder, temporary
    /// files) and, with `fresh`, the cache of finished units.
    ///
    /// Refused, naming `out`: a file; a non-empty folder that is not a run
    /// folder (so that `--out .` cannot swap files into a user's folder); a
    /// folder that cannot be written; a folder another run holds (with that
    /// run's pid).
    pub fn open(out: &Path, fresh: bool) -> anyhow::Result<RunFolder> {
        let shown = out.display();
        if out.exists() && !out.is_dir() {
            anyhow::bail!("run folder {shown}: is a file; give a folder with --out");
        }
        if out.is_dir() && !is_empty(out)? && !is_run_folder(out) {
            anyhow::bail!(
                "run folder {shown}: exists, is not empty and is not a palpate run folder (no {STATE}/ or provenance.json in it); \
                 give a new or empty folder with --out so that nothing of yours is replaced"
            );
        }
        check_writable("run folder", out, true)?;
        let state = out.join(STATE);
        std::fs::create_dir_all(&state)
            .with_context(|| format!("cannot create run folder {}", state.display()))?;
        let lock = lock(&state.join("lock"), out)?;
        let folder = RunFolder {
            out: out.to_path_buf(),
            staging: state.join("staging"),
            cache: state.join("cache"),
            files: state.join("files.json"),
            _lock: lock,
        };
        // What an interrupted run left: its staging folder and its temporary
        // files (any temporary file is stale: this process holds the lock).
        if folder.staging.exists() {
            std::fs::remove_dir_all(&folder.staging)
                .with_context(|| format!("cannot remove the stale {}", folder.staging.display()))?;
        }
        // Scratch folders of killed shards (shards run only under a shared lock).
        if let Ok(entries) = std::fs::read_dir(&state) {
            for e in entries.flatten() {
                if e.file_name().to_string_lossy().starts_with(SHARD_SCRATCH) {
                    std::fs::remove_dir_all(e.path()).ok();
                }
            }
        }
        if fresh && folder.cache.exists() {
            std::fs::remove_dir_all(&folder.cache)
                .with_context(|| format!("cannot remove {}", folder.cache.display()))?;
        }
        for dir in [out, &out.join("plots"), &state, &folder.cache] {
            remove_temps(dir);
        }
        for dir in [&folder.staging.join("plots"), &folder.cache] {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
        }
        if !folder.is_complete() {
            folder.mark_incomplete()?;
        }
        Ok(folder)
    }

    /// Opens the run folder `out` for shard `shard` ([`crate::run::shard`]):
    /// under a shared lock (shards run side by side; a full run or a merge
    /// waits for none of them and is refused while one runs), creating the
    /// folder and its cache if needed, marking a new folder incomplete. It
    /// removes nothing: the temporary files may be other shards' writes.
    pub fn open_shared(out: &Path, shard: crate::run::shard::Shard) -> anyhow::Result<RunFolder> {
        let shown = out.display();
        if out.exists() && !out.is_dir() {
            anyhow::bail!("run folder {shown}: is a file; give a folder with --out");
        }
        if out.is_dir() && !is_empty(out)? && !is_run_folder(out) {
            anyhow::bail!(
                "run folder {shown}: exists, is not empty and is not a palpate run folder (no {STATE}/ or provenance.json in it); \
                 give a new or empty folder with --out so that nothing of yours is replaced"
            );
        }
        check_writable("run folder", out, true)?;
        let state = out.join(STATE);
        let cache = state.join("cache");
        std::fs::create_dir_all(&cache)
            .with_context(|| format!("cannot create run folder {}", cache.display()))?;
        let lock = lock_shared(&state.join("lock"), out, shard)?;
        let folder = RunFolder {
            out: out.to_path_buf(),
            staging: state.join("staging"),
            cache,
            files: state.join("files.json"),
            _lock: lock,
        };
        if !folder.is_complete() {
            folder.mark_incomplete()?;
        }
        Ok(folder)
    }

    /// Where this run writes its files (`results.json`, `plots/...`).
    pub fn staging(&self) -> &Path {
        &self.staging
    }

    /// Whether the folder holds a complete run.
    pub fn is_complete(&self) -> bool {
        self.files.is_file() && !self.out.join(INCOMPLETE).exists()
    }

    fn mark_incomplete(&self) -> anyhow::Result<()> {
        write_atomic(
            &self.out.join(INCOMPLETE),
            format!(
                "This run folder does not hold a complete run: `palpate run` (pid {}) was writing it \
                 and did not finish (interrupted, killed or failed).\n\
                 Run the same command again: the finished fits and diagnoses are taken from {STATE}/cache \
                 and only the rest is computed.\n",
                std::process::id()
            )
            .as_bytes(),
        )
    }

    /// The cache key of a unit: SHA-256 of the cache format, palpate's
    /// version and the unit's inputs (their `Debug` text: names, settings
    /// and every data value).
    pub fn key(inputs: &impl std::fmt::Debug) -> String {
        let text = format!("{CACHE_FORMAT} {} {inputs:?}", env!("CARGO_PKG_VERSION"));
        format!("{:x}", Sha256::digest(text.as_bytes()))
    }

    /// A finished unit's record, if cached and readable (an unreadable one
    /// is computed again).
    pub fn cached<T: serde::de::DeserializeOwned>(&self, key: &str) -> Option<T> {
        let text = std::fs::read(self.cache.join(format!("{key}.json"))).ok()?;
        serde_json::from_slice(&text).ok()
    }

    /// Whether a unit's record is in the cache.
    pub fn has(&self, key: &str) -> bool {
        self.cache.join(format!("{key}.json")).is_file()
    }

    /// Stores a finished unit's record (atomically: a kill never leaves half a record).
    pub fn store<T: serde::Serialize>(&self, key: &str, record: &T) -> anyhow::Result<()> {
        write_json(&self.cache.join(format!("{key}.json")), record)
    }

    /// Swaps the staged run in: moves its files into the folder, removes
    /// the files of the previous run it did not write, records the list and
    /// removes the `INCOMPLETE` mark. Returns the folder.
    pub fn commit(self) -> anyhow::Result<PathBuf> {
        self.mark_incomplete()?;
        let new = list_files(&self.staging)?;
        for old in self.previous_files() {
            if !new.contains(&old) {
                match std::fs::remove_file(self.out.join(&old)) {
                    Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                        return Err(e).with_context(|| {
                            format!("cannot remove {}", self.out.join(&old).display())
                        })
                    }
                    _ => {}
                }
            }
        }
        for f in &new {
            let to = self.out.join(f);
            if let Some(dir) = to.parent() {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("cannot create {}", dir.display()))?;
            }
            std::fs::rename(self.staging.join(f), &to)
                .with_context(|| format!("cannot move the result into {}", to.display()))?;
        }
        write_json(&self.files, &new)?;
        std::fs::remove_dir_all(&self.staging).ok();
        let plots = self.out.join("plots");
        if list_files(&plots).is_ok_and(|l| l.is_empty()) {
            std::fs::remove_dir(&plots).ok();
        }
        std::fs::remove_file(self.out.join(INCOMPLETE))
            .with_context(|| format!("cannot remove {}", self.out.join(INCOMPLETE).display()))?;
        Ok(self.out.clone())
    }

    /// The files of the previous complete run (relative paths): its record,
    /// or for a folder written before records were kept, the files a run
    /// writes (results, report, provenance and the plots).
    fn previous_files(&self) -> Vec<String> {
        if let Some(list) = std::fs::read(&self.files)
            .ok()
            .and_then(|t| serde_json::from_slice::<Vec<String>>(&t).ok())
        {
            return list.into_iter().filter(|f| is_plain_relative(f)).collect();
        }
        let mut list: Vec<String> = ["results.json", "report.md", "provenance.json"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        if let Ok(plots) = list_files(&self.out.join("plots")) {
            list.extend(
                plots
                    .into_iter()
                    .filter(|p| p.ends_with(".svg"))
                    .map(|p| format!("plots/{p}")),
            );
        }
        list
    }
}

/// Takes the lock file's advisory lock, or names the process that holds it.
fn lock(path: &Path, out: &Path) -> anyhow::Result<File> {
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .with_context(|| format!("cannot open the lock file {}", path.display()))?;
    match file.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            // The holder writes its pid right after locking: give it a moment.
            let mut pid = String::new();
            for _ in 0..20 {
                pid.clear();
                file.rewind().ok();
                file.read_to_string(&mut pid).ok();
                if !pid.trim().is_empty() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            let holder = match pid.trim() {
                "" => "another palpate process".to_string(),
                p => format!("another palpate process (pid {p})"),
            };
            let holder = match running_shards(out) {
                s if s.is_empty() => holder,
                s => format!(
                    "{holder} or the shards {} (palpate run --shard)",
                    s.join(", ")
                ),
            };
            anyhow::bail!(
                "run folder {}: {holder} is writing it (lock {}); wait until it finishes, or give another --out",
                out.display(),
                path.display()
            );
        }
        Err(std::fs::TryLockError::Error(e)) => {
            return Err(e).with_context(|| format!("cannot lock {}", path.display()))
        }
    }
    file.set_len(0)
        .and_then(|_| file.rewind())
        .and_then(|_| writeln!(file, "{}", std::process::id()))
        .with_context(|| format!("cannot write the lock file {}", path.display()))?;
    Ok(file)
}

/// Takes the lock file's shared lock for a shard (refused while a full run
/// holds it exclusively), and marks the shard running (its pid in
/// `.palpate/shards/I-of-N.running` while the process lives).
fn lock_shared(path: &Path, out: &Path, shard: crate::run::shard::Shard) -> anyhow::Result<File> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .with_context(|| format!("cannot open the lock file {}", path.display()))?;
    match file.try_lock_shared() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            let pid = std::fs::read_to_string(path).unwrap_or_default();
            let holder = match pid.trim() {
                "" => "another palpate process".to_string(),
                p => format!("another palpate process (pid {p})"),
            };
            anyhow::bail!(
                "run folder {}: {holder} is running the whole study in it (lock {}); shard {shard} waits until it finishes",
                out.display(),
                path.display()
            );
        }
        Err(std::fs::TryLockError::Error(e)) => {
            return Err(e).with_context(|| format!("cannot lock {}", path.display()))
        }
    }
    let running = crate::run::shard::records_dir(out).join(format!("{}.running", shard.stem()));
    write_atomic(&running, format!("{}\n", std::process::id()).as_bytes())?;
    Ok(file)
}

/// The shards marked running in `out` whose process still lives (their
/// `I/N`, with the pid).
fn running_shards(out: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(crate::run::shard::records_dir(out)) else {
        return Vec::new();
    };
    let mut list = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix(".running") else {
            continue;
        };
        let pid = std::fs::read_to_string(e.path()).unwrap_or_default();
        let pid = pid.trim();
        if !pid.is_empty() && Path::new("/proc").join(pid).exists() {
            list.push(format!("{} (pid {pid})", stem.replace("-of-", "/")));
        }
    }
    list.sort();
    list
}

/// A folder a run has written (or is writing).
fn is_run_folder(dir: &Path) -> bool {
    dir.join(STATE).is_dir() || dir.join("provenance.json").is_file()
}

/// Whether `dir` holds nothing but another palpate process's write probe
/// ([`check_writable`]'s). Asked BEFORE [`is_run_folder`]: shards started
/// at once into a new folder race, and a folder seen non-empty because
/// another shard has just created its state folder must then be seen as a
/// run folder (asked the other way round, a shard saw neither state folder
/// nor emptiness and refused the folder; the Python guide's Dask block hit
/// it).
fn is_empty(dir: &Path) -> anyhow::Result<bool> {
    let mut entries =
        std::fs::read_dir(dir).with_context(|| format!("cannot read {}", dir.display()))?;
    Ok(entries.all(|e| {
        e.map(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(crate::run::output::WRITE_PROBE)
        })
        .unwrap_or(false)
    }))
}

/// A relative path without `..` or a root (a record from disk is not trusted
/// to name files outside the folder).
fn is_plain_relative(f: &str) -> bool {
    let p = Path::new(f);
    !f.is_empty()
        && p.components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
}

/// Removes the temporary files of [`crate::run::output::write_atomic`] in `dir`.
fn remove_temps(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        if e.file_name().to_str().is_some_and(is_temp_name) && e.path().is_file() {
            std::fs::remove_file(e.path()).ok();
        }
    }
}

/// Every file under `dir`, as sorted relative paths with `/` separators.
fn list_files(dir: &Path) -> anyhow::Result<Vec<String>> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) -> std::io::Result<()> {
        for e in std::fs::read_dir(dir)? {
            let e = e?;
            let p = e.path();
            if e.file_type()?.is_dir() {
                walk(root, &p, out)?;
            } else if let Ok(rel) = p.strip_prefix(root) {
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push(parts.join("/"));
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out).with_context(|| format!("cannot list {}", dir.display()))?;
    out.sort();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Shards started at the same instant into a folder that does not exist
    /// yet, or exists empty, all open it (none sees it half-made and
    /// refuses it as a user's folder).
    #[test]
    fn shards_started_at_once_all_open_a_new_folder() {
        for trial in 0..40 {
            let dir = tempfile::tempdir().unwrap();
            let out = dir.path().join("run");
            if trial % 2 == 1 {
                std::fs::create_dir(&out).unwrap();
            }
            let n = 4;
            let barrier = std::sync::Barrier::new(n);
            std::thread::scope(|s| {
                let handles: Vec<_> = (0..n)
                    .map(|i| {
                        let (out, barrier) = (&out, &barrier);
                        s.spawn(move || {
                            barrier.wait();
                            let shard = format!("{i}/{n}").parse().unwrap();
                            RunFolder::open_shared(out, shard).map(drop)
                        })
                    })
                    .collect();
                for h in handles {
                    let r = h.join().unwrap();
                    assert!(r.is_ok(), "trial {trial}: {}", r.err().unwrap());
                }
            });
        }
    }

    #[test]
    fn a_second_open_is_refused_naming_the_holder_and_a_drop_releases() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let first = RunFolder::open(&out, false).unwrap();
        let e = RunFolder::open(&out, false).err().unwrap().to_string();
        assert!(
            e.contains(&format!("pid {}", std::process::id())) && e.contains("run folder"),
            "{e}"
        );
        drop(first);
        RunFolder::open(&out, false).unwrap();
    }

    #[test]
    fn a_user_folder_is_not_taken_over() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("notes.txt"), "mine").unwrap();
        let e = RunFolder::open(dir.path(), false)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("not a palpate run folder"), "{e}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn commit_swaps_in_the_new_files_and_removes_the_old_ones() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let f = RunFolder::open(&out, false).unwrap();
        assert!(out.join(INCOMPLETE).is_file());
        for p in ["results.json", "plots/a.svg", "plots/b.svg"] {
            write_atomic(&f.staging().join(p), p.as_bytes()).unwrap();
        }
        f.commit().unwrap();
        assert!(out.join("plots/b.svg").is_file() && !out.join(INCOMPLETE).exists());
        let f = RunFolder::open(&out, false).unwrap();
        assert!(f.is_complete() && !out.join(INCOMPLETE).exists());
        write_atomic(&f.staging().join("results.json"), b"2").unwrap();
        write_atomic(&f.staging().join("plots/a.svg"), b"2").unwrap();
        f.commit().unwrap();
        assert!(!out.join("plots/b.svg").exists(), "old plot kept");
        assert_eq!(std::fs::read(out.join("plots/a.svg")).unwrap(), b"2");
        assert!(!out.join(STATE).join("staging").exists());
    }

    #[test]
    fn keys_differ_with_the_inputs() {
        assert_eq!(RunFolder::key(&("a", 1.0)), RunFolder::key(&("a", 1.0)));
        assert_ne!(
            RunFolder::key(&("a", 1.0)),
            RunFolder::key(&("a", 1.0 + 1e-15))
        );
    }
}
