//! The kinds of study step, one file each, and their registry.
//!
//! A step kind is a serde type (the `[steps.KIND]` table of a manifest,
//! `deny_unknown_fields`) implementing [`Step`]: its checks against the rest
//! of the study, its input files, how shards treat it and its run. The
//! registry below turns the list of kinds into [`StepEntry`], the externally
//! tagged enum a manifest's `[[steps]]` tables are read into, so that adding
//! a kind is its file plus one line here.

use crate::run::step::Step;
use serde::Deserialize;

/// Declares the step modules and the [`StepEntry`] enum over their types.
macro_rules! registry {
    ($($module:ident => $variant:ident($ty:ident),)*) => {
        $(pub mod $module;)*

        /// One `[[steps]]` table of a manifest: exactly one step kind.
        #[derive(Debug, Clone, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum StepEntry {
            $($variant($module::$ty),)*
        }

        impl StepEntry {
            /// Every kind, as spelled in manifests.
            pub const KINDS: &'static [&'static str] = &[$(stringify!($module)),*];

            /// The step.
            pub fn step(&self) -> &dyn Step {
                match self {
                    $(StepEntry::$variant(s) => s,)*
                }
            }

            /// The step's kind, as spelled in manifests.
            pub fn kind(&self) -> &'static str {
                match self {
                    $(StepEntry::$variant(_) => stringify!($module),)*
                }
            }
        }
    };
}

registry! {
    calibrate => Calibrate(CalibrateStep),
    diagnose => Diagnose(DiagnoseStep),
    predict => Predict(PredictStep),
    anova => Anova(AnovaStep),
    two_stage => TwoStage(TwoStageStep),
    localize => Localize(LocalizeStep),
    sample => Sample(SampleStep),
    replicates => Replicates(ReplicatesStep),
    replicates_summary => ReplicatesSummary(ReplicatesSummaryStep),
    plan => Plan(PlanStep),
}

impl StepEntry {
    /// The step's name.
    pub fn name(&self) -> &str {
        self.step().name()
    }
}
