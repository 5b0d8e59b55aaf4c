//! The reference problems of docs/benchmarks.md as experiment descriptions,
//! shipped as TOML files (`presets/*.toml`, the text `palpate experiment
//! show NAME` prints). Each carries the reference model's mesh, so that its
//! model is the one the reference's constructor makes.

use super::Experiment;
use crate::FeError;

/// The presets: name and TOML text.
const FILES: [(&str, &str); 7] = [
    ("N1", include_str!("presets/n1.toml")),
    ("N3", include_str!("presets/n3.toml")),
    ("C1", include_str!("presets/c1.toml")),
    ("C1-bonded", include_str!("presets/c1-bonded.toml")),
    ("Q1", include_str!("presets/q1.toml")),
    ("R2", include_str!("presets/r2.toml")),
    ("R2-1", include_str!("presets/r2-1.toml")),
];

impl Experiment {
    /// The names of the presets, in the order of docs/benchmarks.md's
    /// variants.
    pub const PRESETS: [&'static str; 7] = ["N1", "N3", "C1", "C1-bonded", "Q1", "R2", "R2-1"];

    /// The names of the presets ([`Experiment::PRESETS`]).
    pub fn preset_names() -> &'static [&'static str] {
        &Experiment::PRESETS
    }

    /// A preset by name (case-insensitive: `n1`, `C1-bonded`); an unknown
    /// name is an error listing the valid ones.
    pub fn preset(name: &str) -> Result<Experiment, FeError> {
        let (canonical, text) = entry(name)?;
        Experiment::from_toml_str(text, &format!("preset {canonical}"))
    }

    /// A preset's TOML text as shipped, with its comments (what `palpate
    /// experiment show NAME` prints for a user to copy and edit).
    pub fn preset_toml(name: &str) -> Result<&'static str, FeError> {
        Ok(entry(name)?.1)
    }
}

fn entry(name: &str) -> Result<(&'static str, &'static str), FeError> {
    FILES
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name.trim()))
        .copied()
        .ok_or_else(|| FeError::InvalidConfig {
            field: "preset".into(),
            reason: format!(
                "`{name}` is not a preset; valid: {}",
                Experiment::PRESETS.join(", ")
            ),
        })
}
