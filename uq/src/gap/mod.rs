//! Sim-to-real gap diagnosis (GAP.md): where a calibrated base model misses
//! the data, which unmodelled effect explains it, and by how much adding it
//! shrinks the misfit on fitted and held-out data.
//!
//! The method (details and failure modes in `docs/gap-diagnosis.md`):
//!
//! 1. **Noise** from the data alone: second-order pseudo-residuals
//!    ([`noise::difference_noise_sd`]), blind to a smooth misfit.
//! 2. **Locate**: fit the base model (palpate-inverse, Levenberg-Marquardt);
//!    test its residuals against the noise (chi-square of the misfit, lag-1
//!    autocorrelation, Wald-Wolfowitz runs) and scan running windows for a
//!    significant bias or scatter ([`structure`]); a discrepancy band.
//! 3. **Attribute**: for every effect the base model offers
//!    (`ForwardModel::effects`/`enrich`), a score test at the "off" point
//!    ([`score`]), then a refit from several starts; compare by the
//!    likelihood ratio against the noise, blocked cross-validation (each of
//!    K contiguous blocks predicted by a fit to the others; the last block,
//!    the later segment of the history, is also reported on its own), and
//!    approximate information criteria under AR(1) errors; identifiability
//!    from the calibration report, the overlap of the effects' sensitivities,
//!    and confounding between effects whose fits the data cannot tell apart.
//! 4. **Verdict**: `none` when the base misfit is consistent with noise or no
//!    effect earns its parameters; else the best effect that does.
//! 5. **Explanation**: the verdict is the first member of a set; further
//!    effects join by forward selection with the set as the base, each
//!    assessed as in step 3, until the misfit is noise or nothing earns its
//!    place; a backward check drops members the others make redundant
//!    ([`set`]). Each member's share of the excess misfit, and the
//!    remainder with where it lies.

mod assess;
mod base;
mod compose;
mod crossval;
mod diagnose;
mod error;
mod fit;
mod memo;
pub mod noise;
mod options;
mod plausible;
pub mod profile;
mod rank;
mod report;
mod residual;
pub mod score;
mod set;
mod starts;
pub mod structure;
mod undetectable;
mod verdict;

pub use diagnose::diagnose;
pub use error::GapError;
pub use noise::{difference_noise_sd, path_noise_sd, NoiseEstimate, NoisePaths};
pub use options::{CrossValidation, FoldLayout, GapOptions};
pub use profile::ProfileInterval;
pub use report::{BaseSummary, FailedCandidate, GapPlot, GapReport, PracticalSize, RankedEffect};
pub use score::{score_test, sensitivities, ScoreTest};
pub use set::{Remainder, SetMember};
pub use structure::{discrepancy_band, significant_windows, whiteness, GapWindow, WhitenessTests};
pub use undetectable::Undetectable;
pub use verdict::{PartlyExplained, Verdict};
