//! The units of a localize step's model (`palpate_studies::apps::localize::units`,
//! what its shards compute one at a time) enumerate to the nodule-free pass
//! plus one scan per design point, each with its own inputs, and assemble,
//! computed in any order and read back from their cached JSON, to the model
//! the unsharded path builds in one go (`Surrogate::build` of the same
//! request, as `LocModel::load_or_build` does): the same surrogate but for
//! its build times, the same predictions bit for bit. Wrong or missing
//! units are refused with the reason. On a cheap analytic stand-in for the
//! FE scan (an R2 scan is a minute of CPU; the FE units themselves are
//! tested by studies/tests/integration/shards.rs, ignored for its cost).

use palpate_core::{
    Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace, ParamSpec,
};
use palpate_studies::apps::localize::units::{ModelRun, ModelUnits};
use palpate_studies::apps::localize::{Baseline, LocModel, LocSetup};
use palpate_uq::surrogate::Surrogate;

/// Force of one nodule at depth d at offset o, over a flat 9 N.
struct Scan(ParamSpace);
struct Eval;
impl Evaluator for Eval {
    fn predict_into(&mut self, t: &[f64], l: &Loading, o: &mut [f64]) -> Result<(), ForwardError> {
        for (o, x) in o.iter_mut().zip(&l.drive) {
            let w = 3.0 + 0.4 * t[0];
            *o = 9.0 + 6.0 * ((24.0 - t[0]) / 18.0).powi(2) * (-x * x / (2.0 * w * w)).exp();
        }
        Ok(())
    }
}
impl ForwardModel for Scan {
    fn name(&self) -> String {
        "analytic nodule scan".into()
    }
    fn space(&self) -> &ParamSpace {
        &self.0
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(Eval)
    }
}

fn scan() -> Scan {
    Scan(ParamSpace::new(vec![ParamSpec::new(
        "depth", "mm", 6.0, 24.0, 15.0,
    )]))
}

fn baseline(setup: &LocSetup) -> Baseline {
    Baseline {
        centre: setup.centre(),
        step: setup.step,
        force: (0..40).map(|k| 9.0 - 0.01 * k as f64).collect(),
        time_s: 0.0,
    }
}

/// A unit's result as a run folder caches it and a shard reads it back.
fn through_json(r: ModelRun) -> ModelRun {
    serde_json::from_str(&serde_json::to_string(&r).unwrap()).unwrap()
}

#[test]
fn units_computed_apart_assemble_to_the_model_built_in_one_go() {
    let setup = LocSetup::r2(6.0);
    let units = ModelUnits::new(&setup, scan()).unwrap();
    assert_eq!(units.len(), 1 + setup.training + setup.holdout);
    // Each unit has its own inputs (its cache key), the same in every process.
    let inputs: Vec<String> = (0..units.len()).map(|k| units.inputs(k)).collect();
    let mut distinct = inputs.clone();
    distinct.sort();
    distinct.dedup();
    assert_eq!(distinct.len(), units.len(), "{inputs:#?}");
    let again = ModelUnits::new(&setup, scan()).unwrap();
    assert!((0..units.len()).all(|k| again.inputs(k) == inputs[k]));
    assert!(inputs[0].contains("baseline") && inputs[1].contains("scan"));

    // The scans in reverse order, as shards would finish them, through JSON.
    let mut runs: Vec<(usize, ModelRun)> = (1..units.len())
        .rev()
        .map(|k| (k, through_json(units.compute(k).unwrap())))
        .collect();
    runs.push((0, through_json(ModelRun::Baseline(baseline(&setup)))));
    runs.sort_by_key(|(k, _)| *k);
    let runs: Vec<ModelRun> = runs.into_iter().map(|(_, r)| r).collect();
    let parts = units.assemble(runs.clone()).unwrap();

    let built = Surrogate::build(&units.request(), None).unwrap();
    let strip = |s: &Surrogate| {
        let mut v: serde_json::Value = serde_json::from_str(&s.to_json()).unwrap();
        v["build_time_s"] = serde_json::Value::Null;
        v["build_cpu_s"] = serde_json::Value::Null;
        v
    };
    assert_eq!(strip(&parts.scan), strip(&built));
    let whole = LocModel::from_parts(&setup, built, baseline(&setup), None, None).unwrap();
    let positions: Vec<f64> = (0..=60).map(|k| 20.0 + 2.0 * k as f64).collect();
    let nodules = [(50.0, 9.0), (95.0, 17.0)];
    let (a, va) = parts.predict(&positions, &nodules, 1.1).unwrap();
    let (b, vb) = whole.predict(&positions, &nodules, 1.1).unwrap();
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert!(va.iter().zip(&vb).all(|(x, y)| x.to_bits() == y.to_bits()));

    // Missing, misplaced or unknown units are refused with the reason.
    let refusal = |runs: Vec<ModelRun>| match units.assemble(runs) {
        Ok(_) => panic!("accepted"),
        Err(e) => format!("{e:#}"),
    };
    let e = refusal(runs[..runs.len() - 1].to_vec());
    assert!(
        e.contains("8 results for the 9 units") && e.contains("RD 6"),
        "{e}"
    );
    let mut swapped = runs.clone();
    swapped.swap(0, 1);
    let e = refusal(swapped);
    assert!(
        e.contains("unit 0") && e.contains("not the baseline"),
        "{e}"
    );
    let e = units.compute(units.len()).unwrap_err().to_string();
    assert!(
        e.contains("unit 9 of a localisation model of 9 units"),
        "{e}"
    );
}

/// With the end lean (the study's default model), its 16 FE scans are
/// units after the design's scans, each with its own inputs; computed
/// apart and read back from JSON they assemble to the centre model plus
/// the lean, whose shifts are the ones planted in the stand-in scans
/// (each a shifted, scaled copy of the centre model's excess).
#[test]
fn lean_scans_are_units_and_assemble_to_the_planted_lean() {
    use palpate_studies::apps::localize::lean;
    use std::sync::Arc;
    let centre = LocSetup::r2(6.0);
    let setup = LocSetup::r2_lean(6.0);
    // the centre model, as the lean-less units assemble it
    let plain = ModelUnits::new(&centre, scan()).unwrap();
    let mut runs: Vec<ModelRun> = vec![ModelRun::Baseline(baseline(&centre))];
    runs.extend((1..plain.len()).map(|k| plain.compute(k).unwrap()));
    let model = Arc::new(plain.assemble(runs.clone()).unwrap());
    // planted lean: shift 0.6 mm at 15 mm from the end falling to 0 at 50,
    // larger for shallow nodules; amplitude 0.95
    let planted = |e: f64, d: f64| 0.6 * (50.0 - e) / 35.0 * (30.0 - d) / 22.0;
    let m = Arc::clone(&model);
    let offsets = setup.lean_offsets();
    let stand_in: palpate_studies::apps::localize::units::LeanScan = Box::new(move |(e, d)| {
        let mut grid = vec![0.0; m.scan.loading().len()];
        m.excess_grid(d, m.centre, &mut grid)
            .map_err(|e| e.to_string())?;
        Ok(offsets
            .iter()
            .map(|&o| m.baseline_at(e + o) + 0.95 * m.excess_at(&grid, o + planted(e, d), false))
            .collect())
    });
    let units = ModelUnits::new(&setup, scan())
        .unwrap()
        .with_lean_scan(stand_in);
    let cases = lean::cases();
    assert_eq!(units.len(), plain.len() + cases.len());
    let inputs: Vec<String> = (0..units.len()).map(|k| units.inputs(k)).collect();
    let mut distinct = inputs.clone();
    distinct.sort();
    distinct.dedup();
    assert_eq!(distinct.len(), units.len(), "{inputs:#?}");
    // the centre units keep their inputs (their cached runs are shared)
    assert!((0..plain.len()).all(|k| plain.inputs(k) == inputs[k]));
    assert!(
        inputs[plain.len()].contains("lean scan") && inputs[plain.len()].contains("distance 15")
    );

    for k in (plain.len()..units.len()).rev() {
        let r = through_json(units.compute(k).unwrap());
        assert!(matches!(r, ModelRun::Lean(_)), "unit {k}: {r:?}");
    }
    let mut all = runs.clone();
    all.extend((plain.len()..units.len()).map(|k| through_json(units.compute(k).unwrap())));
    let parts = units.assemble(all.clone()).unwrap();
    let l = parts.lean.as_ref().expect("the lean");
    for (i, &e) in l.distance.iter().enumerate() {
        for (j, &d) in l.depth.iter().enumerate() {
            // the fit is exact but for the cubic interpolation of the grid
            assert!(
                (l.shift[i][j] - planted(e, d)).abs() < 0.03,
                "e {e} d {d}: {} vs {}",
                l.shift[i][j],
                planted(e, d)
            );
            assert!(
                (l.amplitude[i][j] - 0.95).abs() < 0.02,
                "{}",
                l.amplitude[i][j]
            );
        }
    }
    // the same centre model otherwise
    let positions: Vec<f64> = (0..=60).map(|k| 20.0 + 2.0 * k as f64).collect();
    let mid = [(75.0, 15.0)];
    let (a, _) = parts.predict(&positions, &mid, 1.0).unwrap();
    let (b, _) = model.predict(&positions, &mid, 1.0).unwrap();
    assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12));
    // a centre scan where a lean scan belongs, or one lean scan short: refused
    let mut wrong = all.clone();
    let last = wrong.len() - 1;
    wrong[last] = ModelRun::Scan(Ok(vec![0.0]));
    let refusal = |runs: Vec<ModelRun>| match units.assemble(runs) {
        Ok(_) => panic!("accepted"),
        Err(e) => format!("{e:#}"),
    };
    let e = refusal(wrong);
    assert!(e.contains("not a lean scan"), "{e}");
    let e = refusal(all[..all.len() - 1].to_vec());
    assert!(e.contains("units of the localisation model at RD 6"), "{e}");
}
