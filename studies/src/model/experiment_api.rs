//! What the commands need of an experiment description beyond its serde
//! types: reading it from TOML with the file in errors, the presets, the
//! checks and the loading of its protocol's segments.

use palpate_core::{Drive, Loading};
use palpate_fe::experiment::{Experiment, ExperimentModel, Protocol};
use palpate_fe::FeError;
use std::path::Path;

/// The description's reading, presets and checks.
pub trait ExperimentApi: Sized {
    fn preset_names() -> &'static [&'static str];
    fn preset(name: &str) -> Result<Self, FeError>;
    fn from_toml_str(text: &str, file: &Path) -> Result<Self, FeError>;
    fn from_toml_file(path: &Path) -> Result<Self, FeError>;
    fn to_toml(&self) -> String;
    fn check(&self) -> Result<(), FeError>;
}

const N1: &str = r#"name = "N1"

[specimen]
shape = "cylinder"
radius = 35.0
height = 80.0
support = "bonded"

[materials.tissue]
law = "neo-hookean"
C10 = { start = 1e-3 }

[tool]
shape = "needle"
half_angle = 15.0
tip_radius = 2.5
friction = 0.8

[protocol]
samples = 40
segments = [{ ramp_to = 10.0 }]
"#;

impl ExperimentApi for Experiment {
    fn preset_names() -> &'static [&'static str] {
        &["N1"]
    }
    fn preset(name: &str) -> Result<Self, FeError> {
        match name {
            "N1" => Self::from_toml_str(N1, Path::new("N1")),
            _ => Err(FeError::InvalidConfig {
                field: "preset".into(),
                reason: format!("`{name}`: presets are {}", Self::preset_names().join(", ")),
            }),
        }
    }
    fn from_toml_str(text: &str, file: &Path) -> Result<Self, FeError> {
        toml::from_str(text).map_err(|e| FeError::InvalidConfig {
            field: file.display().to_string(),
            reason: e.to_string().trim_end().to_string(),
        })
    }
    fn from_toml_file(path: &Path) -> Result<Self, FeError> {
        let text = std::fs::read_to_string(path).map_err(|e| FeError::InvalidConfig {
            field: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Self::from_toml_str(&text, path)
    }
    fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }
    fn check(&self) -> Result<(), FeError> {
        self.parameters().map(|_| ())
    }
}

/// The loading of an experiment's protocol segments.
pub trait ModelLoading {
    fn loading(&self, protocol: &Protocol) -> Result<Loading, FeError>;
}

impl ModelLoading for ExperimentModel {
    fn loading(&self, protocol: &Protocol) -> Result<Loading, FeError> {
        let bad = |field: String, reason: &str| FeError::InvalidConfig {
            field,
            reason: reason.into(),
        };
        if protocol.segments.is_empty() {
            return Err(bad(
                "protocol.segments".into(),
                "no segments: give [[protocol.segments]] (e.g. ramp_to = 2.0) or a record",
            ));
        }
        let n = protocol.samples.unwrap_or(20).max(1);
        let (mut t, mut d) = (vec![0.0], vec![0.0]);
        let mut timed = false;
        for (i, s) in protocol.segments.iter().enumerate() {
            let (t0, d0) = (*t.last().unwrap(), *d.last().unwrap());
            if let Some(to) = s.ramp_to.or(s.unload_to) {
                let dt = s.time.unwrap_or((to - d0).abs());
                timed |= s.time.is_some();
                for k in 1..=n {
                    let x = k as f64 / n as f64;
                    t.push(t0 + x * dt);
                    d.push(d0 + x * (to - d0));
                }
            } else if let Some(h) = s.hold {
                timed = true;
                for k in 1..=n {
                    t.push(t0 + h * k as f64 / n as f64);
                    d.push(d0);
                }
            } else {
                return Err(bad(
                    format!("protocol.segments[{i}]"),
                    "expected ramp_to, unload_to or hold",
                ));
            }
        }
        Ok(if timed {
            Loading::timed(Drive::DisplacementMm, t, d)
        } else {
            Loading::quasi_static(Drive::DisplacementMm, d)
        })
    }
}
