//! # palpate-enrich
//!
//! The enrichments of the sim-to-real gap diagnosis (`GAP.md`) that act on
//! *any* forward model, closed-form or finite-element, through
//! `dyn ForwardModel`:
//!
//! * [`ZeroOffset`] — contact starts at a recorded displacement d0;
//! * [`ToolCompliance`] — a series spring between recorded and true travel;
//! * [`Viscoelastic`] — quasi-linear viscoelasticity (Fung) with a Prony
//!   series applied to the wrapped model's prediction (exact for homogeneous
//!   tests, the usual force-level approximation for a structure);
//! * [`TensionCompressionAsymmetry`] — a bimodular homogeneous response;
//! * [`MaterialForm`] with [`richer_law`] — the next richer law of the same
//!   family, with the "off" point that reproduces the base law; of
//!   neo-Hookean, a small family of richer laws ([`richer_laws`]: reduced
//!   polynomial 2-3, Mooney-Rivlin, Ogden 1-2, Gent, Humphrey), each a form
//!   the diagnosis chooses among ([`material_forms`]).
//!
//! Each is zero ("off") at a reachable parameter value, so a score test can
//! differentiate there, and each implements
//! [`Enrichable`](palpate_core::Enrichable) so that enrichments compose.
//! Model crates (`palpate-analytic`, `palpate-fe`) offer them from their own
//! [`Enrichable::enrich`](palpate_core::Enrichable::enrich); this crate
//! depends on palpate-core and palpate-material only.
//!
//! ```
//! use palpate_analytic::C1Compression;
//! use palpate_core::{Drive, Enrichable, ForwardModel, Loading};
//! use palpate_enrich::ZeroOffset;
//! use palpate_material::Law;
//!
//! let base = C1Compression::new(Law::NeoHookean);
//! let shifted = ZeroOffset::new(Box::new(base.clone()));
//! let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.5, 1.0]);
//! // "Off" (d0 = 0) reproduces the base model exactly ...
//! let off = shifted.embed(&[0.03]);
//! assert_eq!(off, [0.03, 0.0]);
//! assert_eq!(shifted.predict(&off, &loading)?, base.predict(&[0.03], &loading)?);
//! // ... and d0 = 0.5 mm delays contact by half a millimetre.
//! let f = shifted.predict(&[0.03, 0.5], &loading)?;
//! assert_eq!(f[1], 0.0);
//! assert_eq!(f[2], base.predict(&[0.03], &Loading::quasi_static(Drive::DisplacementMm, vec![0.5]))?[0]);
//! # Ok::<(), palpate_core::ForwardError>(())
//! ```

mod asymmetry;
mod convert;
mod material_form;
mod tool_compliance;
mod viscoelastic;
mod wrap;
mod zero_offset;

pub use asymmetry::TensionCompressionAsymmetry;
pub use convert::law_space;
pub use material_form::{material_forms, richer_law, richer_laws, LawMap, MaterialForm, RicherLaw};
pub use tool_compliance::ToolCompliance;
pub use viscoelastic::{check_prony, prony_params, qlv_convolve, Viscoelastic};
pub use wrap::{wrap, wrapper_effects, DEFAULT_PRONY_TERMS, WRAPPER_EFFECTS};
pub use zero_offset::ZeroOffset;
