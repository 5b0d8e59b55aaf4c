//! Unit tests of the two-stage identification.

use super::*;

/// The setters both option builders (CLI, manifest step) share refuse
/// what they should and keep the old value when they do.
#[test]
fn the_setters_check_their_ranges() {
    let mut o = TwoStageOptions::new(Law::NeoHookean);
    o.set_terms(3).unwrap();
    assert_eq!(o.terms, 3);
    assert!(o.set_terms(0).unwrap_err().contains("1 to 4"));
    assert!(o.set_terms(5).is_err());
    assert_eq!(o.terms, 3);
    o.set_fit_mesh(0.15).unwrap();
    for bad in [0.01, 1.5, f64::NAN] {
        assert!(o.set_fit_mesh(bad).unwrap_err().contains("0.02..1 mm"));
    }
    assert_eq!(o.h_fine, 0.15);
    o.set_time_step(0.5).unwrap();
    for bad in [0.0, -1.0, f64::INFINITY] {
        assert!(o.set_time_step(bad).unwrap_err().contains("positive"));
    }
    assert_eq!(o.max_time_step, 0.5);
    // the correcting mesh: in range and finer than the fit mesh (0.15)
    for bad in [0.01, 0.15, 0.2] {
        assert!(o.set_correct_mesh(bad).is_err(), "{bad}");
    }
    assert!(o.set_correct_mesh(0.2).unwrap_err().contains("finer"));
    assert_eq!(o.correct_h, None);
    o.set_correct_mesh(0.1).unwrap();
    assert_eq!(o.correct_h, Some(0.1));
    // the check mesh: in range and not the mesh the estimates are of
    for bad in [0.0, 0.01, 2.0, f64::NAN] {
        assert!(o.set_mesh_check(bad).unwrap_err().contains("0.02..1 mm"));
    }
    assert!(o.set_mesh_check(0.1).unwrap_err().contains("already"));
    assert_eq!(o.check_h, None);
    o.set_mesh_check(0.0667).unwrap();
    assert_eq!(o.check_h, Some(0.0667));
    let mut plain = TwoStageOptions::new(Law::NeoHookean);
    assert!(plain.set_mesh_check(0.3).unwrap_err().contains("0.3 mm"));
    plain.set_mesh_check(0.15).unwrap();
}

/// A deep record on the default fit mesh gets the note; a shallow one,
/// a corrected fit or a fine fit mesh do not.
#[test]
fn a_deep_record_is_told_of_the_correcting_mesh() {
    let rec = |depth: f64| {
        Q1Record::new(
            "r",
            vec![0.0, 0.5, 10.0],
            vec![0.0, depth, depth],
            vec![0.0, 0.1, 0.05],
        )
        .unwrap()
    };
    let mut o = TwoStageOptions::new(Law::NeoHookean);
    let note = deep_record_note(&rec(5.0), &o).expect("a note at 5 mm");
    assert!(
        note.contains("5 mm") && note.contains("--correct-mesh"),
        "{note}"
    );
    assert!(deep_record_note(&rec(1.0), &o).is_none());
    o.set_correct_mesh(0.1).unwrap();
    assert!(deep_record_note(&rec(5.0), &o).is_none());
    let mut fine = TwoStageOptions::new(Law::NeoHookean);
    fine.set_fit_mesh(0.1).unwrap();
    assert!(deep_record_note(&rec(5.0), &fine).is_none());
}

#[test]
fn the_edge_radius_reaches_both_fit_models() {
    let mut o = TwoStageOptions::new(Law::NeoHookean);
    assert_eq!(
        o.elastic_model().edge_radius,
        palpate_fe::q1::DEFAULT_EDGE_RADIUS
    );
    o.set_edge_radius(1.0).unwrap();
    assert_eq!(o.elastic_model().edge_radius, 1.0);
    assert_eq!(o.viscoelastic_model().edge_radius, 1.0);
    for bad in [0.0, -1.0, 2.0, f64::NAN] {
        assert!(o.set_edge_radius(bad).is_err(), "{bad}");
        assert_eq!(o.edge_radius, 1.0);
    }
}

/// The fit mesh's own punch edge: only with a correcting mesh, which keeps
/// the record's punch; the fit models take it.
#[test]
fn the_fit_edge_needs_a_correcting_mesh_that_keeps_the_records_punch() {
    let mut o = TwoStageOptions::new(Law::NeoHookean);
    let e = o.set_fit_edge_radius(0.6).unwrap_err();
    assert!(e.contains("correcting mesh"), "{e}");
    assert_eq!(o.fit_edge_radius, None);
    o.set_correct_mesh(0.1).unwrap();
    for bad in [0.0, 2.0, f64::NAN] {
        assert!(o.set_fit_edge_radius(bad).is_err(), "{bad}");
    }
    o.set_fit_edge_radius(0.6).unwrap();
    assert_eq!(o.elastic_model().edge_radius, 0.6);
    assert_eq!(o.viscoelastic_model().edge_radius, 0.6);
    let rec = palpate_fe::q1::DEFAULT_EDGE_RADIUS;
    assert_eq!(o.elastic_model_at(0.1).edge_radius, rec);
    assert_eq!(o.viscoelastic_model_at(0.1).edge_radius, rec);
    // a fit edge set on the struct without a correcting mesh is refused by
    // the run
    o.correct_h = None;
    let r = Q1Record::new(
        "r",
        vec![0.0, 0.5, 1.0],
        vec![0.0, 0.5, 0.5],
        vec![0.0, 1.0, 0.9],
    )
    .unwrap();
    let e = identify(&r, &o, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("only with a correcting mesh"), "{e}");
}
