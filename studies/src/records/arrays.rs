//! Records given as arrays in memory instead of CSV files (the Python
//! package passes numpy arrays this way, docs/python.md).
//!
//! A `--data` value whose file part is `<array:K>` (e.g.
//! `uniaxial=<array:0>`, `C1=<array:1>`) names the K-th [`ArrayRecord`]
//! handed to the command beside its options, so that everything else about
//! the option (the test, the reading options in brackets, the order, the
//! names of repeated tests) is read exactly as for a file. The record's
//! columns are borrowed slices, turned into the [`Table`] a CSV reader
//! would have made: the same checks (finite values, a monotonic `time_s`,
//! equal lengths, distinct names, at least one row) with the same messages,
//! a row's "line" counting the header as line 1, as in the CSV the file
//! path writes. The table owns its columns, so each value is copied once
//! here, into the record palpate keeps (no text, no file).

use palpate_core::data::{DataError, Table};
use palpate_core::Column;
use std::path::PathBuf;

/// One record's columns, borrowed from the caller.
#[derive(Debug, Clone)]
pub struct ArrayRecord<'a> {
    /// The column names, as a CSV header would give them (`stretch`,
    /// `stress_MPa`, `displacement_mm`, `force_N`, `time_s`, ...).
    pub names: Vec<String>,
    /// The columns, in the order of `names`.
    pub columns: Vec<&'a [f64]>,
}

/// The index K of a `<array:K>` placeholder, `None` for a file path.
pub fn placeholder(path: &str) -> Option<anyhow::Result<usize>> {
    let inner = path.strip_prefix("<array:")?.strip_suffix('>')?;
    Some(inner.parse::<usize>().map_err(|_| {
        anyhow::anyhow!("`{path}`: expected <array:K> with K the index of an array record")
    }))
}

/// The record `<array:K>` of `path` among `records`, or `None` when `path`
/// is a file path. Errors name the placeholder when there is no record K.
pub fn record_for<'r, 'a>(
    path: &str,
    records: &'r [ArrayRecord<'a>],
) -> anyhow::Result<Option<&'r ArrayRecord<'a>>> {
    let Some(k) = placeholder(path) else {
        return Ok(None);
    };
    let k = k?;
    records.get(k).map(Some).ok_or_else(|| {
        anyhow::anyhow!(
            "`{path}`: no array record {k} (given {} array records)",
            records.len()
        )
    })
}

impl ArrayRecord<'_> {
    /// The table a CSV reader would have made of these columns, named
    /// `label` in messages (as a file path would be).
    pub fn table(&self, label: &str) -> Result<Table, DataError> {
        let file = PathBuf::from(label);
        if self.names.len() != self.columns.len() {
            return Err(DataError::FieldCount {
                file,
                line: 1,
                expected: self.names.len(),
                found: self.columns.len(),
            });
        }
        for (k, n) in self.names.iter().enumerate() {
            if self.names[..k].contains(n) {
                return Err(DataError::DuplicateColumn {
                    file,
                    line: 1,
                    column: n.clone(),
                });
            }
        }
        let rows = self.columns.first().map_or(0, |c| c.len());
        if rows == 0 {
            return Err(DataError::Empty { file });
        }
        if let Some(c) = self.columns.iter().find(|c| c.len() != rows) {
            // The first row the shorter (or longer) column does not match.
            return Err(DataError::FieldCount {
                file,
                line: 2 + rows.min(c.len()),
                expected: self.names.len(),
                found: self.names.len() - 1,
            });
        }
        for (name, col) in self.names.iter().zip(&self.columns) {
            for (i, &v) in col.iter().enumerate() {
                let line = i + 2;
                if !v.is_finite() {
                    return Err(DataError::NotFinite {
                        file,
                        line,
                        column: name.clone(),
                    });
                }
                if name == Column::TIME && i > 0 && v < col[i - 1] {
                    return Err(DataError::NonMonotonicTime {
                        file,
                        line,
                        prev: col[i - 1],
                        value: v,
                    });
                }
            }
        }
        Ok(Table {
            file,
            names: self.names.clone(),
            header_line: 1,
            columns: self.columns.iter().map(|c| c.to_vec()).collect(),
            lines: (2..rows + 2).collect(),
            comments: Vec::new(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec<'a>(names: &[&str], columns: Vec<&'a [f64]>) -> ArrayRecord<'a> {
        ArrayRecord {
            names: names.iter().map(|s| s.to_string()).collect(),
            columns,
        }
    }

    #[test]
    fn a_record_is_the_table_of_the_same_csv() {
        let (x, y) = ([1.0, 1.5, 2.0], [0.0, 0.25, 0.5]);
        let t = rec(&["stretch", "stress_MPa"], vec![&x, &y])
            .table("uniaxial")
            .unwrap();
        let csv = Table::parse("uniaxial", "stretch,stress_MPa\n1,0\n1.5,0.25\n2,0.5\n").unwrap();
        assert_eq!(t.columns, csv.columns);
        assert_eq!(t.lines, csv.lines);
        assert_eq!(t.names, csv.names);
    }

    #[test]
    fn bad_records_are_refused_as_the_csv_would_be() {
        let (a, b, nan) = ([0.0, 1.0, 2.0], [0.0, 1.0], [0.0, f64::NAN, 1.0]);
        let back = [0.0, 2.0, 1.0];
        for (r, says) in [
            (rec(&["x", "y"], vec![&a, &b]), "r:4: expected 2 fields"),
            (rec(&["x", "x"], vec![&a, &a]), "names column `x` twice"),
            (
                rec(&["x", "y"], vec![&a, &nan]),
                "r:3: column `y`: value is NaN",
            ),
            (
                rec(&["time_s", "y"], vec![&back, &a]),
                "r:4: column `time_s` is not monotonic",
            ),
            (rec(&["x"], vec![&[]]), "r: no data rows"),
            (rec(&["x", "y"], vec![&a]), "expected 2 fields, found 1"),
        ] {
            let e = r.table("r").unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
    }

    #[test]
    fn placeholders_name_their_record() {
        let x = [1.0];
        let records = [rec(&["x"], vec![&x])];
        assert!(record_for("data.csv", &records).unwrap().is_none());
        assert!(record_for("<array:0>", &records).unwrap().is_some());
        let e = record_for("<array:3>", &records).unwrap_err().to_string();
        assert!(e.contains("no array record 3 (given 1"), "{e}");
        let e = record_for("<array:x>", &records).unwrap_err().to_string();
        assert!(e.contains("expected <array:K>"), "{e}");
    }
}
