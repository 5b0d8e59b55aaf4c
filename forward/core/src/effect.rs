//! Canonical names of unmodelled effects (`GAP.md`, "Effect library").

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// An effect that a base model leaves out and an enrichment adds.
///
/// The `Display`/`FromStr` spelling is the canonical snake-case name used in
/// JSON, manifests and the CLI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    MaterialForm,
    Viscoelasticity,
    ZeroOffset,
    Compressibility,
    Friction,
    ModellingSpace,
    BoundaryCondition,
    ToolCompliance,
    Inclusion,
    /// Different stiffness in compression and in tension (bimodular
    /// response, e.g. brain tissue; Budday et al. 2017): only visible in a
    /// record that spans both.
    TensionCompressionAsymmetry,
}

impl Effect {
    /// Every effect, in the order of `GAP.md` (then the homogeneous-test
    /// effect `tension_compression_asymmetry`).
    pub const ALL: [Effect; 10] = [
        Effect::MaterialForm,
        Effect::Viscoelasticity,
        Effect::ZeroOffset,
        Effect::Compressibility,
        Effect::Friction,
        Effect::ModellingSpace,
        Effect::BoundaryCondition,
        Effect::ToolCompliance,
        Effect::Inclusion,
        Effect::TensionCompressionAsymmetry,
    ];

    /// Canonical snake-case name.
    pub fn name(self) -> &'static str {
        match self {
            Effect::MaterialForm => "material_form",
            Effect::Viscoelasticity => "viscoelasticity",
            Effect::ZeroOffset => "zero_offset",
            Effect::Compressibility => "compressibility",
            Effect::Friction => "friction",
            Effect::ModellingSpace => "modelling_space",
            Effect::BoundaryCondition => "boundary_condition",
            Effect::ToolCompliance => "tool_compliance",
            Effect::Inclusion => "inclusion",
            Effect::TensionCompressionAsymmetry => "tension_compression_asymmetry",
        }
    }
}

impl PartialEq<str> for Effect {
    fn eq(&self, other: &str) -> bool {
        self.name() == other
    }
}

impl PartialEq<&str> for Effect {
    fn eq(&self, other: &&str) -> bool {
        self.name() == *other
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

impl FromStr for Effect {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Effect::ALL
            .iter()
            .copied()
            .find(|e| e.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Effect::ALL.iter().map(|e| e.name()).collect();
                format!("unknown effect `{s}`; expected one of {}", names.join(", "))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn names_round_trip() {
        for e in Effect::ALL {
            assert_eq!(e.name().parse::<Effect>().unwrap(), e);
            assert_eq!(e.to_string(), e.name());
        }
        assert!("viscosity".parse::<Effect>().is_err());
    }

    /// JSON (results, reports) spells an effect as its canonical name and
    /// reads it back.
    #[test]
    fn serde_round_trips_through_the_canonical_name() {
        for e in Effect::ALL {
            let json = serde_json::to_string(&e).unwrap();
            assert_eq!(json, format!("\"{}\"", e.name()));
            assert_eq!(serde_json::from_str::<Effect>(&json).unwrap(), e);
        }
        assert!(serde_json::from_str::<Effect>("\"viscosity\"").is_err());
    }
}
