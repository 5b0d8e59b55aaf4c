//! The staged inverse FE identification of Q1 (`palpate_studies::apps::two_stage`)
//! on a small, short record: a 1 mm mesh under the punch, 0.5 mm depth,
//! a 5 s hold, one Prony term. The record is the fit model's own prediction
//! at known parameters plus a fixed pseudo-random noise (0.3 % of the peak),
//! so the test checks the algorithm (stages, counts, standard errors,
//! profiles), not the discretisation: the estimates must land within 3
//! standard errors and 2 % of the truth, each stage in at most 5 LM
//! iterations from the default start, the profile intervals must be
//! bounded and hold the truth, and the one-stage fit must reach the same
//! optimum. The full study (finer-mesh record, 60 s hold, two terms) is
//! `studies/two-stage-q1.toml`.

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_material::Law;
use palpate_studies::apps::two_stage::{identify, report, Q1Record, TwoStageOptions};

/// C10 (MPa), g1, tau1 (s).
const TRUTH: [f64; 3] = [0.0016, 0.4, 0.8];

fn options() -> TwoStageOptions {
    let mut o = TwoStageOptions::new(Law::NeoHookean);
    o.terms = 1;
    o.h_fine = 1.0;
    o.max_time_step = 0.5;
    o
}

fn record() -> Q1Record {
    record_on(&options())
}

/// The record made on `made_on`'s viscoelastic model.
fn record_on(made_on: &TwoStageOptions) -> Q1Record {
    let mut t: Vec<f64> = (0..=8).map(|i| 0.5 * i as f64 / 8.0).collect();
    let mut d: Vec<f64> = (0..=8).map(|i| 0.5 * i as f64 / 8.0).collect();
    for k in 0..10 {
        t.push(0.5 + 0.05 * 1.5f64.powi(k));
        d.push(0.5);
    }
    let loading = Loading::timed(Drive::DisplacementMm, t.clone(), d.clone());
    let f = made_on
        .viscoelastic_model()
        .predict(&TRUTH, &loading)
        .expect("the record's run");
    let peak = f.iter().cloned().fold(0.0, f64::max);
    // a fixed zero-mean pseudo-noise (golden-ratio sequence)
    let noisy = f
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let u = (k as f64 * 0.618_033_988_75).fract() - 0.5;
            v + 0.003 * peak * 2.0 * u
        })
        .collect();
    Q1Record::new("short", t, d, noisy).expect("a valid record")
}

#[test]
fn two_stage_recovers_the_parameters_in_few_iterations() {
    let rec = record();
    let result = identify(&rec, &options(), &|_| {}).expect("identification");
    eprintln!("{}", report(&result, Some(&TRUTH)));
    let names: Vec<&str> = result.stages.iter().map(|s| s.stage.as_str()).collect();
    assert_eq!(names, ["elastic", "relaxation", "polish"]);
    assert_eq!(result.stages[0].free, ["C10"]);
    assert_eq!(result.stages[1].free, ["g1", "tau1_s"]);
    // the ramp only in stage 1
    assert_eq!(result.stages[0].samples, 9);
    for s in &result.stages {
        assert!(
            s.converged,
            "{} did not converge: {}",
            s.stage, s.termination
        );
        assert!(
            s.iterations <= 5,
            "{}: {} iterations",
            s.stage,
            s.iterations
        );
        assert!(s.fe_runs > s.iterations as usize);
    }
    // the elastic fit of the ramp of a relaxing record is below the
    // instantaneous modulus; the force-level QLV correction brings it within 3 %
    let s1 = &result.stages[0];
    assert!(
        s1.fit.parameters[0].value < 0.97 * TRUTH[0],
        "{}",
        s1.fit.parameters[0].value
    );
    assert!(s1.correction.expect("a correction") > 1.0);
    assert!(
        (s1.theta[0] / TRUTH[0] - 1.0).abs() < 0.03,
        "{:?}",
        s1.theta
    );
    let polish = &result.stages[2];
    for (k, e) in polish.fit.parameters.iter().enumerate() {
        let se = e.standard_error.expect("a standard error");
        assert!(
            (e.value - TRUTH[k]).abs() <= 3.0 * se && (e.value / TRUTH[k] - 1.0).abs() < 0.02,
            "{} = {} +- {se}, truth {}",
            e.name,
            e.value,
            TRUTH[k]
        );
        let p = &result.profiles[k];
        let (lo, hi) = (
            p.lower.expect("bounded below"),
            p.upper.expect("bounded above"),
        );
        assert!(lo < TRUTH[k] && TRUTH[k] < hi, "{}: [{lo}, {hi}]", e.name);
        // near-linear model: the profile interval is close to +-1.96 SE
        assert!(((hi - lo) / (2.0 * 1.96 * se) - 1.0).abs() < 0.5, "{p:?}");
    }
    let one = result.one_stage.as_ref().expect("the comparison");
    for (a, b) in one.theta.iter().zip(&polish.theta) {
        assert!(
            (a / b - 1.0).abs() < 0.01,
            "{:?} vs {:?}",
            one.theta,
            polish.theta
        );
    }
}

/// The stages option: the order is elastic,relaxation; unknown names are refused.
#[test]
fn stages_are_parsed_and_checked() {
    assert_eq!(
        TwoStageOptions::parse_stages("elastic, relaxation").unwrap(),
        ["elastic", "relaxation"]
    );
    let e = TwoStageOptions::parse_stages("relaxation,elastic").unwrap_err();
    assert!(e.to_string().contains("order elastic,relaxation"), "{e}");
    let e = TwoStageOptions::parse_stages("elastic,viscous").unwrap_err();
    assert!(e.to_string().contains("unknown stage `viscous`"), "{e}");
}

/// The study manifests parse and validate (the record exists, the options
/// hold); a correcting mesh no finer than the fit mesh is refused by field.
#[test]
fn the_study_manifest_is_valid() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let edge1 = dir.join("two-stage-q1-5mm-edge1.toml");
    let m = palpate_studies::study::manifest::Manifest::read(&edge1).unwrap();
    m.validate(&edge1).unwrap();
    let deep = dir.join("two-stage-q1-5mm.toml");
    let m = palpate_studies::study::manifest::Manifest::read(&deep).unwrap();
    m.validate(&deep).unwrap();
    let coarse = std::fs::read_to_string(&deep)
        .unwrap()
        .replace("correct_mesh = 0.1", "correct_mesh = 0.3");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("coarse.toml");
    std::fs::write(&p, coarse).unwrap();
    let e = palpate_studies::study::manifest::Manifest::read(&p)
        .unwrap()
        .validate(&p)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("correct_mesh = 0.3") && e.contains("finer than the fit mesh"),
        "{e}"
    );
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("two-stage-q1.toml");
    let m = palpate_studies::study::manifest::Manifest::read(&path).unwrap();
    m.validate(&path).unwrap();
    let mut bad = std::fs::read_to_string(&path).unwrap();
    bad = bad.replace("time_step = 1.0", "time_step = 0.0");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.toml");
    std::fs::write(&p, bad).unwrap();
    let m = palpate_studies::study::manifest::Manifest::read(&p).unwrap();
    let e = m.validate(&p).unwrap_err().to_string();
    assert!(
        e.contains("steps[0].two_stage (\"q1-liver\").time_step = 0"),
        "{e}"
    );
}

/// A record made on a 0.5 mm mesh, and options that fit it on the 1 mm mesh
/// with the elastic stage and the polish only.
fn fine_record_and_elastic_stage() -> (Q1Record, TwoStageOptions) {
    let mut fine = options();
    fine.h_fine = 0.5;
    let mut o = options();
    o.stages = vec!["elastic".into()];
    o.one_stage = false;
    o.profile = false;
    (record_on(&fine), o)
}

/// Every estimate of `stage` within 2 of its standard errors of the truth.
fn assert_within_2_se(stage: &palpate_studies::apps::two_stage::StageResult) {
    for (k, e) in stage.fit.parameters.iter().enumerate() {
        let se = e.standard_error.expect("a standard error");
        assert!(
            (e.value - TRUTH[k]).abs() <= 2.0 * se,
            "{} = {} +- {se}, truth {}",
            e.name,
            e.value,
            TRUTH[k]
        );
    }
}

/// A record from a finer mesh than the fits' (0.5 mm under the punch, the
/// fits 1 mm): the plain fit is biased by the fit mesh's stiffness; the fit
/// corrected to the record's mesh (`correct_h`, output space mapping) lands
/// on the truth, as the fine mesh's own fit would, with few runs of it.
#[test]
fn the_mesh_correction_removes_the_fit_mesh_bias() {
    let (rec, plain) = fine_record_and_elastic_stage();
    let mut corrected = plain.clone();
    corrected.set_correct_mesh(0.5).unwrap();
    let biased = identify(&rec, &plain, &|_| {}).expect("the plain fit");
    let result = identify(&rec, &corrected, &|s| eprintln!("{s}")).expect("the corrected fit");
    eprintln!("{}", report(&biased, Some(&TRUTH)));
    eprintln!("{}", report(&result, Some(&TRUTH)));
    let polish = result.stages.last().unwrap();
    let stiff = biased.stages.last().unwrap();
    assert_within_2_se(polish);
    let mut worst_plain = 0.0f64;
    for (k, e) in polish.fit.parameters.iter().enumerate() {
        let se = e.standard_error.expect("a standard error");
        worst_plain = worst_plain.max((stiff.theta[k] - TRUTH[k]).abs() / se);
    }
    assert!(worst_plain > 4.0, "the plain fit is {worst_plain} SE off");
    // one correcting run per stage, and a polish that settles in 2-3 rounds
    assert_eq!(result.stages[0].mesh_corrections.len(), 1);
    assert!((2..=3).contains(&polish.mesh_corrections.len()));
    assert!(polish.round_iterations[1..].iter().all(|&i| i <= 2));
}

/// The fit mesh with a punch of its own (a 1.5 mm edge, which the 1 mm cells
/// resolve; the record's is 0.2 mm), corrected to the record's punch on the
/// 0.5 mm mesh: the estimates land on the truth as with the fit mesh's
/// punch the record's (the test above), and the report names the fit edge.
#[test]
fn a_fit_mesh_with_its_own_punch_edge_is_corrected_to_the_records() {
    let (rec, mut o) = fine_record_and_elastic_stage();
    o.set_correct_mesh(0.5).unwrap();
    o.set_fit_edge_radius(1.5).unwrap();
    let result = identify(&rec, &o, &|s| eprintln!("{s}")).expect("the corrected fit");
    let text = report(&result, Some(&TRUTH));
    eprintln!("{text}");
    assert!(text.contains("edge rounded 1.5 mm"), "{text}");
    // the estimates are of the record's punch: the header names it
    assert!(result.model.contains("edge 0.2 mm"), "{}", result.model);
    assert_within_2_se(result.stages.last().unwrap());
    // the uncorrected fit mesh with this punch is far off: the correction
    // did the work
    let mut own = options();
    own.edge_radius = 1.5;
    let f_own = own
        .viscoelastic_model()
        .predict(&TRUTH, &record_loading(&rec))
        .unwrap();
    let mut fine = options();
    fine.h_fine = 0.5;
    let f_rec = fine
        .viscoelastic_model()
        .predict(&TRUTH, &record_loading(&rec))
        .unwrap();
    let k = rec.ramp_end();
    assert!(
        f_own[k] < 0.9 * f_rec[k],
        "{} against {}",
        f_own[k],
        f_rec[k]
    );
}

fn record_loading(rec: &Q1Record) -> Loading {
    Loading::timed(Drive::DisplacementMm, rec.time.clone(), rec.depth.clone())
}

/// Correction rounds that run out with the anchor still moving are flagged:
/// the one-stage fit from the default start, allowed 2 rounds, moves far in
/// its first (its correction made at the start) and still more than 0.1 SE
/// in its second; the polish, from the elastic stage, settles.
#[test]
fn correction_rounds_that_run_out_are_flagged() {
    let (rec, mut o) = fine_record_and_elastic_stage();
    o.set_correct_mesh(0.5).unwrap();
    o.set_fit_edge_radius(1.5).unwrap();
    o.one_stage = true;
    o.correction_rounds = 2;
    let result = identify(&rec, &o, &|s| eprintln!("{s}")).expect("the corrected fits");
    let text = report(&result, Some(&TRUTH));
    eprintln!("{text}");
    let polish = result.stages.last().unwrap();
    assert!(polish.settled, "{}", polish.last_round_move_se);
    assert!(polish.last_round_move_se <= 0.1);
    let one = result.one_stage.as_ref().unwrap();
    assert_eq!(one.mesh_corrections.len(), 2);
    assert!(!one.settled, "{}", one.last_round_move_se);
    assert!(one.last_round_move_se > 0.1);
    assert!(
        text.contains("one-stage: the correction rounds ran out"),
        "{text}"
    );
    assert!(!text.contains("polish: the correction rounds ran out"));
}

/// A polish that starts at its optimum accepts no step, and the report says
/// so (the sign of a start at the optimum or of a model with jumps).
#[test]
fn a_polish_that_does_not_move_is_flagged() {
    let mut o = options();
    o.stages = Vec::new();
    o.one_stage = false;
    o.profile = false;
    let model = o.viscoelastic_model();
    let start: Vec<f64> = model.space().params.iter().map(|p| p.initial).collect();
    let t: Vec<f64> = vec![0.0, 0.25, 0.5, 1.0, 2.0];
    let d: Vec<f64> = vec![0.0, 0.25, 0.5, 0.5, 0.5];
    let loading = Loading::timed(Drive::DisplacementMm, t.clone(), d.clone());
    let f = model.predict(&start, &loading).expect("the record's run");
    let rec = Q1Record::new("at the start", t, d, f).unwrap();
    let result = identify(&rec, &o, &|_| {}).expect("identification");
    let polish = result.stages.last().unwrap();
    assert!(!polish.moved, "{:?}", polish.theta);
    for (a, b) in polish.theta.iter().zip(&start) {
        assert!((a / b - 1.0).abs() < 1e-12, "{:?}", polish.theta);
    }
    let text = report(&result, None);
    assert!(text.contains("polish: no LM step was accepted"), "{text}");
    // a fit that moves is not flagged
    let moved = identify(&record(), &options(), &|_| {}).expect("identification");
    assert!(moved.stages.iter().all(|s| s.moved));
    assert!(!report(&moved, None).contains("no LM step"));
}

/// The mesh check: a plain fit on the 1 mm mesh of a record made on the
/// 0.5 mm mesh is biased (the test above); its check on the record's mesh
/// (`check_h`, corrected rounds from the polish) moves the estimates by
/// several standard errors onto the truth, as the record's mesh's own fit
/// would, and the report gives each shift.
#[test]
fn the_mesh_check_moves_a_biased_fit_onto_the_records_mesh() {
    let (rec, mut o) = fine_record_and_elastic_stage();
    o.set_mesh_check(0.5).unwrap();
    let result = identify(&rec, &o, &|s| eprintln!("{s}")).expect("the fit and its check");
    let text = report(&result, Some(&TRUTH));
    eprintln!("{text}");
    let check = result.mesh_check.as_ref().expect("a mesh check");
    let polish = result.stages.last().unwrap();
    let largest = check
        .shift_se
        .iter()
        .map(|s| s.expect("a standard error").abs())
        .fold(0.0, f64::max);
    assert!(largest > 4.0, "{:?}", check.shift_se);
    // round by round as the polish: the second round settles
    assert!(
        check.settled && (2..=3).contains(&check.rounds),
        "{check:?}"
    );
    for (k, e) in polish.fit.parameters.iter().enumerate() {
        let se = e.standard_error.unwrap();
        assert!(
            (check.theta[k] - TRUTH[k]).abs() <= 2.0 * se,
            "{}: {} on the check mesh, truth {}",
            e.name,
            check.theta[k],
            TRUTH[k]
        );
    }
    assert!(
        text.contains("**Mesh check**") && text.contains("on the 0.5 mm mesh"),
        "{text}"
    );
    // no check unless asked
    assert!(identify(&record(), &options(), &|_| {})
        .unwrap()
        .mesh_check
        .is_none());
}
