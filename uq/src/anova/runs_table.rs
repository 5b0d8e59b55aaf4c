//! Reading a table with one row per run whose factor columns hold level
//! names (strings) and whose response columns are numeric.
//!
//! palpate-core's `data::Table` reads numeric columns only, hence this small
//! reader. Format: comma-separated, a header line, `#` comment lines and blank
//! lines skipped, fields trimmed; a field may be wrapped in double quotes
//! (which are removed) but may not contain a comma. Every error names the
//! file, and where it applies the line and the column.

use super::FactorColumn;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a runs table could not be read or a column used.
#[derive(Debug, Error)]
pub enum RunsTableError {
    #[error("{file}: cannot read: {source}")]
    Io {
        file: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: no header line")]
    NoHeader { file: PathBuf },
    #[error("{file}:{line}: the header names column `{column}` twice")]
    DuplicateColumn {
        file: PathBuf,
        line: usize,
        column: String,
    },
    #[error("{file}:{line}: expected {expected} fields, found {found}")]
    FieldCount {
        file: PathBuf,
        line: usize,
        expected: usize,
        found: usize,
    },
    #[error("{file}: missing column `{column}` (header has: {header})")]
    MissingColumn {
        file: PathBuf,
        column: String,
        header: String,
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
    #[error("{file}:{line}: column `{column}` is empty")]
    EmptyField {
        file: PathBuf,
        line: usize,
        column: String,
    },
    #[error("{file}: no data rows")]
    Empty { file: PathBuf },
}

/// A table of strings, one row per run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunsTable {
    pub file: PathBuf,
    pub names: Vec<String>,
    /// `rows[i][k]`: row i, column k.
    pub rows: Vec<Vec<String>>,
    /// Source line (1-based) of each row.
    pub lines: Vec<usize>,
    pub comments: Vec<String>,
}

fn unquote(s: &str) -> &str {
    let s = s.trim();
    if s.len() >= 2 && s.starts_with('"') && s.ends_with('"') {
        &s[1..s.len() - 1]
    } else {
        s
    }
}

impl RunsTable {
    /// Reads and checks a file.
    pub fn read(path: impl AsRef<Path>) -> Result<RunsTable, RunsTableError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| RunsTableError::Io {
            file: path.to_path_buf(),
            source,
        })?;
        RunsTable::parse(path, &text)
    }

    /// Parses text as if read from `file`.
    pub fn parse(file: impl AsRef<Path>, text: &str) -> Result<RunsTable, RunsTableError> {
        let file = file.as_ref().to_path_buf();
        let mut names: Option<Vec<String>> = None;
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
                    for (k, n) in fields.iter().enumerate() {
                        if fields[..k].contains(n) {
                            return Err(RunsTableError::DuplicateColumn {
                                file,
                                line,
                                column: n.clone(),
                            });
                        }
                    }
                    names = Some(fields);
                }
                Some(n) => {
                    if fields.len() != n.len() {
                        return Err(RunsTableError::FieldCount {
                            file,
                            line,
                            expected: n.len(),
                            found: fields.len(),
                        });
                    }
                    if let Some(k) = fields.iter().position(String::is_empty) {
                        return Err(RunsTableError::EmptyField {
                            file,
                            line,
                            column: n[k].clone(),
                        });
                    }
                    rows.push(fields);
                    lines.push(line);
                }
            }
        }
        let names = names.ok_or_else(|| RunsTableError::NoHeader { file: file.clone() })?;
        if rows.is_empty() {
            return Err(RunsTableError::Empty { file });
        }
        Ok(RunsTable {
            file,
            names,
            rows,
            lines,
            comments,
        })
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True for a table without rows (never, for a parsed table).
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    fn index(&self, column: &str) -> Result<usize, RunsTableError> {
        self.names
            .iter()
            .position(|n| n == column)
            .ok_or_else(|| RunsTableError::MissingColumn {
                file: self.file.clone(),
                column: column.to_string(),
                header: self.names.join(","),
            })
    }

    /// The column as strings.
    pub fn strings(&self, column: &str) -> Result<Vec<&str>, RunsTableError> {
        let k = self.index(column)?;
        Ok(self.rows.iter().map(|r| r[k].as_str()).collect())
    }

    /// The column as level names of a factor (levels in order of first appearance).
    pub fn factor(&self, column: &str) -> Result<FactorColumn, RunsTableError> {
        Ok(FactorColumn::from_names(column, &self.strings(column)?))
    }

    /// The column as finite numbers; errors name the line.
    pub fn numeric(&self, column: &str) -> Result<Vec<f64>, RunsTableError> {
        let k = self.index(column)?;
        self.rows
            .iter()
            .zip(&self.lines)
            .map(|(r, &line)| {
                let v: f64 = r[k].parse().map_err(|_| RunsTableError::NotNumeric {
                    file: self.file.clone(),
                    line,
                    column: column.to_string(),
                    value: r[k].clone(),
                })?;
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(RunsTableError::NotFinite {
                        file: self.file.clone(),
                        line,
                        column: column.to_string(),
                    })
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_strings_and_numbers_with_located_errors() {
        let t = RunsTable::parse(
            "d.csv",
            "# c\nmaterial,space,r2\nNH,\"3D\",0.98\n\nRP,axisymmetric,0.99\n",
        )
        .unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t.lines, vec![3, 5]);
        let f = t.factor("space").unwrap();
        assert_eq!(f.levels, vec!["3D", "axisymmetric"]);
        assert_eq!(t.numeric("r2").unwrap(), vec![0.98, 0.99]);
        let e = t.numeric("material").unwrap_err().to_string();
        assert!(
            e.contains("d.csv:3") && e.contains("material") && e.contains("NH"),
            "{e}"
        );
        let e = t.factor("temperature").unwrap_err().to_string();
        assert!(e.contains("d.csv") && e.contains("temperature"), "{e}");
        let e = RunsTable::parse("d.csv", "a,b\n1,2\n3\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("d.csv:3") && e.contains("expected 2 fields"),
            "{e}"
        );
        let e = RunsTable::parse("d.csv", "a,b\n1,\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("d.csv:2") && e.contains("`b` is empty"), "{e}");
        let e = RunsTable::parse("d.csv", "a,b\n1,NaN\n")
            .unwrap()
            .numeric("b")
            .unwrap_err()
            .to_string();
        assert!(e.contains("d.csv:2") && e.contains("NaN"), "{e}");
    }
}
