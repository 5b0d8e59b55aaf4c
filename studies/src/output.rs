//! Writing result files safely: write to a temporary file in the same
//! directory, then rename, so an interrupted run never leaves a truncated or
//! lost result file.

use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temp file + rename), creating the
/// parent directory if needed. Errors name the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    use anyhow::Context;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let mut tmp = tempfile::NamedTempFile::new_in(dir)
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

/// A path as the file system sees it, for comparing: canonical when it
/// exists, else its canonical parent joined with its name.
fn identity(p: &Path) -> std::path::PathBuf {
    if let Ok(c) = p.canonicalize() {
        return c;
    }
    let parent = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (parent.canonicalize(), p.file_name()) {
        (Ok(d), Some(n)) => d.join(n),
        _ => p.to_path_buf(),
    }
}

/// The outputs that were asked for, as `(option, path)`.
pub fn given<'a>(list: &[(&'a str, &'a Option<std::path::PathBuf>)]) -> Vec<(&'a str, &'a Path)> {
    list.iter()
        .filter_map(|(o, p)| p.as_deref().map(|p| (*o, p)))
        .collect()
}

/// Checks, before any work, that no output (`(option, path)`) is one of the
/// input files or the same file as another output: writing it would replace
/// the data (data loss) or one result with another.
pub fn check_outputs(inputs: &[&Path], outputs: &[(&str, &Path)]) -> anyhow::Result<()> {
    let ins: Vec<_> = inputs.iter().map(|p| identity(p)).collect();
    for (k, (opt, out)) in outputs.iter().enumerate() {
        let id = identity(out);
        if let Some(i) = ins.iter().position(|p| *p == id) {
            anyhow::bail!(
                "{opt} {}: this is the input file {}; writing there would replace it (choose another output path)",
                out.display(),
                inputs[i].display()
            );
        }
        if let Some((other, _)) = outputs[..k].iter().find(|(_, o)| identity(o) == id) {
            anyhow::bail!(
                "{opt} {}: {other} writes to the same file; give each output its own path",
                out.display()
            );
        }
    }
    Ok(())
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
