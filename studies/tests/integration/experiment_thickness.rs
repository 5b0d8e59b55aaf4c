//! The `boundary_condition` effect of a described cylinder on a bonded
//! base: the specimen's thickness as a parameter (`thickness_mm`). At the
//! described height the enriched model is the base, bit for bit; at
//! another thickness it is close to the description of that thickness
//! (the same cells stretched below the fine zone instead of a mesh of its
//! own); the sliding base is its second form, on a described cylinder as
//! on the N1 model. The fast test of the effect that
//! `experiment_diagnose.rs` diagnoses with.

use palpate_core::enrichable::{effects_of, embed, enrich, enrich_forms};
use palpate_core::{Drive, Effect, ForwardModel, Loading};
use palpate_fe::experiment::Experiment;
use palpate_fe::N1Needle;
use palpate_material::Law;

/// A 2.5 mm sphere on a bonded gel cylinder `height` mm high, 4-node
/// elements at level 1, meshed for a ramp to 0.5 mm.
fn gel(height: f64) -> Box<dyn ForwardModel> {
    let text = format!(
        "[specimen]\nshape = \"cylinder\"\nradius = 20.0\nheight = {height}\nsupport = \"bonded\"\n\
         [materials.gel]\nlaw = \"neo-hookean\"\nC10 = {{ start = 2e-3 }}\n\
         [tool]\nshape = \"sphere\"\nradius = 2.5\n\
         [protocol]\nsegments = [{{ ramp_to = 0.5 }}]\n\
         [mesh]\nlevel = 1\nelement = \"quad4\"\n"
    );
    let e: Experiment = toml::from_str(&text).unwrap();
    e.model().unwrap().boxed()
}

fn loading() -> Loading {
    Loading::quasi_static(Drive::DisplacementMm, vec![0.1, 0.2, 0.3, 0.4, 0.5])
}

#[test]
fn a_described_bonded_cylinder_offers_its_thickness() {
    let base = gel(40.0);
    let offered = effects_of(base.as_ref());
    assert!(offered.contains(&Effect::BoundaryCondition), "{offered:?}");
    // N3's block is the 3D counterpart of N1's specimen only
    assert!(!offered.contains(&Effect::ModellingSpace), "{offered:?}");
    let rich = enrich(base.as_ref(), Effect::BoundaryCondition).unwrap();
    assert_eq!(rich.space().names(), ["C10", "thickness_mm"]);
    let p = &rich.space().params[1];
    assert!(p.lower < 10.0 && p.upper == 80.0, "{p:?}");
    // a geometric parameter: finite differences, not sensitivities
    assert!(rich.as_sensitivities().is_none());
    assert!(base.as_sensitivities().is_some());
    // one enrichment on top of it: the thickness stays the last parameter
    let further = effects_of(rich.as_ref());
    assert!(!further.contains(&Effect::BoundaryCondition), "{further:?}");
    assert!(!further.contains(&Effect::Friction), "{further:?}");
    let c10 = 5e-3;
    let off = embed(rich.as_ref(), &[c10]);
    assert_eq!(off, [c10, 40.0]);
    let f_base = base.predict(&[c10], &loading()).unwrap();
    assert_eq!(rich.predict(&off, &loading()).unwrap(), f_base);
    // at 10 mm: the described 10 mm layer within 2 %, and stiffer than
    // the 40 mm specimen
    let f_thin = rich.predict(&[c10, 10.0], &loading()).unwrap();
    let f_ten = gel(10.0).predict(&[c10], &loading()).unwrap();
    for ((t, r), b) in f_thin.iter().zip(&f_ten).zip(&f_base) {
        assert!((t - r).abs() < 0.02 * r, "stretched {t} described {r}");
        assert!(t > b, "10 mm {t} 40 mm {b}");
    }
    // the same evaluator, back at the described height: the base again
    let mut ev = rich.evaluator();
    let mut out = vec![0.0; 5];
    ev.predict_into(&[c10, 10.0], &loading(), &mut out).unwrap();
    ev.predict_into(&[c10, 40.0], &loading(), &mut out).unwrap();
    assert_eq!(out, f_base);
}

#[test]
fn the_sliding_base_is_the_second_form_on_every_cylinder() {
    let n1 = N1Needle::new(Law::NeoHookean);
    for model in [gel(40.0), Box::new(n1) as Box<dyn ForwardModel>] {
        let forms = enrich_forms(model.as_ref(), Effect::BoundaryCondition).unwrap();
        let names: Vec<&str> = forms.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["thickness", "sliding_base"], "{}", model.name());
        assert_eq!(forms[1].model.space().len(), model.space().len());
        assert!(forms[1].model.name().contains("sliding base"));
    }
}
