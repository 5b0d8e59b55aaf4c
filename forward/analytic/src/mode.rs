//! The homogeneous test modes.

use palpate_core::ForwardError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Homogeneous deformation mode of an incompressible specimen, loaded along
/// direction 1 with principal stretch `s`:
///
/// * `Uniaxial`: lambda = (s, s^-1/2, s^-1/2);
/// * `Equibiaxial`: lambda = (s, s, s^-2);
/// * `Planar` (pure shear): lambda = (s, 1, 1/s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    Uniaxial,
    Equibiaxial,
    Planar,
}

impl Mode {
    /// Canonical spelling.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Uniaxial => "uniaxial",
            Mode::Equibiaxial => "equibiaxial",
            Mode::Planar => "planar",
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Mode {
    type Err = ForwardError;
    /// Accepts `uniaxial`, `biaxial`/`equibiaxial`, `planar`/`pure-shear`
    /// (also `pure_shear`), case-insensitively.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "uniaxial" => Ok(Mode::Uniaxial),
            "biaxial" | "equibiaxial" => Ok(Mode::Equibiaxial),
            "planar" | "pure-shear" | "pure_shear" => Ok(Mode::Planar),
            other => Err(ForwardError::InvalidConfig {
                field: "mode".into(),
                reason: format!("unknown mode `{other}`; expected uniaxial, equibiaxial (biaxial) or planar (pure-shear)"),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn spellings() {
        assert_eq!("biaxial".parse::<Mode>().unwrap(), Mode::Equibiaxial);
        assert_eq!("Pure-Shear".parse::<Mode>().unwrap(), Mode::Planar);
        for m in [Mode::Uniaxial, Mode::Equibiaxial, Mode::Planar] {
            assert_eq!(m.to_string().parse::<Mode>().unwrap(), m);
        }
        assert!("shear".parse::<Mode>().is_err());
    }
}
