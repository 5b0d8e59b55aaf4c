//! An experiment description as TOML: read from text or a file (errors
//! with the file and line, then [`Experiment::check`]) and written back.

use std::path::Path;

use super::{Experiment, Specimen};
use crate::FeError;

impl Experiment {
    /// Reads a description from TOML text; `file` names it in errors. A
    /// syntax error, an unknown key or a bad value is a
    /// [`FeError::ConfigFile`] with the 1-based line; a description that
    /// parses but cannot be built is refused by [`Experiment::check`]
    /// (an [`FeError::InvalidConfig`] naming the field, the file in its
    /// reason).
    pub fn from_toml_str(text: &str, file: &str) -> Result<Experiment, FeError> {
        let e = parse(text, file)?;
        checked(e, file)
    }
}

/// The description in `text`, parsed but not checked.
fn parse(text: &str, file: &str) -> Result<Experiment, FeError> {
    toml::from_str::<Experiment>(text).map_err(|err| {
        let line = err
            .span()
            .map(|s| error_line(text, s.start, err.message()))
            .unwrap_or(0);
        FeError::ConfigFile {
            file: file.to_string(),
            line,
            reason: err.message().trim().to_string(),
        }
    })
}

/// A parsed description checked, the file named in the reason of an error.
fn checked(e: Experiment, file: &str) -> Result<Experiment, FeError> {
    e.check().map_err(|err| match err {
        FeError::InvalidConfig { field, reason } => FeError::InvalidConfig {
            field,
            reason: format!("{reason} (in {file})"),
        },
        other => other,
    })?;
    Ok(e)
}

impl Experiment {
    /// Reads a description from a TOML file ([`Experiment::from_toml_str`]).
    /// Its relative paths (`protocol.from_record`, `specimen.file`) are
    /// made relative to the file's folder; the name defaults to the file's
    /// stem.
    pub fn from_toml_file(path: impl AsRef<Path>) -> Result<Experiment, FeError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| FeError::ConfigFile {
            file: file.clone(),
            line: 0,
            reason: format!("cannot read: {e}"),
        })?;
        let mut e = parse(&text, &file)?;
        let folder = path.parent().unwrap_or(Path::new(""));
        let resolve = |p: &mut String| {
            if Path::new(p.as_str()).is_relative() {
                *p = folder.join(p.as_str()).display().to_string();
            }
        };
        if let Some(r) = &mut e.protocol.from_record {
            resolve(r);
        }
        if let Specimen::Mesh(m) = &mut e.specimen {
            resolve(&mut m.file);
        }
        if e.name.is_none() {
            e.name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        }
        checked(e, &file)
    }

    /// The description as TOML, which [`Experiment::from_toml_str`] reads
    /// back to an equal description.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_else(|e| format!("# not representable as TOML: {e}\n"))
    }
}

/// The 1-based line of an error at byte `start`: for an unknown field, the
/// line of that key at or after `start` (the parser of a tagged table
/// points at the table's header), else the line of `start`.
fn error_line(text: &str, start: usize, message: &str) -> usize {
    let start = start.min(text.len());
    let line_of = |at: usize| {
        text.as_bytes()[..at]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    };
    let key = message
        .strip_prefix("unknown field `")
        .and_then(|rest| rest.split('`').next());
    if let Some(key) = key {
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let here = offset;
            offset += line.len();
            if here + line.len() <= start {
                continue;
            }
            let code = line.trim_start();
            if let Some(after) = code.strip_prefix(key) {
                if after.trim_start().starts_with('=') {
                    return line_of(here);
                }
            }
        }
    }
    line_of(start)
}
