//! A lab's own experiment as a model ([`ExperimentSpec`], the
//! `experiment` kind of [`super::ModelSpec`]): the description of
//! `palpate_fe::experiment` (specimen, materials, tool, supports, protocol,
//! mesh) with where it came from, the same from `--experiment FILE|PRESET`,
//! a study manifest and Python.
//!
//! In a study manifest a description is a table `[experiments.NAME]`
//! holding the same fields as an experiment file, and a model refers to it
//! by name (or to a preset, or to a file relative to the manifest):
//!
//! ```toml
//! [experiments.gel]
//! specimen = { shape = "cylinder", radius = 20.0, height = 10.0, support = "bonded" }
//! tool = { shape = "sphere", radius = 2.5 }
//! materials.gel = { law = "neo-hookean", C10 = { start = 2e-3 } }
//!
//! [models.gel]
//! experiment = "gel"            # [experiments.gel] | a preset (N1, ...) | a file
//! ```
//!
//! A model may also hold its description inline (`[models.gel.experiment]`
//! with the fields of an experiment file). The model's parameters are the
//! description's ([`Experiment::param_space`]): its fixed ones are held in
//! fits as a manifest model's `fixed` values are.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use palpate_fe::experiment::Experiment;

/// An experiment description and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentSpec {
    pub source: ExperimentSource,
    pub experiment: Box<Experiment>,
}

/// Where a description came from (for messages and reports).
#[derive(Debug, Clone, PartialEq)]
pub enum ExperimentSource {
    /// A shipped preset (`N1`, `C1`, ...).
    Preset(String),
    /// An experiment file.
    File(PathBuf),
    /// A manifest's `[experiments.NAME]` table.
    Table { manifest: PathBuf, name: String },
    /// Given inline (a manifest model's `experiment` table, a Python dict).
    Inline,
}

impl fmt::Display for ExperimentSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExperimentSource::Preset(p) => write!(f, "preset {p}"),
            ExperimentSource::File(p) => write!(f, "{}", p.display()),
            ExperimentSource::Table { manifest, name } => {
                write!(f, "{}: experiments.{name}", manifest.display())
            }
            ExperimentSource::Inline => write!(f, "the inline experiment"),
        }
    }
}

/// The names of the shipped presets.
pub fn preset_names() -> Vec<String> {
    Experiment::preset_names()
        .iter()
        .map(|s| s.to_string())
        .collect()
}

/// A preset by name (case-insensitive), `None` when there is none.
pub fn preset(name: &str) -> Option<Experiment> {
    let canonical = Experiment::preset_names()
        .iter()
        .find(|p| p.eq_ignore_ascii_case(name))?;
    Experiment::preset(canonical).ok()
}

/// Parses an experiment file's text; errors name `file` and the line.
pub fn parse(text: &str, file: &Path) -> anyhow::Result<Experiment> {
    Experiment::from_toml_str(text, &file.display().to_string()).map_err(|e| anyhow::anyhow!("{e}"))
}

/// Reads an experiment file; errors name the file.
pub fn read(path: &Path) -> anyhow::Result<Experiment> {
    Experiment::from_toml_file(path).map_err(|e| anyhow::anyhow!("{e}"))
}

/// What `--experiment X` (or a manifest's `experiment = "X"`) names: a
/// file when one exists at `dir/X`, else a preset; the error lists both.
/// Text starting with `{` is the description itself as JSON.
pub fn resolve(arg: &str, dir: &Path) -> anyhow::Result<ExperimentSpec> {
    if arg.trim_start().starts_with('{') {
        // the description as JSON text (as the Python package passes a dict)
        let e: Experiment = serde_json::from_str(arg)
            .map_err(|e| anyhow::anyhow!("the experiment given as JSON: {e}"))?;
        return Ok(ExperimentSpec::inline(e));
    }
    let path = dir.join(arg);
    if path.is_file() {
        return Ok(ExperimentSpec {
            experiment: Box::new(read(&path)?),
            source: ExperimentSource::File(path),
        });
    }
    if let Some(e) = preset(arg) {
        let name = e.name.clone().unwrap_or_else(|| arg.to_string());
        return Ok(ExperimentSpec {
            experiment: Box::new(e),
            source: ExperimentSource::Preset(name),
        });
    }
    anyhow::bail!(
        "`{arg}`: no such file ({}) and not a preset (presets: {})",
        path.display(),
        preset_names().join(", ")
    )
}

impl ExperimentSpec {
    /// The description of `--experiment X`, resolved against the working
    /// directory and checked ([`Experiment::check`]); errors name the file
    /// (or preset) and the field.
    pub fn from_option(arg: &str) -> anyhow::Result<ExperimentSpec> {
        let spec = resolve(arg, Path::new("")).map_err(|e| anyhow::anyhow!("--experiment {e}"))?;
        spec.check()?;
        Ok(spec)
    }

    /// A description given inline (a Python dict, a manifest table).
    pub fn inline(experiment: Experiment) -> ExperimentSpec {
        ExperimentSpec {
            source: ExperimentSource::Inline,
            experiment: Box::new(experiment),
        }
    }

    /// [`Experiment::check`] with the source in the message.
    pub fn check(&self) -> anyhow::Result<()> {
        self.experiment
            .check()
            .map_err(|e| anyhow::anyhow!("{}: {e}", self.source))
    }

    /// The parameters held fixed, by name, with their values.
    pub fn fixed(&self) -> anyhow::Result<Vec<(String, f64)>> {
        self.experiment
            .fixed_parameters()
            .map_err(|e| anyhow::anyhow!("{}: {e}", self.source))
    }

    /// The law of the first material the specimen uses (the law a report
    /// names and whose stability range a calibration states).
    pub fn law_text(&self) -> &str {
        let e = &self.experiment;
        let first = e.material_order().ok().and_then(|o| o.into_iter().next());
        first
            .and_then(|m| e.materials.get(&m))
            .or_else(|| e.materials.values().next())
            .map_or("", |m| m.law.as_str())
    }
}

/// The `[experiments]` tables of the manifest being read, so that a
/// model's `experiment = "NAME"` resolves against them (and a file name
/// against the manifest's folder) while serde reads the model.
struct Scope {
    manifest: PathBuf,
    tables: BTreeMap<String, Experiment>,
}

thread_local! {
    static SCOPE: RefCell<Option<Scope>> = const { RefCell::new(None) };
}

/// Runs `f` with `tables` (read from `manifest`) in scope for the
/// `experiment = "NAME"` references of its models.
pub(crate) fn with_tables<T>(
    manifest: &Path,
    tables: BTreeMap<String, Experiment>,
    f: impl FnOnce() -> T,
) -> T {
    struct Reset(Option<Scope>);
    impl Drop for Reset {
        fn drop(&mut self) {
            let old = self.0.take();
            SCOPE.with(|s| *s.borrow_mut() = old);
        }
    }
    let old = SCOPE.with(|s| {
        s.borrow_mut().replace(Scope {
            manifest: manifest.to_path_buf(),
            tables,
        })
    });
    let _reset = Reset(old);
    f()
}

/// A model's `experiment = "NAME"`: the manifest's table, a preset or a
/// file next to the manifest.
fn resolve_in_scope(name: &str) -> Result<ExperimentSpec, String> {
    SCOPE.with(|s| {
        let scope = s.borrow();
        let Some(scope) = scope.as_ref() else {
            return resolve(name, Path::new("")).map_err(|e| e.to_string());
        };
        if let Some(e) = scope.tables.get(name) {
            return Ok(ExperimentSpec {
                source: ExperimentSource::Table {
                    manifest: scope.manifest.clone(),
                    name: name.to_string(),
                },
                experiment: Box::new(e.clone()),
            });
        }
        let dir = scope.manifest.parent().unwrap_or(Path::new(""));
        resolve(name, dir).map_err(|e| {
            let tables: Vec<&str> = scope.tables.keys().map(String::as_str).collect();
            format!(
                "{e}; nor a table [experiments.{name}] (tables: {})",
                if tables.is_empty() {
                    "none".to_string()
                } else {
                    tables.join(", ")
                }
            )
        })
    })
}

impl<'de> serde::Deserialize<'de> for ExperimentSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        // a name (string) or the description's table
        let value = toml::Value::deserialize(d)?;
        match value {
            toml::Value::String(name) => resolve_in_scope(&name).map_err(D::Error::custom),
            other => {
                let e: Experiment = other.try_into().map_err(D::Error::custom)?;
                Ok(ExperimentSpec::inline(e))
            }
        }
    }
}
