//! Study manifests: one TOML file describes a whole study.
//!
//! Plain serde types with `deny_unknown_fields` (a misspelled field is an
//! error with its line, reported by the TOML parser), then [`Manifest::validate`]
//! checks every cross-reference and file, names the offending field and
//! returns a [`CheckedManifest`], the only form the runner takes. Steps are
//! an externally tagged enum ([`StepEntry`], the registry of
//! [`crate::steps`]), so each `[[steps]]` table holds exactly one of
//! `calibrate`, `diagnose`, `predict`, `anova`, `two_stage`, `localize`, `replicates` or
//! `sample`; each kind checks itself ([`crate::run::step::Step::validate`]).
//!
//! ```toml
//! [study]
//! name = "treloar-laws"
//! seed = 1
//!
//! [data.uniaxial]
//! file = "data/treloar/uniaxial.csv"     # relative to the manifest
//! test = "uniaxial"                      # uniaxial | biaxial | planar | C1
//!
//! [models.nh]
//! law = "neo-hookean"
//!
//! [experiments.gel]                      # a lab's own experiment (crate::model::experiment)
//! specimen = { shape = "cylinder", radius = 20.0, height = 10.0 }
//! tool = { shape = "sphere", radius = 2.5 }
//! materials.gel = { law = "neo-hookean", C10 = { start = 2e-3 } }
//!
//! [models.disc]
//! experiment = "gel"                     # [experiments.gel], a preset (N1, ...) or a file
//!
//! [[steps]]
//! [steps.calibrate]
//! name = "laws"
//! models = ["nh"]
//! fits = { uniaxial = ["uniaxial"] }
//! residuals = ["absolute", "relative"]
//! ```

use crate::records::TESTS;
use crate::run::step::{At, StepRef, Study};
use palpate_fe::experiment::Experiment;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

pub use crate::model::{ModelEntry, ModelForm};
pub use crate::records::DataSpec;
pub use crate::run::step::StudyMeta;
pub use crate::steps::StepEntry;

/// A whole study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub study: StudyMeta,
    #[serde(default)]
    pub data: BTreeMap<String, DataSpec>,
    #[serde(default)]
    pub models: BTreeMap<String, ModelEntry>,
    /// Experiment descriptions by name, as in an experiment file; a model
    /// refers to one with `experiment = "NAME"`.
    #[serde(default)]
    pub experiments: BTreeMap<String, Experiment>,
    pub steps: Vec<StepEntry>,
}

/// The `[experiments]` tables alone (the first reading of a manifest, so
/// that its models can refer to them by name).
#[derive(Deserialize)]
struct Experiments {
    #[serde(default)]
    experiments: BTreeMap<String, Experiment>,
}

/// A manifest whose references, names and files [`Manifest::validate`] has
/// checked.
#[derive(Debug, Clone)]
pub struct CheckedManifest(Manifest);

impl std::ops::Deref for CheckedManifest {
    type Target = Manifest;
    fn deref(&self) -> &Manifest {
        &self.0
    }
}

impl CheckedManifest {
    /// The manifest.
    pub fn into_inner(self) -> Manifest {
        self.0
    }
}

impl Manifest {
    /// Reads and parses a manifest; TOML and unknown-field errors carry the
    /// file name and line.
    pub fn read(path: &Path) -> anyhow::Result<Manifest> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("cannot read manifest {}: {e}", path.display()))?;
        Manifest::parse(path, &text)
    }

    /// Parses manifest text (errors name `path`).
    pub fn parse(path: &Path, text: &str) -> anyhow::Result<Manifest> {
        let err = |e: toml::de::Error| {
            let at = e
                .span()
                .and_then(|span| key_path_at(text, span.start))
                .map(|keys| format!("{keys}: "))
                .unwrap_or_default();
            anyhow::anyhow!("{}: {at}{}", path.display(), e.to_string().trim_end())
        };
        let tables = toml::from_str::<Experiments>(text)
            .map_err(err)?
            .experiments;
        crate::model::experiment::with_tables(path, tables, || toml::from_str(text)).map_err(err)
    }

    /// The study as its steps see it.
    pub fn study_view(&self) -> Study<'_> {
        Study {
            study: &self.study,
            data: &self.data,
            models: &self.models,
            steps: self
                .steps
                .iter()
                .map(|s| StepRef {
                    kind: s.kind(),
                    step: s.step(),
                })
                .collect(),
        }
    }

    /// Checks every reference (models, data sets, laws, residual and
    /// estimator names, files) and names the offending field.
    pub fn validate(self, manifest_path: &Path) -> anyhow::Result<CheckedManifest> {
        let where_ = manifest_path.display();
        let dir = manifest_path.parent().unwrap_or(Path::new("."));
        // The study name is the run folder under runs/ and each step name a
        // file-name prefix in it: one plain name each, no two steps alike.
        check_file_name(&self.study.name)
            .map_err(|e| anyhow::anyhow!("{where_}: study.name = {:?}: {e}", self.study.name))?;
        anyhow::ensure!(
            !self.steps.is_empty(),
            "{where_}: steps: no steps; give at least one [[steps]] table"
        );
        for (i, step) in self.steps.iter().enumerate() {
            let (kind, name) = (step.kind(), step.name());
            check_file_name(name)
                .map_err(|e| anyhow::anyhow!("{where_}: steps[{i}].{kind}.name = {name:?}: {e}"))?;
            if let Some(j) = self.steps[..i].iter().position(|s| s.name() == name) {
                anyhow::bail!(
                    "{where_}: steps[{i}].{kind}.name = {name:?}: steps[{j}] has the same name (their outputs would overwrite each other)"
                );
            }
        }
        for (name, d) in &self.data {
            if !TESTS.contains(&d.test.as_str()) {
                anyhow::bail!(
                    "{where_}: data.{name}.test = \"{}\": expected one of {}",
                    d.test,
                    TESTS.join(", ")
                );
            }
            d.read_options()
                .map_err(|e| anyhow::anyhow!("{where_}: data.{name}: {e}"))?;
            let f = dir.join(&d.file);
            if !f.is_file() {
                anyhow::bail!("{where_}: data.{name}.file: no such file {}", f.display());
            }
        }
        for (name, e) in &self.experiments {
            e.check()
                .map_err(|e| anyhow::anyhow!("{where_}: experiments.{name}: {e}"))?;
        }
        for (name, m) in &self.models {
            match &m.model {
                ModelForm::Law(law) => {
                    if let Err(e) = law.parse::<palpate_material::Law>() {
                        anyhow::bail!("{where_}: models.{name}.law = \"{law}\": {e}");
                    }
                }
                ModelForm::Spec(spec) => {
                    if let Err(e) = spec.validate() {
                        anyhow::bail!("{where_}: models.{name}.{e}");
                    }
                }
            }
            if let Ok(law) = m.law_text().parse::<palpate_material::Law>() {
                let fixed: Vec<(String, f64)> =
                    m.fixed.iter().map(|(k, v)| (k.clone(), *v)).collect();
                crate::run::checks::check_fixed(
                    &law,
                    &fixed,
                    &format!("{where_}: models.{name}.fixed:"),
                )?;
            }
        }
        let study = self.study_view();
        for (i, step) in self.steps.iter().enumerate() {
            let at = At {
                file: where_.to_string(),
                index: i,
                kind: step.kind(),
                dir,
            };
            step.step().validate(&study, &at)?;
        }
        drop(study);
        Ok(CheckedManifest(self))
    }
}

/// The dotted path (`models.x.n1_needle.mesh`, `steps[0].calibrate.name`)
/// of the innermost value of a TOML document at byte `at`, to name the
/// field of an error the TOML reader places by line only.
fn key_path_at(text: &str, at: usize) -> Option<String> {
    use toml::de::{DeTable, DeValue};
    fn find(v: &DeValue<'_>, at: usize, path: &mut Vec<String>) -> bool {
        let mut visit = |key: String, child: &toml::Spanned<DeValue<'_>>| {
            path.push(key);
            if find(child.get_ref(), at, path) || child.span().contains(&at) {
                return true;
            }
            path.pop();
            false
        };
        match v {
            DeValue::Table(t) => t.iter().any(|(k, c)| visit(format!(".{}", k.get_ref()), c)),
            DeValue::Array(a) => a
                .iter()
                .enumerate()
                .any(|(i, c)| visit(format!("[{i}]"), c)),
            _ => false,
        }
    }
    let doc = DeTable::parse(text).ok()?;
    let mut path = Vec::new();
    find(&DeValue::Table(doc.into_inner()), at, &mut path).then(|| {
        let p = path.concat();
        p.trim_start_matches('.').to_string()
    })
}

/// Checks a name used as a file or folder name inside the run folder: not
/// empty, no path separator, not `.` or `..`, no control character, so that
/// nothing is written outside `runs/` or into `runs/` itself.
pub fn check_file_name(name: &str) -> Result<(), String> {
    if name.trim().is_empty() {
        return Err("empty; expected a plain name such as \"treloar-laws\"".into());
    }
    if name.contains(['/', '\\']) || Path::new(name).is_absolute() {
        return Err(
            "contains a path separator; expected a plain name (it names a folder inside runs/)"
                .into(),
        );
    }
    if name == "." || name == ".." {
        return Err("expected a plain name, not a reference to a folder".into());
    }
    if name.chars().any(char::is_control) {
        return Err("contains a control character".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[study]
name = "t"

[data.uni]
file = "x.csv"
test = "uniaxial"

[models.nh]
law = "neo-hookean"

[[steps]]
[steps.calibrate]
name = "fit"
models = ["nh"]
fits = { u = ["uni"] }
"#;

    #[test]
    fn parses_a_good_manifest() {
        let m = Manifest::parse(Path::new("s.toml"), GOOD).unwrap();
        assert_eq!(m.steps.len(), 1);
        assert!(
            matches!(&m.steps[0], StepEntry::Calibrate(c) if c.residuals == ["absolute"] && c.estimator == "lm")
        );
    }

    #[test]
    fn misspelled_field_is_an_error_with_its_line() {
        let bad = GOOD.replace("models = [\"nh\"]", "modles = [\"nh\"]");
        let e = Manifest::parse(Path::new("s.toml"), &bad)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("s.toml") && e.contains("modles") && e.contains("line 15"),
            "{e}"
        );
    }

    #[test]
    fn unknown_references_name_the_field() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("x.csv"), "stretch,stress_MPa\n1,0\n").unwrap();
        let p = dir.path().join("s.toml");
        let m =
            Manifest::parse(&p, &GOOD.replace("models = [\"nh\"]", "models = [\"mr\"]")).unwrap();
        let e = m.validate(&p).unwrap_err().to_string();
        assert!(
            e.contains("steps[0].calibrate") && e.contains("\"mr\""),
            "{e}"
        );
        let m = Manifest::parse(&p, &GOOD.replace("neo-hookean", "neo-hooke")).unwrap();
        let e = m.validate(&p).unwrap_err().to_string();
        assert!(e.contains("models.nh.law"), "{e}");
        let m = Manifest::parse(&p, GOOD).unwrap();
        m.validate(&p).unwrap();
    }

    #[test]
    fn a_diagnose_step_takes_a_base_law_or_a_named_model() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.csv"), "displacement_mm,force_N\n0,0\n").unwrap();
        let p = dir.path().join("s.toml");
        let text = |base: &str| {
            format!(
                "[study]\nname = \"t\"\n\n[data.rec]\nfile = \"r.csv\"\ntest = \"N1\"\n\n\
                 [models.needle.n1_needle]\nlaw = \"neo-hookean\"\n\n\
                 [models.press.c1]\nlaw = \"neo-hookean\"\n\n\
                 [[steps]]\n[steps.diagnose]\nname = \"gap\"\ndata = [\"rec\"]\n{base}\n"
            )
        };
        for ok in ["base = \"neo-hookean\"", "model = \"needle\""] {
            let m = Manifest::parse(&p, &text(ok)).unwrap();
            m.validate(&p).unwrap();
        }
        for (bad, needle) in [
            ("", "exactly one of `base`"),
            (
                "base = \"yeoh\"\nmodel = \"needle\"",
                "exactly one of `base`",
            ),
            ("model = \"nedle\"", "unknown model \"nedle\""),
            ("model = \"press\"", "does not predict data set \"rec\""),
        ] {
            let m = Manifest::parse(&p, &text(bad)).unwrap();
            let e = m.validate(&p).unwrap_err().to_string();
            assert!(e.contains("steps[0].diagnose") && e.contains(needle), "{e}");
        }
    }

    #[test]
    fn diagnose_effects_are_checked_by_name() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.csv"), "displacement_mm,force_N\n0,0\n").unwrap();
        let p = dir.path().join("s.toml");
        let text = |effects: &str| {
            format!(
                "[study]\nname = \"t\"\n\n[data.rec]\nfile = \"r.csv\"\ntest = \"N1\"\n\n\
                 [[steps]]\n[steps.diagnose]\nname = \"gap\"\nbase = \"neo-hookean\"\n\
                 data = [\"rec\"]\neffects = [{effects}]\n"
            )
        };
        let m = Manifest::parse(&p, &text("\"friction\", \"zero_offset\"")).unwrap();
        m.validate(&p).unwrap();
        let m = Manifest::parse(&p, &text("\"frictoin\"")).unwrap();
        let e = m.validate(&p).unwrap_err().to_string();
        assert!(
            e.contains("steps[0].diagnose") && e.contains("effects") && e.contains("frictoin"),
            "{e}"
        );
    }
}
