//! An R2 force record: `position_mm,force_N[,...]` (as `palpate simulate
//! --benchmark R2 --csv` writes it), checked against the rolled path.

use palpate_core::data::Table;
use std::path::{Path, PathBuf};

/// Wheel positions (increasing, mm) and vertical forces (N).
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub file: PathBuf,
    pub positions: Vec<f64>,
    pub force: Vec<f64>,
}

impl Record {
    /// Reads `path`; the error names the file, the line and the column:
    /// missing columns, positions outside `path_mm` (the rolled path) or not
    /// increasing, non-finite forces, fewer than 5 rows.
    pub fn read(path: &Path, path_mm: (f64, f64)) -> anyhow::Result<Record> {
        let table = Table::read(path).map_err(|e| anyhow::anyhow!("{e}"))?;
        Self::from_table(&table, path_mm)
    }

    /// The checks of [`Record::read`] on a parsed table.
    pub fn from_table(table: &Table, (lo, hi): (f64, f64)) -> anyhow::Result<Record> {
        let file = table.file.display();
        let x = table
            .column("position_mm")
            .map_err(|e| anyhow::anyhow!("{e} (an R2 record has position_mm,force_N)"))?;
        let f = table
            .column("force_N")
            .map_err(|e| anyhow::anyhow!("{e} (an R2 record has position_mm,force_N)"))?;
        anyhow::ensure!(
            x.len() >= 5,
            "{file}: {} rows; a record of the rolled pass needs at least 5",
            x.len()
        );
        for i in 0..x.len() {
            let line = table.lines[i];
            if !(x[i] >= lo - 1e-9 && x[i] <= hi + 1e-9) {
                anyhow::bail!(
                    "{file}:{line}: position_mm {} is outside the rolled path {lo}..{hi} mm",
                    x[i]
                );
            }
            if i > 0 && x[i].partial_cmp(&x[i - 1]) != Some(std::cmp::Ordering::Greater) {
                anyhow::bail!(
                    "{file}:{line}: position_mm {} does not increase (previous row {} mm): the record must follow the wheel along the path",
                    x[i],
                    x[i - 1]
                );
            }
            if !f[i].is_finite() {
                anyhow::bail!("{file}:{line}: force_N is not a finite number");
            }
        }
        Ok(Record {
            file: table.file.clone(),
            positions: x.to_vec(),
            force: f.to_vec(),
        })
    }
}
