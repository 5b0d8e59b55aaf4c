//! The record vocabulary: the kinds of test a data file records
//! ([`TestKind`]), a record read for one test ([`TestData`]), how to read it
//! ([`ReadOptions`], [`DataSpec`] in manifests) and the columns of each kind
//! ([`columns`]); files as testing machines write them, with metadata lines,
//! column names with units and other separators ([`machine`]); sign
//! conventions ([`sign`]); records given as arrays ([`arrays`]); a record
//! given as text, `TEST[options]=FILE` ([`data_option`]). It depends
//! on nothing else in the crate, so that models, calibration and the steps
//! all build on it.

pub mod arrays;
pub mod columns;
pub mod data_option;
pub mod machine;
pub mod published;
pub mod replicates;
pub mod sign;

pub use machine::{Metadata, Role, SpecimenSize};
pub use sign::Compression;

use palpate_analytic::Mode;
use palpate_core::data::{Column, Table};
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_inverse::DataSet;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;
/// The kind of experiment a data file records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TestKind {
    /// A homogeneous test driven by one stretch: uniaxial (tension and
    /// compression), equibiaxial or planar; columns `stretch` (or `strain`,
    /// `true_strain`) and `stress_MPa` (or `true_stress_MPa`, kPa, Pa),
    /// and `time_s` for a timed (viscoelastic) record ([`columns`]).
    Homogeneous(Mode),
    /// General biaxial extension: `lambda1`, `lambda2`, `stress1_MPa`,
    /// `stress2_MPa` (two stretches and two stresses per row; `--data
    /// biaxial=FILE` becomes this when the file has two stretch columns).
    GeneralBiaxial,
    /// Simple shear, optionally superposed on an axial stretch:
    /// `amount_of_shear`, `shear_stress_MPa`.
    SimpleShear,
    /// Benchmark C1: columns `displacement_mm`, `force_N` (and `time_s` when timed).
    C1,
    /// Benchmark N1 (FE needle indentation; by default friction 0.8, coarse mesh): same columns as C1.
    N1,
}

impl TestKind {
    /// Parses `uniaxial`, `biaxial` (equibiaxial, or general from the
    /// columns), `planar` (`pure_shear`), `general_biaxial`, `simple_shear`
    /// (and their aliases), `C1` or `N1`.
    pub fn parse(s: &str) -> anyhow::Result<TestKind> {
        if s.eq_ignore_ascii_case("c1") {
            return Ok(TestKind::C1);
        }
        if s.eq_ignore_ascii_case("n1") {
            return Ok(TestKind::N1);
        }
        match s.trim().to_ascii_lowercase().replace('-', "_").as_str() {
            "simple_shear" => return Ok(TestKind::SimpleShear),
            "shear" => anyhow::bail!(
                "test `{s}` is ambiguous: simple_shear (amount of shear, shear stress) or planar (pure shear: stretch, stress)"
            ),
            "general_biaxial" => return Ok(TestKind::GeneralBiaxial),
            _ => {}
        }
        s.parse::<Mode>().map(TestKind::Homogeneous).map_err(|_| {
            anyhow::anyhow!(
                "unknown test `{s}`; expected uniaxial, biaxial, planar, simple_shear, general_biaxial, C1 or N1"
            )
        })
    }

    /// Whether records of this kind are homogeneous stress records (not force records).
    pub fn is_homogeneous(self) -> bool {
        !matches!(self, TestKind::C1 | TestKind::N1)
    }
}

/// A data file read for one test.
#[derive(Debug, Clone)]
pub struct TestData {
    /// Name in reports (`uniaxial`, or the manifest's data-set name).
    pub name: String,
    pub test: TestKind,
    pub file: String,
    pub loading: Loading,
    pub observed: Vec<f64>,
    /// Weight of this record's residuals in a joint fit (default 1).
    pub weight: f64,
    /// Simple shear: the axial stretch the shear is superposed on (default 1).
    pub axial_stretch: f64,
    /// The lines of the file before its header (specimen size, speed,
    /// machine), in order; empty for a file in palpate's own format.
    pub metadata: Metadata,
    /// How the file's columns were read, e.g. `Load (N) -> force_N`,
    /// `Strain (%) -> strain (x 0.01)` (only those renamed or converted).
    pub columns_read: Vec<String>,
    /// How the record's sign was read, e.g. `compression, written negative
    /// as palpate's` (empty when there is nothing to say).
    pub sign: String,
    /// The batch of a replicate, when declared (`batch=A`).
    pub batch: Option<String>,
}

/// How to read a data file beyond its test kind (all optional).
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Weight of the record in a joint fit (> 0).
    pub weight: f64,
    /// Simple shear superposed on this axial stretch (> 0).
    pub axial_stretch: f64,
    /// The unit the stress columns are really in, in MPa per unit,
    /// overriding the unit in their names (for a file whose header is
    /// known to be wrong).
    pub stress_unit: Option<f64>,
    /// How the file writes compression; `None`: read from the data, and
    /// refused when ambiguous ([`sign`]).
    pub compression: Option<Compression>,
    /// Columns chosen by name (`force=Load`, `stress=Engineering Stress`).
    pub columns: Vec<(Role, String)>,
    /// Lines at the top of the file before the header (kept as metadata);
    /// `None`: the header is found.
    pub skip_rows: Option<usize>,
    /// The batch of a replicate (a cast, a day, a machine), for the
    /// batch-to-batch comparison of replicates.
    pub batch: Option<String>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            weight: 1.0,
            axial_stretch: 1.0,
            stress_unit: None,
            compression: None,
            columns: Vec::new(),
            skip_rows: None,
            batch: None,
        }
    }
}

impl ReadOptions {
    /// Parses the options of a `--data KIND[key=value,...]=FILE` or a
    /// manifest data set: `weight`, `axial_stretch`, `stress_unit` (MPa,
    /// kPa, Pa), `compression` (negative, positive, yes, none), `skip_rows`
    /// (a count of lines), `batch` (a replicate's batch), or a column chosen by name: `time`, `displacement`,
    /// `force`, `stretch`, `strain`, `true_strain`, `stress`, `true_stress`
    /// (`force=Load`).
    pub fn set(&mut self, key: &str, value: &str) -> anyhow::Result<()> {
        if let Some(role) = Role::parse(key) {
            let name = value.trim();
            anyhow::ensure!(
                !name.is_empty(),
                "{}=: expected the name of a column of the file",
                role.key()
            );
            if let Some((_, before)) = self.columns.iter().find(|(r, _)| *r == role) {
                anyhow::bail!(
                    "{}={name}: the {} column is already chosen ({}={before})",
                    role.key(),
                    role.key(),
                    role.key()
                );
            }
            self.columns.push((role, name.to_string()));
            return Ok(());
        }
        let number = |what: &str| -> anyhow::Result<f64> {
            value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| *v > 0.0 && v.is_finite())
                .ok_or_else(|| anyhow::anyhow!("{what} `{value}`: expected a positive number"))
        };
        match key.trim() {
            "weight" => self.weight = number("weight")?,
            "axial_stretch" => self.axial_stretch = number("axial_stretch")?,
            "stress_unit" => {
                self.stress_unit = Some(match value.trim() {
                    "MPa" => 1.0,
                    "kPa" => 1e-3,
                    "Pa" => 1e-6,
                    other => anyhow::bail!("stress_unit `{other}`: expected MPa, kPa or Pa"),
                })
            }
            "compression" => self.compression = Some(Compression::parse(value)?),
            "batch" => {
                let b = value.trim();
                anyhow::ensure!(
                    !b.is_empty(),
                    "batch=: expected the name of the replicate's batch, e.g. batch=A"
                );
                self.batch = Some(b.to_string());
            }
            "skip_rows" => {
                self.skip_rows = Some(value.trim().parse::<usize>().map_err(|_| {
                    anyhow::anyhow!("skip_rows `{value}`: expected a count of lines (0, 1, 2, ...)")
                })?)
            }
            other => anyhow::bail!(
                "unknown data option `{other}`; expected weight, axial_stretch, stress_unit, compression, skip_rows, batch \
                 or a column chosen by name ({})",
                Role::ALL.map(|r| format!("{}=NAME", r.key())).join(", ")
            ),
        }
        Ok(())
    }
}

impl TestData {
    /// Reads a data file for a test; errors name the file, line and column.
    pub fn read(name: &str, test: TestKind, path: &Path) -> anyhow::Result<TestData> {
        Self::read_with(name, test, path, ReadOptions::default())
    }

    /// [`TestData::read`] with a weight, an axial stretch or a stress unit.
    pub fn read_with(
        name: &str,
        test: TestKind,
        path: &Path,
        options: ReadOptions,
    ) -> anyhow::Result<TestData> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
        let m = machine::parse(
            path,
            &text,
            &machine::Layout {
                columns: &options.columns,
                skip_rows: options.skip_rows,
                stress_unit: options.stress_unit,
            },
        )?;
        let mut d = Self::from_parts(name, test, m.table, &m.metadata, &m.header, options)?;
        d.metadata = m.metadata;
        d.columns_read = m.renamed;
        Ok(d)
    }

    /// The specimen size the file's metadata states (`Cylinder Diameter:
    /// 50mm`, `Height (mm),30`), for an experiment description; `Ok(None)`
    /// when it states none, `Err` naming the line of a value that is not a
    /// length.
    pub fn specimen(&self) -> anyhow::Result<Option<SpecimenSize>> {
        self.metadata
            .specimen()
            .map_err(|e| anyhow::anyhow!("{}: {e}", self.file))
    }

    /// What a report says about how the record was read: its metadata,
    /// the columns renamed or converted and its sign convention (empty for
    /// a file in palpate's own format with nothing to say).
    pub fn describe(&self) -> String {
        let mut out = String::new();
        for e in &self.metadata.entries {
            if e.value.is_empty() {
                out.push_str(&format!("  {}\n", e.key));
            } else {
                out.push_str(&format!("  {}: {}\n", e.key, e.value));
            }
        }
        if !self.columns_read.is_empty() {
            out.push_str(&format!("  columns: {}\n", self.columns_read.join("; ")));
        }
        let plain = self.metadata.is_empty() && self.columns_read.is_empty();
        if !self.sign.is_empty() && !plain {
            out.push_str(&format!("  sign: {}\n", self.sign));
        }
        out
    }

    /// A record from a table already read (a file's, or the columns of an
    /// [`arrays::ArrayRecord`]); messages name `table.file`.
    pub fn from_table(
        name: &str,
        test: TestKind,
        table: Table,
        options: ReadOptions,
    ) -> anyhow::Result<TestData> {
        let header = table.names.clone();
        Self::from_parts(name, test, table, &Metadata::default(), &header, options)
    }

    /// [`TestData::from_table`] with the file's metadata and original
    /// header, which tell whether it records a compression test ([`sign`]).
    fn from_parts(
        name: &str,
        test: TestKind,
        mut table: Table,
        metadata: &Metadata,
        header: &[String],
        options: ReadOptions,
    ) -> anyhow::Result<TestData> {
        let sign = sign::resolve(&mut table, test, metadata, header, options.compression)?;
        let path = table.file.clone();
        let path = path.as_path();
        if options.axial_stretch != 1.0 && test != TestKind::SimpleShear {
            anyhow::bail!(
                "{}: axial_stretch = {} is for simple-shear records, not {test:?}",
                path.display(),
                options.axial_stretch
            );
        }
        let mut test = test;
        let mut stress_column = String::from("stress_MPa");
        let (loading, observed) = match test {
            TestKind::Homogeneous(_) | TestKind::GeneralBiaxial | TestKind::SimpleShear => {
                let h = columns::read(&table, test, options.axial_stretch, options.stress_unit)?;
                test = h.test;
                if let Some(c) = h.used.last() {
                    stress_column = c.clone();
                }
                let loading = match (table.has(Column::TIME), test) {
                    (true, TestKind::GeneralBiaxial) | (false, _) => {
                        Loading::quasi_static(h.drive_kind, h.drive)
                    }
                    (true, _) => {
                        Loading::timed(h.drive_kind, table.column(Column::TIME)?.to_vec(), h.drive)
                    }
                };
                (loading, h.stress)
            }
            TestKind::C1 | TestKind::N1 => {
                table.require(&[Column::DISPLACEMENT, Column::FORCE])?;
                let d = table.column(Column::DISPLACEMENT)?.to_vec();
                let loading = if table.has(Column::TIME) {
                    Loading::timed(
                        Drive::DisplacementMm,
                        table.column(Column::TIME)?.to_vec(),
                        d,
                    )
                } else {
                    Loading::quasi_static(Drive::DisplacementMm, d)
                };
                (loading, table.column(Column::FORCE)?.to_vec())
            }
        };
        // A record must carry a curve: two samples at least, and not zero
        // everywhere (a fit to zeros "converges" to nothing with R^2 -inf).
        let column = if test.is_homogeneous() {
            stress_column.as_str()
        } else {
            Column::FORCE
        };
        if observed.len() < 2 {
            anyhow::bail!(
                "{}:{}: a single data row; a record needs at least 2 rows of `{column}`",
                path.display(),
                table.lines[0]
            );
        }
        if observed.iter().all(|&v| v == 0.0) {
            anyhow::bail!(
                "{}: column `{column}` is zero on every row (lines {}-{}): nothing to fit",
                path.display(),
                table.lines[0],
                table.lines[table.lines.len() - 1]
            );
        }
        Ok(TestData {
            name: name.to_string(),
            test,
            file: path.display().to_string(),
            loading,
            observed,
            weight: options.weight,
            axial_stretch: options.axial_stretch,
            metadata: Metadata::default(),
            columns_read: Vec::new(),
            sign,
            batch: options.batch,
        })
    }

    /// The data set of this record predicted by `model`.
    pub fn dataset(&self, model: Arc<dyn ForwardModel>) -> DataSet {
        let mut d = DataSet::new(
            self.name.clone(),
            model,
            self.loading.clone(),
            self.observed.clone(),
        );
        d.weight = self.weight;
        d
    }
}

/// The kinds of test a data set can record.
pub const TESTS: [&str; 7] = [
    "uniaxial",
    "biaxial",
    "general_biaxial",
    "planar",
    "simple_shear",
    "C1",
    "N1",
];

/// One data file and the test it records.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataSpec {
    /// CSV file, relative to the manifest's directory.
    pub file: PathBuf,
    /// `uniaxial`, `biaxial` (equibiaxial, or general with `lambda1,lambda2`),
    /// `planar`, `simple_shear` (stretch or strain and stress_MPa, see the
    /// guide), `C1` or `N1` (displacement_mm, force_N[, time_s]).
    pub test: String,
    /// Weight of the record's residuals in joint fits (default 1).
    #[serde(default)]
    pub weight: Option<f64>,
    /// Simple shear superposed on this axial stretch (default 1).
    #[serde(default)]
    pub axial_stretch: Option<f64>,
    /// `MPa`, `kPa` or `Pa`: the unit the stress columns are really in, for a
    /// file whose header names the wrong unit (default: the header's).
    #[serde(default)]
    pub stress_unit: Option<String>,
    /// `negative`, `positive` or `none`: how the file writes compression
    /// (default: read from the data, refused when ambiguous).
    #[serde(default)]
    pub compression: Option<String>,
    /// Columns chosen by name: `{ force = "Load", displacement = "Compression" }`
    /// (keys time, displacement, force, stretch, strain, true_strain, stress,
    /// true_stress).
    #[serde(default)]
    pub columns: Option<std::collections::BTreeMap<String, String>>,
    /// Lines at the top of the file before its header (default: found).
    #[serde(default)]
    pub skip_rows: Option<usize>,
}

impl DataSpec {
    /// The reading options this data set states.
    pub fn read_options(&self) -> anyhow::Result<ReadOptions> {
        let mut o = ReadOptions::default();
        if let Some(w) = self.weight {
            o.set("weight", &w.to_string())?;
        }
        if let Some(a) = self.axial_stretch {
            o.set("axial_stretch", &a.to_string())?;
        }
        if let Some(u) = &self.stress_unit {
            o.set("stress_unit", u)?;
        }
        if let Some(c) = &self.compression {
            o.set("compression", c)?;
        }
        for (k, v) in self.columns.iter().flatten() {
            anyhow::ensure!(
                Role::parse(k).is_some(),
                "columns.{k}: unknown column role; expected one of {}",
                Role::ALL.map(|r| r.key()).join(", ")
            );
            o.set(k, v)
                .map_err(|e| anyhow::anyhow!("columns.{k}: {e}"))?;
        }
        if let Some(n) = self.skip_rows {
            o.skip_rows = Some(n);
        }
        Ok(o)
    }
}
