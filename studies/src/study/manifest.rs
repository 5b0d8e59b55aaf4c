//! Study manifests: one TOML file describes a whole study.
//!
//! Plain serde types with `deny_unknown_fields` (a misspelled field is an
//! error with its line, reported by the TOML parser), then [`Manifest::validate`]
//! checks every cross-reference and file and names the offending field.
//! Steps are an externally tagged enum, so each `[[steps]]` table holds exactly
//! one of `calibrate`, `diagnose`, `predict` ([`PredictStep`]: models run with
//! a calibrate step's parameters against records) or `anova` ([`AnovaStep`]:
//! a factorial analysis of a predict step's comparisons).
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
//! [[steps]]
//! [steps.calibrate]
//! name = "laws"
//! models = ["nh"]
//! fits = { uniaxial = ["uniaxial"] }
//! residuals = ["absolute", "relative"]
//! ```

use crate::models::ModelSpec;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A whole study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub study: StudyMeta,
    #[serde(default)]
    pub data: BTreeMap<String, DataSpec>,
    #[serde(default)]
    pub models: BTreeMap<String, ModelEntry>,
    pub steps: Vec<Step>,
}

/// Name, description and seed of a study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyMeta {
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// Seed for everything random in the study (noise, MCMC, run order).
    #[serde(default)]
    pub seed: u64,
}

/// One data file and the test it records.
#[derive(Debug, Clone, Deserialize)]
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
}

impl DataSpec {
    /// The reading options this data set states.
    pub fn read_options(&self) -> anyhow::Result<crate::calibration::ReadOptions> {
        let mut o = crate::calibration::ReadOptions::default();
        if let Some(w) = self.weight {
            o.set("weight", &w.to_string())?;
        }
        if let Some(a) = self.axial_stretch {
            o.set("axial_stretch", &a.to_string())?;
        }
        if let Some(u) = &self.stress_unit {
            o.set("stress_unit", u)?;
        }
        Ok(o)
    }
}

/// A named model: a law applied to each data set's own test (`law = "..."`,
/// the original form) or one model of [`ModelSpec`] (`[models.NAME.n1_needle]`,
/// `[models.NAME.c1_fe]`, ...), with parameters optionally held fixed in fits.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelEntry {
    pub model: ModelForm,
    /// Parameters held at a value during fits, by name (MPa or dimensionless).
    pub fixed: BTreeMap<String, f64>,
    /// With `law = "..."`: a viscoelastic form of the homogeneous tests,
    /// `qlv:N` or `finite:N` ([`crate::models::Viscous`]).
    pub viscoelastic: Option<String>,
}

/// The two forms of a named model.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelForm {
    /// `law = "..."`: `neo-hookean`, `mooney-rivlin`, `reduced-polynomial:N`,
    /// `yeoh`, `arruda-boyce`, `ogden:N`, in the model of each data set's test
    /// ([`crate::models::for_test`]).
    Law(String),
    /// One model kind with its settings.
    Spec(ModelSpec),
}

impl<'de> Deserialize<'de> for ModelEntry {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use crate::models::{
            C1FeSpec, C1Spec, HomogeneousSpec, N1NeedleSpec, N3NeedleSpec, Q1Spec,
        };
        use serde::de::{Error, MapAccess, Visitor};
        const FIELDS: &[&str] = &[
            "law",
            "fixed",
            "viscoelastic",
            "homogeneous",
            "c1",
            "c1_fe",
            "n1_needle",
            "q1",
            "n3_needle",
        ];
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ModelEntry;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "a model: `law = \"...\"` or one table of homogeneous, c1, c1_fe, n1_needle, n3_needle",
                )
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<ModelEntry, A::Error> {
                let mut law: Option<String> = None;
                let mut spec: Option<ModelSpec> = None;
                let mut fixed = BTreeMap::new();
                let mut viscoelastic: Option<String> = None;
                while let Some(key) = map.next_key::<String>()? {
                    let next = match key.as_str() {
                        "law" => {
                            law = Some(map.next_value()?);
                            None
                        }
                        "fixed" => {
                            fixed = map.next_value()?;
                            None
                        }
                        "viscoelastic" => {
                            viscoelastic = Some(map.next_value()?);
                            None
                        }
                        "homogeneous" => {
                            Some(ModelSpec::Homogeneous(map.next_value::<HomogeneousSpec>()?))
                        }
                        "c1" => Some(ModelSpec::C1(map.next_value::<C1Spec>()?)),
                        "c1_fe" => Some(ModelSpec::C1Fe(map.next_value::<C1FeSpec>()?)),
                        "n1_needle" => Some(ModelSpec::N1Needle(map.next_value::<N1NeedleSpec>()?)),
                        "q1" => Some(ModelSpec::Q1(map.next_value::<Q1Spec>()?)),
                        "n3_needle" => Some(ModelSpec::N3Needle(map.next_value::<N3NeedleSpec>()?)),
                        other => return Err(A::Error::unknown_field(other, FIELDS)),
                    };
                    if let Some(n) = next {
                        if let Some(old) = &spec {
                            return Err(A::Error::custom(format!(
                                "two model kinds, `{}` and `{}`: a model has one",
                                old.kind(),
                                n.kind()
                            )));
                        }
                        spec = Some(n);
                    }
                }
                let model = match (law, spec) {
                    (Some(l), None) => ModelForm::Law(l),
                    (None, Some(s)) => ModelForm::Spec(s),
                    (Some(_), Some(s)) => {
                        return Err(A::Error::custom(format!(
                            "both `law` and a `{}` table: give the law inside the `{}` table",
                            s.kind(),
                            s.kind()
                        )))
                    }
                    (None, None) => {
                        return Err(A::Error::custom(
                            "no model: expected `law = \"...\"` or one table of homogeneous, c1, c1_fe, n1_needle, n3_needle",
                        ))
                    }
                };
                if let (Some(v), ModelForm::Spec(s)) = (&viscoelastic, &model) {
                    return Err(A::Error::custom(format!(
                        "`viscoelastic = \"{v}\"` goes with `law = ...`; inside the `{}` table give it there",
                        s.kind()
                    )));
                }
                if let Some(v) = &viscoelastic {
                    crate::models::Viscous::parse(v)
                        .map_err(|e| A::Error::custom(format!("viscoelastic: {e}")))?;
                }
                Ok(ModelEntry {
                    model,
                    fixed,
                    viscoelastic,
                })
            }
        }
        d.deserialize_map(V)
    }
}

impl ModelEntry {
    /// The law as written.
    pub fn law_text(&self) -> &str {
        match &self.model {
            ModelForm::Law(l) => l,
            ModelForm::Spec(s) => s.law_text(),
        }
    }
}

/// One step of a study.
#[derive(Debug, Clone, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Step {
    Calibrate(CalibrateStep),
    Diagnose(DiagnoseStep),
    Predict(PredictStep),
    Anova(AnovaStep),
    TwoStage(crate::two_stage::TwoStageStep),
    Localize(LocalizeStep),
    Sample(crate::sample_step::SampleStep),
}

pub use crate::anova_step::AnovaStep;
pub use crate::localize_step::LocalizeStep;
pub use crate::predict_step::PredictStep;

/// Fit every model to every group of data sets, with every residual kind.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrateStep {
    pub name: String,
    /// Model names (keys of `[models]`).
    pub models: Vec<String>,
    /// Named groups of data sets fitted jointly, e.g. `{ all = ["uniaxial", "biaxial", "planar"] }`.
    pub fits: BTreeMap<String, Vec<String>>,
    /// Residual kinds: `absolute`, `relative`, `normalised`.
    #[serde(default = "default_residuals")]
    pub residuals: Vec<String>,
    /// `lm`, `bfgs` or `lbfgs`.
    #[serde(default = "default_estimator")]
    pub estimator: String,
    /// Data sets on which every fit is also evaluated (predictions of other modes).
    #[serde(default)]
    pub predict: Vec<String>,
}

/// Diagnose the sim-to-real gap of a base model on C1 or N1 records.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagnoseStep {
    pub name: String,
    /// Data set names (each diagnosed separately).
    pub data: Vec<String>,
    /// Base law, e.g. `neo-hookean`, in the base model of each record's test
    /// ([`crate::models::gap_base`]: C1 analytic; N1 frictionless, coarse mesh).
    #[serde(default)]
    pub base: Option<String>,
    /// Or the base model by name (a `[models.NAME.<kind>]` entry).
    #[serde(default)]
    pub model: Option<String>,
    /// Candidate effects (GAP.md names); default: C1 every effect its model
    /// offers, N1 `friction` and `boundary_condition`.
    #[serde(default)]
    pub effects: Option<Vec<String>>,
}

fn default_residuals() -> Vec<String> {
    vec!["absolute".into()]
}
fn default_estimator() -> String {
    "lm".into()
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
        toml::from_str(text)
            .map_err(|e| anyhow::anyhow!("{}: {}", path.display(), e.to_string().trim_end()))
    }

    /// Checks every reference (models, data sets, laws, residual and
    /// estimator names, files) and names the offending field.
    pub fn validate(&self, manifest_path: &Path) -> anyhow::Result<()> {
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
                crate::checks::check_fixed(
                    &law,
                    &fixed,
                    &format!("{where_}: models.{name}.fixed:"),
                )?;
            }
        }
        for (i, step) in self.steps.iter().enumerate() {
            match step {
                Step::Predict(p) => p.validate(self, i, &where_.to_string())?,
                Step::Anova(a) => a.validate(self, i, &where_.to_string(), dir)?,
                Step::TwoStage(t) => t.validate(
                    &where_.to_string(),
                    &format!("steps[{i}].two_stage (\"{}\")", t.name),
                    dir,
                )?,
                Step::Localize(l) => l.validate(self, i, &where_.to_string())?,
                Step::Sample(p) => p.validate(self, i, &where_.to_string())?,
                Step::Calibrate(c) => {
                    let at = format!("steps[{i}].calibrate (\"{}\")", c.name);
                    for (field, list) in [
                        ("models", &c.models),
                        ("residuals", &c.residuals),
                        ("predict", &c.predict),
                    ] {
                        if list.is_empty() && field != "predict" {
                            anyhow::bail!("{where_}: {at}.{field} = []: give at least one");
                        }
                        if let Some(d) = duplicate(list) {
                            anyhow::bail!("{where_}: {at}.{field}: \"{d}\" is listed twice");
                        }
                    }
                    for m in &c.models {
                        if !self.models.contains_key(m) {
                            anyhow::bail!(
                                "{where_}: {at}.models: unknown model \"{m}\" (defined: {})",
                                keys(&self.models)
                            );
                        }
                    }
                    if c.fits.is_empty() {
                        anyhow::bail!(
                            "{where_}: {at}.fits: at least one group of data sets is needed"
                        );
                    }
                    for (g, sets) in &c.fits {
                        if sets.is_empty() {
                            anyhow::bail!("{where_}: {at}.fits.{g}: empty group");
                        }
                        for s in sets {
                            if !self.data.contains_key(s) {
                                anyhow::bail!("{where_}: {at}.fits.{g}: unknown data set \"{s}\" (defined: {})", keys(&self.data));
                            }
                        }
                    }
                    for s in &c.predict {
                        if !self.data.contains_key(s) {
                            anyhow::bail!(
                                "{where_}: {at}.predict: unknown data set \"{s}\" (defined: {})",
                                keys(&self.data)
                            );
                        }
                    }
                    for m in &c.models {
                        let ModelForm::Spec(spec) = &self.models[m].model else {
                            continue;
                        };
                        for s in c.fits.values().flatten().chain(&c.predict) {
                            self.check_predicts(where_.to_string(), &at, m, spec, s)?;
                        }
                    }
                    for r in &c.residuals {
                        if !["absolute", "relative", "normalised"].contains(&r.as_str()) {
                            anyhow::bail!("{where_}: {at}.residuals: \"{r}\" is not one of absolute, relative, normalised");
                        }
                    }
                    if !["lm", "bfgs", "lbfgs"].contains(&c.estimator.as_str()) {
                        anyhow::bail!(
                            "{where_}: {at}.estimator: \"{}\" is not one of lm, bfgs, lbfgs",
                            c.estimator
                        );
                    }
                }
                Step::Diagnose(d) => {
                    let at = format!("steps[{i}].diagnose (\"{}\")", d.name);
                    for s in &d.data {
                        match self.data.get(s) {
                            None => anyhow::bail!(
                                "{where_}: {at}.data: unknown data set \"{s}\" (defined: {})",
                                keys(&self.data)
                            ),
                            Some(spec) if spec.test != "C1" && spec.test != "N1" => {
                                anyhow::bail!("{where_}: {at}.data: \"{s}\" is a {} test; the gap diagnosis needs a C1 or N1 force record", spec.test)
                            }
                            _ => {}
                        }
                    }
                    match (&d.base, &d.model) {
                        (Some(base), None) => {
                            if let Err(e) = base.parse::<palpate_material::Law>() {
                                anyhow::bail!("{where_}: {at}.base = \"{base}\": {e}");
                            }
                        }
                        (None, Some(m)) => match self.models.get(m).map(|e| &e.model) {
                            None => anyhow::bail!(
                                "{where_}: {at}.model: unknown model \"{m}\" (defined: {})",
                                keys(&self.models)
                            ),
                            Some(ModelForm::Law(_)) => anyhow::bail!(
                                "{where_}: {at}.model: \"{m}\" is a law alone; give the law as `base` or define models.{m}.c1 / models.{m}.n1_needle"
                            ),
                            Some(ModelForm::Spec(spec)) => {
                                for s in &d.data {
                                    self.check_predicts(where_.to_string(), &at, m, spec, s)?;
                                }
                            }
                        },
                        _ => anyhow::bail!(
                            "{where_}: {at}: give exactly one of `base` (a law) and `model` (a model name)"
                        ),
                    }
                    anyhow::ensure!(
                        !d.data.is_empty(),
                        "{where_}: {at}.data = []: give at least one record"
                    );
                    let mut effects = Vec::new();
                    for e in d.effects.iter().flatten() {
                        match e.parse::<palpate_core::Effect>() {
                            Ok(e) => effects.push(e),
                            Err(m) => anyhow::bail!("{where_}: {at}.effects: \"{e}\": {m}"),
                        }
                    }
                    if let Some(list) = &d.effects {
                        anyhow::ensure!(
                            !list.is_empty(),
                            "{where_}: {at}.effects = []: give at least one effect, or leave `effects` out for the default candidates"
                        );
                        if let Some(e) = duplicate(list) {
                            anyhow::bail!("{where_}: {at}.effects: \"{e}\" is listed twice");
                        }
                    }
                    for s in &d.data {
                        let Some(spec) = self.diagnose_model(d, s) else {
                            continue;
                        };
                        if let Ok(model) = crate::models::build(&spec) {
                            crate::models::check_effects(model.as_ref(), &effects)
                                .map_err(|e| anyhow::anyhow!("{where_}: {at}.effects: {e}"))?;
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

impl Step {
    /// The step's name.
    pub fn name(&self) -> &str {
        match self {
            Step::Calibrate(c) => &c.name,
            Step::Diagnose(d) => &d.name,
            Step::Predict(p) => &p.name,
            Step::Anova(a) => &a.name,
            Step::TwoStage(t) => &t.name,
            Step::Localize(l) => &l.name,
            Step::Sample(p) => &p.name,
        }
    }

    /// The step's kind, as spelled in manifests.
    pub fn kind(&self) -> &'static str {
        match self {
            Step::Calibrate(_) => "calibrate",
            Step::Diagnose(_) => "diagnose",
            Step::Predict(_) => "predict",
            Step::Anova(_) => "anova",
            Step::TwoStage(_) => "two_stage",
            Step::Localize(_) => "localize",
            Step::Sample(_) => "sample",
        }
    }
}

/// The first entry of a list that appears twice.
fn duplicate(list: &[String]) -> Option<&String> {
    list.iter()
        .enumerate()
        .find(|(i, x)| list[..*i].contains(x))
        .map(|(_, x)| x)
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

impl Manifest {
    /// The base model a diagnose step uses on data set `data` (None when
    /// the step or the data set is wrong: reported elsewhere).
    fn diagnose_model(&self, d: &DiagnoseStep, data: &str) -> Option<ModelSpec> {
        match (&d.base, &d.model) {
            (Some(base), None) => {
                let test = crate::calibration::TestKind::parse(&self.data.get(data)?.test).ok()?;
                crate::models::gap_base(test, base.parse().ok()?).ok()
            }
            (None, Some(m)) => match &self.models.get(m)?.model {
                ModelForm::Spec(s) => Some(s.clone()),
                ModelForm::Law(_) => None,
            },
            _ => None,
        }
    }

    /// Checks that a model spec predicts the records of data set `data`.
    pub(crate) fn check_predicts(
        &self,
        where_: String,
        at: &str,
        model: &str,
        spec: &ModelSpec,
        data: &str,
    ) -> anyhow::Result<()> {
        let Some(d) = self.data.get(data) else {
            return Ok(());
        };
        let test = crate::calibration::TestKind::parse(&d.test)?;
        if spec.test().ok() != Some(test) {
            anyhow::bail!(
                "{where_}: {at}: model \"{model}\" ({}) does not predict data set \"{data}\" (a {} test)",
                spec.kind(),
                d.test
            );
        }
        Ok(())
    }
}

pub(crate) fn keys<V>(m: &BTreeMap<String, V>) -> String {
    if m.is_empty() {
        "none".into()
    } else {
        m.keys().cloned().collect::<Vec<_>>().join(", ")
    }
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
            matches!(&m.steps[0], Step::Calibrate(c) if c.residuals == ["absolute"] && c.estimator == "lm")
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
