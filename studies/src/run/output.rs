//! The one writer of result files, used by every command:
//!
//! * [`write_atomic`] writes to a temporary file in the same directory, then
//!   renames it, so an interrupted run never leaves a truncated or lost
//!   result file. The file gets the permissions of the user's umask (as
//!   `touch` would: 0666 masked), not the 0600 of a private temporary file.
//!   The temporary file is named `.<name>.<pid>.<random>.tmp`; one left
//!   behind by a process that no longer runs (killed by SIGKILL) is removed
//!   by the next write of the same file.
//! * [`check_outputs`] checks, before any work, every output location of a
//!   command: not an input file, not another output, and writable.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Suffix of the temporary files of [`write_atomic`].
pub const TEMP_SUFFIX: &str = ".tmp";

/// Writes `bytes` to `path` atomically (temp file + rename), creating the
/// parent directory if needed. Errors name the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    use anyhow::Context;
    let dir = parent_of(path);
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let name = path
        .file_name()
        .ok_or_else(|| anyhow::anyhow!("{}: not a file name", path.display()))?
        .to_string_lossy()
        .into_owned();
    remove_stale_temps(dir, Some(&name));
    let prefix = format!(".{name}.{}.", std::process::id());
    let mut tmp = temp_builder(&prefix)
        .tempfile_in(dir)
        .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
    tmp.write_all(bytes)
        .with_context(|| format!("cannot write {}", path.display()))?;
    tmp.as_file().sync_all().ok();
    tmp.persist(path).map_err(|e| {
        anyhow::anyhow!(
            "cannot move the result into {}: {}",
            path.display(),
            e.error
        )
    })?;
    Ok(())
}

/// Serialises `value` as pretty JSON (with a trailing newline) and writes it atomically.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    let mut s = serde_json::to_string_pretty(value)?;
    s.push('\n');
    write_atomic(path, s.as_bytes())
}

/// The directory a file is written in (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// A temporary-file builder: `<prefix>XXXXXX.tmp`, created 0666 less the
/// umask (tempfile's default, 0600, would make every result private).
fn temp_builder(prefix: &str) -> tempfile::Builder<'_, 'static> {
    let mut b = tempfile::Builder::new();
    b.prefix(prefix).suffix(TEMP_SUFFIX);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b
}

/// Whether a process with this id runs (on Linux, `/proc/<pid>` exists;
/// elsewhere every process is taken to run, so nothing is removed).
pub fn process_runs(pid: u32) -> bool {
    let proc_dir = Path::new("/proc");
    !proc_dir.join("self").exists() || proc_dir.join(pid.to_string()).exists()
}

/// The process id in a temporary file name of [`write_atomic`]
/// (`.<name>.<pid>.XXXXXX.tmp`), with the name it stands for.
fn temp_owner(file: &str) -> Option<(&str, u32)> {
    let inner = file.strip_prefix('.')?.strip_suffix(TEMP_SUFFIX)?;
    let (rest, _random) = inner.rsplit_once('.')?;
    let (name, pid) = rest.rsplit_once('.')?;
    Some((name, pid.parse().ok()?))
}

/// Whether a file name is one of the temporary files of [`write_atomic`].
pub fn is_temp_name(file: &str) -> bool {
    temp_owner(file).is_some()
}

/// Removes the temporary files in `dir` (of file `only`, or of any file)
/// whose writing process no longer runs. Returns how many were removed.
pub fn remove_stale_temps(dir: &Path, only: Option<&str>) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for e in entries.flatten() {
        let file = e.file_name();
        let Some((name, pid)) = file.to_str().and_then(temp_owner) else {
            continue;
        };
        if only.is_some_and(|o| o != name) || process_runs(pid) {
            continue;
        }
        if std::fs::remove_file(e.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// A path as the file system sees it, for comparing: canonical when it
/// exists, else its canonical parent joined with its name.
fn identity(p: &Path) -> PathBuf {
    if let Ok(c) = p.canonicalize() {
        return c;
    }
    match (parent_of(p).canonicalize(), p.file_name()) {
        (Ok(d), Some(n)) => d.join(n),
        _ => p.to_path_buf(),
    }
}

/// The outputs that were asked for, as `(option, path)`.
pub fn given<'a>(list: &[(&'a str, &'a Option<PathBuf>)]) -> Vec<(&'a str, &'a Path)> {
    list.iter()
        .filter_map(|(o, p)| p.as_deref().map(|p| (*o, p)))
        .collect()
}

/// Checks, before any work, that no output file (`(option, path)`) is one of
/// the input files or the same file as another output (writing it would
/// replace the data, or one result with another), and that each can be
/// written (see [`check_writable`]).
pub fn check_outputs(inputs: &[&Path], outputs: &[(&str, &Path)]) -> anyhow::Result<()> {
    check_outputs_and_dirs(inputs, outputs, &[])
}

/// [`check_outputs`] for commands that also write into output directories
/// (`(option, dir)`): a directory must not be an input file, and must be a
/// directory that can be written in, or one that can be created.
pub fn check_outputs_and_dirs(
    inputs: &[&Path],
    files: &[(&str, &Path)],
    dirs: &[(&str, &Path)],
) -> anyhow::Result<()> {
    let ins: Vec<_> = inputs.iter().map(|p| identity(p)).collect();
    let all: Vec<(&str, &Path, bool)> = files
        .iter()
        .map(|(o, p)| (*o, *p, false))
        .chain(dirs.iter().map(|(o, p)| (*o, *p, true)))
        .collect();
    for (k, (opt, out, is_dir)) in all.iter().enumerate() {
        let id = identity(out);
        if let Some(i) = ins.iter().position(|p| *p == id) {
            anyhow::bail!(
                "{opt} {}: this is the input file {}; writing there would replace it (choose another output path)",
                out.display(),
                inputs[i].display()
            );
        }
        if let Some((other, _, _)) = all[..k].iter().find(|(_, o, _)| identity(o) == id) {
            anyhow::bail!(
                "{opt} {}: {other} writes to the same place; give each output its own path",
                out.display()
            );
        }
        check_writable(opt, out, *is_dir)?;
    }
    Ok(())
}

/// The name prefix of [`check_writable`]'s probe file (created and removed
/// at once; another process may see it for an instant).
pub const WRITE_PROBE: &str = ".palpate-write-check.";

/// Checks that `path` can be written as a file (`dir = false`) or written
/// in as a directory, without writing it: the path is not a directory (for
/// a file) or not a file (for a directory), and the nearest existing folder
/// on the way to it is a directory in which a file can be created (tried
/// with a temporary file, removed at once). Errors name the option and path.
pub fn check_writable(option: &str, path: &Path, dir: bool) -> anyhow::Result<()> {
    let shown = path.display();
    if path.is_dir() && !dir {
        anyhow::bail!("{option} {shown}: is a directory; give a file name");
    }
    if path.exists() && !path.is_dir() && dir {
        anyhow::bail!("{option} {shown}: is a file; give a directory (it is created if missing)");
    }
    // The nearest folder that exists: the directory itself, or the first
    // existing ancestor of the file (missing folders are created on write).
    let mut at: &Path = if dir && path.is_dir() {
        path
    } else {
        parent_of(path)
    };
    loop {
        match std::fs::metadata(at) {
            Ok(m) if m.is_dir() => break,
            Ok(_) => anyhow::bail!(
                "{option} {shown}: {} is a file, not a directory, so nothing can be written under it",
                at.display()
            ),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
                ) =>
            {
                at = parent_of(at);
                if at == Path::new(".") && !at.exists() {
                    break;
                }
            }
            Err(e) => anyhow::bail!("{option} {shown}: cannot reach {}: {e}", at.display()),
        }
    }
    tempfile::Builder::new()
        .prefix(WRITE_PROBE)
        .tempfile_in(at)
        .map(drop)
        .map_err(|e| anyhow::anyhow!("{option} {shown}: cannot write in {}: {e}", at.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn atomic_write_replaces_content_and_leaves_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("sub/out.json");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "two");
        assert_eq!(std::fs::read_dir(p.parent().unwrap()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn results_get_the_umask_permissions_not_0600() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.json");
        write_atomic(&p, b"{}").unwrap();
        // Whatever the umask, group/other read as `touch` would give them:
        // compare with a file created by std (0666 less the umask).
        let q = dir.path().join("plain");
        std::fs::write(&q, b"").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&p), mode(&q));
    }

    #[test]
    fn a_temporary_file_of_a_dead_process_is_removed_by_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.json");
        // pid 0 is never a user process; u32::MAX - 1 is above pid_max.
        let stale = dir
            .path()
            .join(format!(".r.json.{}.abcdef.tmp", u32::MAX - 1));
        let other = dir
            .path()
            .join(format!(".s.json.{}.abcdef.tmp", u32::MAX - 1));
        let live = dir
            .path()
            .join(format!(".r.json.{}.abcdef.tmp", std::process::id()));
        for f in [&stale, &other, &live] {
            std::fs::write(f, b"half").unwrap();
        }
        write_atomic(&p, b"whole").unwrap();
        assert!(!stale.exists(), "stale temp file kept");
        assert!(
            other.exists() && live.exists(),
            "removed a temp file it does not own"
        );
        assert_eq!(remove_stale_temps(dir.path(), None), 1);
        assert!(!other.exists() && live.exists());
    }

    #[test]
    fn an_unwritable_output_is_refused_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("data.csv");
        std::fs::write(&file, "x").unwrap();
        let under = file.join("out.json");
        let e = check_outputs(&[], &[("--json", &under)])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--json ") && e.contains("is a file"), "{e}");
        let e = check_outputs(&[], &[("--json", dir.path())])
            .unwrap_err()
            .to_string();
        assert!(e.contains("is a directory"), "{e}");
        let e = check_outputs_and_dirs(&[], &[], &[("--plot", &file)])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--plot ") && e.contains("is a file"), "{e}");
        // Missing folders on the way are fine: they are created on write.
        check_outputs_and_dirs(
            &[],
            &[("--json", &dir.path().join("new/sub/r.json"))],
            &[("--plot", &dir.path().join("figs/more"))],
        )
        .unwrap();
        assert!(
            !dir.path().join("new").exists(),
            "the check wrote something"
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn an_output_on_an_input_or_on_another_output_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let data = dir.path().join("in.csv");
        std::fs::write(&data, "x").unwrap();
        let same = dir.path().join(".").join("in.csv");
        let e = check_outputs(&[&data], &[("--json", &same)])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--json ") && e.contains("input file"), "{e}");
        let a = dir.path().join("a.svg");
        let e = check_outputs(&[&data], &[("--json", &a), ("--plot", &a)])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--plot ") && e.contains("--json"), "{e}");
        check_outputs(
            &[&data],
            &[("--json", &a), ("--plot", &dir.path().join("b.svg"))],
        )
        .unwrap();
        assert_eq!(std::fs::read_to_string(&data).unwrap(), "x");
    }
}
