//! Reading a table with one row per run whose factor columns hold level
//! names (strings) and whose response columns are numeric.
//!
//! The text layer (comments, header, field counts, quotes) is palpate-core's
//! [`TextTable`]; this module keeps factor columns as level names and reads
//! response columns as numbers. Every error names the file, and where it
//! applies the line and the column.

use super::FactorColumn;
use palpate_core::{DataError, TextTable};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a runs table could not be read or a column used.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RunsTableError {
    /// The text layer (file, comments, header, field counts) and numeric
    /// columns: palpate-core's errors, naming file, line and column.
    #[error(transparent)]
    Data(#[from] palpate_core::DataError),
    #[error("{file}:{line}: column `{column}` is empty")]
    EmptyField {
        file: PathBuf,
        line: usize,
        column: String,
    },
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

impl RunsTable {
    /// Reads and checks a file.
    pub fn read(path: impl AsRef<Path>) -> Result<RunsTable, RunsTableError> {
        RunsTable::from_text(TextTable::read(path)?)
    }

    /// Parses text as if read from `file`.
    pub fn parse(file: impl AsRef<Path>, text: &str) -> Result<RunsTable, RunsTableError> {
        RunsTable::from_text(TextTable::parse(file, text)?)
    }

    /// Checks that no field is empty (a run without a level or a response).
    fn from_text(t: TextTable) -> Result<RunsTable, RunsTableError> {
        for (row, &line) in t.rows.iter().zip(&t.lines) {
            if let Some(k) = row.iter().position(String::is_empty) {
                return Err(RunsTableError::EmptyField {
                    file: t.file,
                    line,
                    column: t.names[k].clone(),
                });
            }
        }
        Ok(RunsTable {
            file: t.file,
            names: t.names,
            rows: t.rows,
            lines: t.lines,
            comments: t.comments,
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
            .ok_or_else(|| DataError::MissingColumn {
                file: self.file.clone(),
                column: column.to_string(),
                header: self.names.join(","),
            })
            .map_err(RunsTableError::from)
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
                let v: f64 = r[k].parse().map_err(|_| DataError::NotNumeric {
                    file: self.file.clone(),
                    line,
                    column: column.to_string(),
                    value: r[k].clone(),
                })?;
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(DataError::NotFinite {
                        file: self.file.clone(),
                        line,
                        column: column.to_string(),
                    })
                }
            })
            .collect::<Result<_, DataError>>()
            .map_err(RunsTableError::from)
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
