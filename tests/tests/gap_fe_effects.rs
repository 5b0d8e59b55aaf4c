//! Gap diagnosis on every FE model (issue 14, item 5) — the cheap part that
//! runs in CI; the heavier runs are release examples
//! (`examples/gap_fe_effects.rs`).
//!
//! * Q1 (`viscoelasticity`): the enrichment's "off" point and its
//!   relaxation. The diagnosis of the records of `tests/data/gap-q1/` (ten
//!   minutes of CPU) is the release example's.
//! * N1 -> N3 (`modelling_space`): the enrichment is the 3D model of the
//!   same needle, law and friction, with the same parameters (a discrete
//!   switch), offered only where N3 has the same physics.

use palpate_core::enrichable::{effects_of, embed, enrich};
use palpate_core::{Drive, Effect, ForwardModel, Loading};
use palpate_fe::{N1Needle, Q1Punch};
use palpate_material::Law;

/// The `viscoelasticity` enrichment of Q1: "off" (g1 = 0) is the elastic
/// model bit for bit; with relaxation the force falls during the hold
/// (monotonically, towards (1 - g1) of its elastic value for a hold much
/// longer than tau1) while the elastic force stays constant. A ramp to
/// 0.5 mm in 0.25 s and a 1.5 s hold on mesh level 2 (level 1 does not
/// converge at the first viscoelastic hold increment, see
/// docs/gap-diagnosis.md).
#[test]
fn q1_viscoelasticity_is_off_at_zero_weight_and_relaxes_in_the_hold() {
    let mut q1 = Q1Punch::new(Law::NeoHookean);
    q1.level = 2;
    assert_eq!(effects_of(&q1), [Effect::Viscoelasticity]);
    let rich = enrich(&q1, Effect::Viscoelasticity).unwrap();
    assert_eq!(rich.space().names(), ["C10", "g1", "tau1_s"]);
    let off = embed(rich.as_ref(), &[1e-3]);
    assert_eq!(off[..2], [1e-3, 0.0]);
    let t: Vec<f64> = (0..=7).map(|i| 0.25 * i as f64).collect();
    let d: Vec<f64> = t.iter().map(|&s| (2.0 * s).min(0.5)).collect();
    let loading = Loading::timed(Drive::DisplacementMm, t, d);
    let elastic = q1.predict(&[1e-3], &loading).unwrap();
    assert_eq!(rich.predict(&off, &loading).unwrap(), elastic);
    let relaxing = rich.predict(&[1e-3, 0.3, 0.2], &loading).unwrap();
    for k in 2..elastic.len() {
        // the hold: constant elastic force, relaxing viscoelastic one
        assert!((elastic[k] - elastic[1]).abs() <= 1e-9 * elastic[1]);
        assert!(relaxing[k] < relaxing[k - 1], "{relaxing:?}");
    }
    let end = relaxing[relaxing.len() - 1] / elastic[elastic.len() - 1];
    assert!(
        (end - 0.7).abs() < 0.03,
        "relaxed to {end} of the elastic force"
    );
}

#[test]
fn modelling_space_turns_the_axisymmetric_needle_into_the_3d_one() {
    let mut n1 = N1Needle::new(Law::NeoHookean);
    n1.friction = 0.3;
    assert!(effects_of(&n1).contains(&Effect::ModellingSpace));
    let n3 = enrich(&n1, Effect::ModellingSpace).unwrap();
    assert_eq!(n3.space().names(), n1.space().names());
    assert!(
        n3.expensive() && n3.name().starts_with("N3"),
        "{}",
        n3.name()
    );
    assert!(n3.name().contains("friction 0.3"), "{}", n3.name());
    assert_eq!(embed(n3.as_ref(), &[1e-3]), [1e-3]);
    // not offered where N3 lacks the physics: a sliding base, friction as
    // a parameter
    let sliding = enrich(&n1, Effect::BoundaryCondition).unwrap();
    assert!(!effects_of(sliding.as_ref()).contains(&Effect::ModellingSpace));
    let rough = enrich(&n1, Effect::Friction).unwrap();
    assert!(!effects_of(rough.as_ref()).contains(&Effect::ModellingSpace));
}
