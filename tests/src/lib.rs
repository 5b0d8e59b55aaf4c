//! Cross-crate verification of palpate: the integration tests in `tests/`
//! check forward models against each other and against independent
//! references, through the same trait objects the estimators use.
//!
//! Helpers shared by those tests live here.
pub mod counted;

/// The R2 development experiment of the gap diagnosis:
/// a shorter, thinner block than docs/benchmarks.md R2 so that one rolled pass
/// costs seconds, not minutes — 80 mm long, 20 mm high, 50 mm thick,
/// neo-Hookean tissue, no nodule, bonded bottom, frictionless wheel of
/// diameter 8 mm rolled at RD 3 mm from x = 28 to 52 mm in steps of at most
/// 1 mm (R2's 0.5 mm steps double the cost for the same forces within the
/// solver tolerance); the records
/// (`tools/src/bin/make_gap_r2.rs`) and the diagnoses (`tools/src/bin/gap_fe_effects.rs
/// -- r2`, `tests/integration/gap_fe_effects.rs`) share it.
pub mod r2_dev {
    use palpate_core::{Drive, Loading};
    use palpate_fe::R2Rolling;
    use palpate_material::Law;

    /// Rolling depth (mm).
    pub const RD: f64 = 3.0;

    /// The experiment with elements of `h` mm along the top and around a
    /// nodule.
    pub fn rolling(h: f64) -> R2Rolling {
        let mut r = R2Rolling::new(Law::NeoHookean, Law::NeoHookean, RD);
        r.nodules.clear();
        r.length = 80.0;
        r.height = 20.0;
        r.press_x = START;
        r.roll_to = END;
        r.element_size = Some(h);
        r.options.max_step = 1.0;
        r
    }

    /// Start and end of the rolled pass (mm).
    pub const START: f64 = 28.0;
    pub const END: f64 = 52.0;

    /// The rolled pass sampled every `step` mm from START to END.
    pub fn loading(step: f64) -> Loading {
        let n = ((END - START) / step).round() as usize;
        let x = (0..=n)
            .map(|k| START + (END - START) * k as f64 / n as f64)
            .collect();
        Loading::quasi_static(Drive::PositionMm, x)
    }
}
