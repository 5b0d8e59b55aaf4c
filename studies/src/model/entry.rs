//! A named model of a manifest's `[models]` table: a law alone, or one
//! model kind with its settings ([`super::ModelSpec`]), and parameters held fixed.

use super::ModelSpec;
use serde::Deserialize;
use std::collections::BTreeMap;

/// A named model: a law applied to each data set's own test (`law = "..."`,
/// the original form) or one model of [`ModelSpec`] (`[models.NAME.n1_needle]`,
/// `[models.NAME.c1_fe]`, ..., `experiment = "NAME"` for a lab's own
/// experiment, [`super::experiment`]), with parameters optionally held fixed
/// in fits (an experiment's own fixed parameters are held too).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelEntry {
    pub model: ModelForm,
    /// Parameters held at a value during fits, by name (MPa or dimensionless).
    pub fixed: BTreeMap<String, f64>,
    /// With `law = "..."`: a viscoelastic form of the homogeneous tests,
    /// `qlv:N` or `finite:N` ([`super::Viscous`]).
    pub viscoelastic: Option<super::Viscous>,
}

/// The two forms of a named model.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelForm {
    /// `law = "..."`: `neo-hookean`, `mooney-rivlin`, `reduced-polynomial:N`,
    /// `yeoh`, `arruda-boyce`, `ogden:N`, `gent`, `veronda-westmann`, `humphrey`, in the
    /// model of each data set's test
    /// ([`super::for_test`]).
    Law(String),
    /// One model kind with its settings.
    Spec(ModelSpec),
}

impl<'de> Deserialize<'de> for ModelEntry {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use super::{C1FeSpec, C1Spec, HomogeneousSpec, N1NeedleSpec, N3NeedleSpec, Q1Spec};
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
            "experiment",
        ];
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ModelEntry;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "a model: `law = \"...\"`, `experiment = \"NAME\"` or one table of homogeneous, c1, c1_fe, n1_needle, n3_needle, q1, experiment",
                )
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<ModelEntry, A::Error> {
                let mut law: Option<String> = None;
                let mut spec: Option<ModelSpec> = None;
                let mut fixed = BTreeMap::new();
                let mut viscoelastic: Option<super::Viscous> = None;
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
                        // a name ([experiments.NAME], a preset, a file) or the table
                        "experiment" => Some(ModelSpec::Experiment(
                            map.next_value::<super::ExperimentSpec>()?,
                        )),
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
                            "no model: expected `law = \"...\"`, `experiment = \"NAME\"` or one table of homogeneous, c1, c1_fe, n1_needle, n3_needle, q1, experiment",
                        ))
                    }
                };
                if let (Some(v), ModelForm::Spec(s)) = (&viscoelastic, &model) {
                    return Err(A::Error::custom(format!(
                        "`viscoelastic = \"{v}\"` goes with `law = ...`; inside the `{}` table give it there",
                        s.kind()
                    )));
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
