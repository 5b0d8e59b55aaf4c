//! Reading the project's CSV data files (docs/benchmarks.md, "Data files").
//!
//! A header line names the columns with their unit (`time_s`,
//! `displacement_mm`, `force_N`, `stretch`, `stress_MPa`, ...); lines
//! beginning with `#` are comments and blank lines are skipped. A missing
//! column, a non-numeric value, a NaN or a non-monotonic `time_s` column is an
//! error naming the file, line and column.
//!
//! Written by hand rather than with the `csv` crate: the format is a strict
//! numeric subset (no quoting), and the errors must carry the original line
//! numbers including comment lines, which is simplest here.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// Well-known column names.
pub struct Column;
impl Column {
    pub const TIME: &'static str = "time_s";
    pub const DISPLACEMENT: &'static str = "displacement_mm";
    pub const POSITION: &'static str = "position_mm";
    pub const FORCE: &'static str = "force_N";
    pub const STRAIN: &'static str = "strain";
    pub const STRETCH: &'static str = "stretch";
    pub const STRESS: &'static str = "stress_MPa";
}

/// Why a data file could not be read. Every variant names the file.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DataError {
    // The I/O error is in the message, not a `source`: a report that prints
    // the chain of causes would otherwise say it twice.
    #[error("{file}: cannot read: {error}")]
    Io {
        file: PathBuf,
        error: std::io::Error,
    },
    #[error(
        "{file}: no header line (expected column names such as `time_s,displacement_mm,force_N`)"
    )]
    NoHeader { file: PathBuf },
    #[error("{file}:{line}: the header names column `{column}` twice")]
    DuplicateColumn {
        file: PathBuf,
        line: usize,
        column: String,
    },
    #[error("{file}: missing column `{column}` (header has: {header})")]
    MissingColumn {
        file: PathBuf,
        column: String,
        header: String,
    },
    #[error("{file}:{line}: expected {expected} fields, found {found}")]
    FieldCount {
        file: PathBuf,
        line: usize,
        expected: usize,
        found: usize,
    },
    #[error("{file}:{line}: column `{column}`: `{value}` is not a number")]
    NotNumeric {
        file: PathBuf,
        line: usize,
        column: String,
        value: String,
    },
    #[error("{file}:{line}: column `{column}`: value is NaN or infinite")]
    NotFinite {
        file: PathBuf,
        line: usize,
        column: String,
    },
    #[error("{file}:{line}: column `time_s` is not monotonic ({prev} then {value})")]
    NonMonotonicTime {
        file: PathBuf,
        line: usize,
        prev: f64,
        value: f64,
    },
    #[error("{file}: no data rows")]
    Empty { file: PathBuf },
}

/// A numeric table read from a data file, column-major, with the source line
/// of each row kept for later error messages.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub file: PathBuf,
    pub names: Vec<String>,
    /// Source line (1-based, counting comments) of the header, for messages
    /// about a column as a whole.
    pub header_line: usize,
    pub columns: Vec<Vec<f64>>,
    pub lines: Vec<usize>,
    /// Comment lines (without the leading `#`), e.g. provenance.
    pub comments: Vec<String>,
}

/// The text layer shared by every CSV reader of palpate: comment lines
/// (`#`, kept), blank lines (skipped), one header line of unique column
/// names, then rows with exactly one field per column (surrounding double
/// quotes stripped). Fields stay strings; [`Table`] turns them into numbers,
/// the ANOVA runs table keeps factor levels as names.
#[derive(Debug, Clone, PartialEq)]
pub struct TextTable {
    pub file: PathBuf,
    pub names: Vec<String>,
    /// Source line (1-based, counting comments) of the header.
    pub header_line: usize,
    /// `rows[i][k]`: row i, column k.
    pub rows: Vec<Vec<String>>,
    /// Source line (1-based, counting comments) of each row.
    pub lines: Vec<usize>,
    pub comments: Vec<String>,
}

impl TextTable {
    /// Reads a file.
    pub fn read(path: impl AsRef<Path>) -> Result<TextTable, DataError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|error| DataError::Io {
            file: path.to_path_buf(),
            error,
        })?;
        TextTable::parse(path, &text)
    }

    /// Parses text as if read from `file`.
    pub fn parse(file: impl AsRef<Path>, text: &str) -> Result<TextTable, DataError> {
        let file = file.as_ref().to_path_buf();
        // A UTF-8 byte-order mark (what Excel writes) is not part of the
        // first column's name; lines may end in LF, CR LF or CR alone (old
        // Mac files), and each ending counts as one line in messages.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let unified;
        let text = if text.contains('\r') {
            unified = text.replace("\r\n", "\n").replace('\r', "\n");
            unified.as_str()
        } else {
            text
        };
        let mut names: Option<Vec<String>> = None;
        let mut header_line = 0;
        let (mut rows, mut lines, mut comments) = (Vec::new(), Vec::new(), Vec::new());
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let s = raw.trim();
            if s.is_empty() {
                continue;
            }
            if let Some(c) = s.strip_prefix('#') {
                comments.push(c.trim().to_string());
                continue;
            }
            let fields: Vec<String> = s.split(',').map(|f| unquote(f).to_string()).collect();
            match &names {
                None => {
                    for (k, name) in fields.iter().enumerate() {
                        if fields[..k].contains(name) {
                            return Err(DataError::DuplicateColumn {
                                file,
                                line,
                                column: name.clone(),
                            });
                        }
                    }
                    names = Some(fields);
                    header_line = line;
                }
                Some(n) => {
                    if fields.len() != n.len() {
                        return Err(DataError::FieldCount {
                            file,
                            line,
                            expected: n.len(),
                            found: fields.len(),
                        });
                    }
                    rows.push(fields);
                    lines.push(line);
                }
            }
        }
        let names = names.ok_or_else(|| DataError::NoHeader { file: file.clone() })?;
        if rows.is_empty() {
            return Err(DataError::Empty { file });
        }
        Ok(TextTable {
            file,
            names,
            header_line,
            rows,
            lines,
            comments,
        })
    }
}

fn unquote(s: &str) -> &str {
    let s = s.trim();
    if s.len() >= 2 && s.starts_with('"') && s.ends_with('"') {
        &s[1..s.len() - 1]
    } else {
        s
    }
}

impl Table {
    /// Reads and checks a file.
    pub fn read(path: impl AsRef<Path>) -> Result<Table, DataError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|error| DataError::Io {
            file: path.to_path_buf(),
            error,
        })?;
        Table::parse(path, &text)
    }

    /// Parses text as if read from `file` (used by `read` and by tests).
    pub fn parse(file: impl AsRef<Path>, text: &str) -> Result<Table, DataError> {
        let raw = TextTable::parse(file, text)?;
        let mut columns: Vec<Vec<f64>> = vec![Vec::with_capacity(raw.rows.len()); raw.names.len()];
        for (row, &line) in raw.rows.iter().zip(&raw.lines) {
            for (k, f) in row.iter().enumerate() {
                let v: f64 = f.parse().map_err(|_| DataError::NotNumeric {
                    file: raw.file.clone(),
                    line,
                    column: raw.names[k].clone(),
                    value: f.to_string(),
                })?;
                if !v.is_finite() {
                    return Err(DataError::NotFinite {
                        file: raw.file.clone(),
                        line,
                        column: raw.names[k].clone(),
                    });
                }
                if raw.names[k] == Column::TIME {
                    if let Some(&prev) = columns[k].last() {
                        if v < prev {
                            return Err(DataError::NonMonotonicTime {
                                file: raw.file.clone(),
                                line,
                                prev,
                                value: v,
                            });
                        }
                    }
                }
                columns[k].push(v);
            }
        }
        Ok(Table {
            file: raw.file,
            names: raw.names,
            header_line: raw.header_line,
            columns,
            lines: raw.lines,
            comments: raw.comments,
        })
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// True when the table has no rows (never, for a table from `parse`).
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Whether a column is present.
    pub fn has(&self, name: &str) -> bool {
        self.names.iter().any(|n| n == name)
    }

    /// A column by name, or an error naming the file and the columns present.
    pub fn column(&self, name: &str) -> Result<&[f64], DataError> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|k| self.columns[k].as_slice())
            .ok_or_else(|| DataError::MissingColumn {
                file: self.file.clone(),
                column: name.to_string(),
                header: self.names.join(","),
            })
    }

    /// Checks that every named column is present.
    pub fn require(&self, names: &[&str]) -> Result<(), DataError> {
        for n in names {
            self.column(n)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_comments_header_and_rows() {
        let t = Table::parse("x.csv", "# hello\ntime_s,force_N\n0,1\n\n0.5,2.5\n").unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t.column("force_N").unwrap(), &[1.0, 2.5]);
        assert_eq!(t.lines, vec![3, 5]);
        assert_eq!(t.comments, vec!["hello"]);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = Table::parse("a.csv", "time_s,force_N\n0,1\n1,abc\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a.csv:3") && e.contains("force_N") && e.contains("abc"),
            "{e}"
        );
        let e = Table::parse("a.csv", "time_s,force_N\n0,1\n1,NaN\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("a.csv:3") && e.contains("NaN"), "{e}");
        let e = Table::parse("a.csv", "time_s,force_N\n1,1\n0.5,2\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("a.csv:3") && e.contains("monotonic"), "{e}");
        let e = Table::parse("a.csv", "time_s,force_N\n1,1,3\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a.csv:2") && e.contains("expected 2 fields"),
            "{e}"
        );
        let t = Table::parse("a.csv", "time_s,force_N\n1,1\n").unwrap();
        let e = t.column("displacement_mm").unwrap_err().to_string();
        assert!(e.contains("a.csv") && e.contains("displacement_mm"), "{e}");
        assert!(Table::parse("a.csv", "# only comments\n").is_err());
    }

    #[test]
    fn a_byte_order_mark_and_every_line_ending_read_the_same() {
        let plain = "# c\ntime_s,force_N\n0,1\n0.5,2.5\n";
        let want = Table::parse("x.csv", plain).unwrap();
        for text in [
            format!("\u{feff}{plain}"),
            plain.replace('\n', "\r\n"),
            plain.replace('\n', "\r"),
            format!("\u{feff}{}", plain.replace('\n', "\r")),
            format!("\u{feff}{}", plain.replace('\n', "\r\n")),
        ] {
            let t = Table::parse("x.csv", &text).unwrap();
            assert_eq!(t, want, "{text:?}");
            assert_eq!(t.names[0], "time_s");
        }
        // The checks that depend on the first column still run, at the right line.
        let e = Table::parse("b.csv", "\u{feff}time_s,force_N\r1,1\r0.5,2\r")
            .unwrap_err()
            .to_string();
        assert!(e.contains("b.csv:3") && e.contains("monotonic"), "{e}");
    }
}
