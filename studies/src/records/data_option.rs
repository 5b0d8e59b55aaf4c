//! A record given on the command line or to the API as text:
//! `TEST=FILE`, `TEST[key=value,...]=FILE` (the reading options of one
//! record), `FILE` or `C1=FILE` for a C1 force record, `force=FILE` for an
//! experiment's force record, and `<array:K>` in place of a file for records
//! given as arrays ([`super::arrays`]). The command line's `--data` and the
//! Python package read records through these functions, so both accept the
//! same forms with the same messages.

use super::arrays::{record_for, ArrayRecord};
use super::{ReadOptions, TestData, TestKind};
use anyhow::Context;
use std::path::Path;

/// Splits `NAME=VALUE` (or `NAME=PATH`).
pub fn split_pair<'a>(s: &'a str, what: &str) -> anyhow::Result<(&'a str, &'a str)> {
    s.split_once('=')
        .filter(|(a, b)| !a.is_empty() && !b.is_empty())
        .ok_or_else(|| anyhow::anyhow!("`{s}`: expected {what}"))
}

/// Splits `TEST=FILE` or `TEST[key=value,...]=FILE` into the test, its
/// reading options and the file.
pub fn split_data(d: &str) -> anyhow::Result<(&str, ReadOptions, &str)> {
    split_data_with(d, &ReadOptions::default())
}

/// [`split_data`] starting from `defaults` (the options of `--column`,
/// `--compression`, `--skip-rows`), which the options in brackets override.
pub fn split_data_with<'a>(
    d: &'a str,
    defaults: &ReadOptions,
) -> anyhow::Result<(&'a str, ReadOptions, &'a str)> {
    let mut options = defaults.clone();
    let mut chosen = Vec::new();
    if let Some(open) = d.find('[').filter(|&i| !d[..i].contains('=')) {
        let close = d[open..]
            .find(']')
            .map(|c| open + c)
            .ok_or_else(|| anyhow::anyhow!("--data {d}: `[` without `]`"))?;
        let path = d[close + 1..]
            .strip_prefix('=')
            .filter(|p| !p.is_empty())
            .ok_or_else(|| anyhow::anyhow!("--data {d}: expected `=FILE` after `]`"))?;
        for kv in d[open + 1..close]
            .split(',')
            .filter(|s| !s.trim().is_empty())
        {
            let (k, v) = split_pair(kv, "key=value inside [...], e.g. weight=0.5")
                .with_context(|| format!("--data {d}"))?;
            // A column chosen here replaces the one --column chose.
            if let Some(role) = super::Role::parse(k) {
                if !chosen.contains(&role) {
                    options.columns.retain(|(r, _)| *r != role);
                    chosen.push(role);
                }
            }
            options.set(k, v).with_context(|| format!("--data {d}"))?;
        }
        return Ok((&d[..open], options, path));
    }
    let (test, path) = split_pair(
        d,
        "TEST=FILE, e.g. uniaxial=data.csv (or use --benchmark C1 --data FILE)",
    )
    .map_err(|e| anyhow::anyhow!("--data {e}"))?;
    Ok((test, options, path))
}

/// Reads the `--data` options.
pub fn read_data(data: &[String], benchmark: Option<&str>) -> anyhow::Result<Vec<TestData>> {
    read_data_with(data, benchmark, &[])
}

/// Reads the `--data` options, a file part `<array:K>` taking the columns of
/// `arrays[K]` instead of a file ([`super::arrays`]).
pub fn read_data_with(
    data: &[String],
    benchmark: Option<&str>,
    arrays: &[ArrayRecord],
) -> anyhow::Result<Vec<TestData>> {
    read_data_opts(data, benchmark, arrays, &ReadOptions::default())
}

/// [`read_data_with`] with the reading options every file starts from
/// (the command line's `--column`, `--compression`, `--skip-rows`).
pub fn read_data_opts(
    data: &[String],
    benchmark: Option<&str>,
    arrays: &[ArrayRecord],
    defaults: &ReadOptions,
) -> anyhow::Result<Vec<TestData>> {
    let read = |name: &str, kind: TestKind, path: &str, options: ReadOptions| match record_for(
        path, arrays,
    )
    .with_context(|| format!("--data {path}"))?
    {
        Some(r) => TestData::from_table(name, kind, r.table(&format!("{name} arrays"))?, options),
        None => TestData::read_with(name, kind, Path::new(path), options),
    };
    let mut out = Vec::new();
    match benchmark {
        Some(b) if b.eq_ignore_ascii_case("c1") => {
            for d in data {
                let path = d
                    .strip_prefix("C1=")
                    .or_else(|| d.strip_prefix("c1="))
                    .unwrap_or(d);
                if let Some((test, _)) = path.split_once('=') {
                    if !Path::new(path).exists() {
                        anyhow::bail!(
                            "--data {d}: with --benchmark C1 every record is a C1 force record; give FILE or C1=FILE, not {test}=FILE"
                        );
                    }
                }
                out.push(read("C1", TestKind::C1, path, defaults.clone())?);
            }
        }
        Some(b) => anyhow::bail!(
            "--benchmark {b}: calibrate takes C1, Q1 or a preset of the experiment descriptions (palpate experiment list)"
        ),
        None => {
            for d in data {
                let (test, options, pattern) = split_data_with(d, defaults)?;
                let kind = TestKind::parse(test).with_context(|| format!("--data {d}"))?;
                // A FILE with wildcards: every file it matches.
                let files = if record_for(pattern, arrays)?.is_some() {
                    vec![pattern.to_string()]
                } else {
                    super::replicates::expand(pattern)
                        .with_context(|| format!("--data {d}"))?
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect()
                };
                for path in &files {
                    let name = if out.iter().any(|o: &TestData| o.name == test) {
                        format!("{test}#{}", out.len() + 1)
                    } else {
                        test.to_string()
                    };
                    out.push(read(&name, kind, path, options.clone())?);
                }
            }
        }
    }
    Ok(out)
}

/// The force records of an experiment's calibration: each of `data` is
/// `FILE`, `force=FILE` or `force[key=value,...]=FILE` (columns
/// `displacement_mm, force_N`, optionally `time_s`; the reading options of
/// `defaults` and the brackets apply), or `<array:K>` for records given as
/// arrays.
pub fn read_force_records(
    data: &[String],
    arrays: &[ArrayRecord],
    defaults: &ReadOptions,
) -> anyhow::Result<Vec<TestData>> {
    let mut out = Vec::new();
    for d in data {
        let (path, options) = if d.contains('=') && !Path::new(d).is_file() {
            let (test, options, path) = split_data_with(d, defaults)?;
            anyhow::ensure!(
                test.eq_ignore_ascii_case("force") || test.eq_ignore_ascii_case("n1"),
                "--data {d}: an experiment is fitted to force records: FILE or force=FILE (columns displacement_mm, force_N), not {test}=FILE"
            );
            (path, options)
        } else {
            (d.as_str(), defaults.clone())
        };
        let name = if data.len() == 1 {
            "force".to_string()
        } else {
            format!("force#{}", out.len() + 1)
        };
        let record = match record_for(path, arrays).with_context(|| format!("--data {path}"))? {
            Some(r) => TestData::from_table(
                &name,
                TestKind::N1,
                r.table(&format!("{name} arrays"))?,
                options,
            )?,
            None => TestData::read_with(&name, TestKind::N1, Path::new(path), options)?,
        };
        out.push(record);
    }
    Ok(out)
}
