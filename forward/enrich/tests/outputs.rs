//! The wrappers keep the outputs of a model with several
//! (`ForwardModel::outputs`): zero offset shifts the drive of every output,
//! QLV relaxes each output with the same function, tool compliance solves the
//! travel with the first output and reports every output at it, the richer
//! law passes them on; and the first column is always `predict`.

use palpate_core::{
    Drive, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output, ParamSpace,
    ParamSpec,
};
use palpate_enrich::{qlv_convolve, MaterialForm, ToolCompliance, Viscoelastic, ZeroOffset};

/// A stiffening spring pushed along y that also pushes sideways:
/// F_y = k d + a d^2, F_x = k d / 2 - a d^2.
struct Sideways(ParamSpace);

fn forces(t: &[f64], d: f64) -> [f64; 2] {
    [t[0] * d + t[1] * d * d, 0.5 * t[0] * d - t[1] * d * d]
}

struct Eval;

impl Evaluator for Eval {
    fn predict_into(&mut self, t: &[f64], l: &Loading, o: &mut [f64]) -> Result<(), ForwardError> {
        for (o, d) in o.iter_mut().zip(&l.drive) {
            *o = forces(t, *d)[0];
        }
        Ok(())
    }
    fn predict_outputs_into(
        &mut self,
        t: &[f64],
        l: &Loading,
        o: &mut [f64],
    ) -> Result<(), ForwardError> {
        palpate_core::check_output_slots(o.len(), l.len(), 2)?;
        for (row, d) in o.chunks_mut(2).zip(&l.drive) {
            row.copy_from_slice(&forces(t, *d));
        }
        Ok(())
    }
}

impl ForwardModel for Sideways {
    fn name(&self) -> String {
        "sideways spring".into()
    }
    fn space(&self) -> &ParamSpace {
        &self.0
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn outputs(&self) -> Vec<Output> {
        vec![
            Output::new("force_N", Observable::ForceN),
            Output::new("force_x_N", Observable::ForceN),
        ]
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(Eval)
    }
}

fn sideways() -> Sideways {
    Sideways(ParamSpace::new(vec![
        ParamSpec::new("k", "N/mm", 0.0, 10.0, 1.0),
        ParamSpec::new("a", "N/mm2", 0.0, 10.0, 0.1),
    ]))
}

const THETA: [f64; 2] = [2.0, 0.5];

fn loading() -> Loading {
    Loading::timed(
        Drive::DisplacementMm,
        vec![0.0, 0.5, 1.0, 1.5, 3.0, 6.0],
        vec![0.0, 0.5, 1.0, 1.5, 1.5, 1.5],
    )
}

/// Every wrapper lists the wrapped model's outputs, and its first column is
/// its one-output prediction.
fn passes_outputs(m: &dyn ForwardModel, theta: &[f64]) -> Vec<Vec<f64>> {
    assert_eq!(m.outputs(), sideways().outputs(), "{}", m.name());
    let columns = m.predict_outputs(theta, &loading()).unwrap();
    assert_eq!(columns.len(), 2);
    assert_eq!(
        columns[0],
        m.predict(theta, &loading()).unwrap(),
        "{}",
        m.name()
    );
    let mut short = vec![0.0; loading().len()];
    let err = m
        .evaluator()
        .predict_outputs_into(theta, &loading(), &mut short)
        .unwrap_err();
    assert!(err.to_string().contains("2 outputs"), "{}: {err}", m.name());
    columns
}

#[test]
fn zero_offset_shifts_the_drive_of_every_output() {
    let m = ZeroOffset::new(Box::new(sideways()));
    let columns = passes_outputs(&m, &[THETA[0], THETA[1], 0.5]);
    for (i, d) in loading().drive.iter().enumerate() {
        let f = forces(&THETA, (d - 0.5).max(0.0));
        assert_eq!([columns[0][i], columns[1][i]], f, "sample {i}");
    }
    // off: the base model exactly
    let off = m.predict_outputs(&[THETA[0], THETA[1], 0.0], &loading());
    assert_eq!(
        off.unwrap(),
        sideways().predict_outputs(&THETA, &loading()).unwrap()
    );
}

#[test]
fn qlv_relaxes_every_output_with_the_same_function() {
    let m = Viscoelastic::new(Box::new(sideways()), 1);
    let prony = [0.4, 2.0];
    let columns = passes_outputs(&m, &[THETA[0], THETA[1], prony[0], prony[1]]);
    let elastic = sideways().predict_outputs(&THETA, &loading()).unwrap();
    let time = loading().time.unwrap();
    for j in 0..2 {
        let mut relaxed = vec![0.0; time.len()];
        qlv_convolve(&time, &elastic[j], &prony, &mut relaxed);
        assert_eq!(columns[j], relaxed, "output {j}");
    }
    // the hold relaxes the vertical force
    assert!(columns[0][5] < columns[0][3]);
}

#[test]
fn tool_compliance_solves_with_the_first_output_and_reports_all_at_that_travel() {
    let m = ToolCompliance::new(Box::new(sideways()));
    let c = 0.05;
    let columns = passes_outputs(&m, &[THETA[0], THETA[1], c]);
    for (i, d) in loading().drive.iter().enumerate() {
        let u = d - c * columns[0][i];
        let f = forces(&THETA, u);
        assert!((f[0] - columns[0][i]).abs() < 1e-9, "sample {i}");
        assert!((f[1] - columns[1][i]).abs() < 1e-9, "sample {i}");
    }
    assert!(columns[0][3] < forces(&THETA, 1.5)[0]);
}

#[test]
fn richer_law_and_compositions_pass_the_outputs_on() {
    let richer = MaterialForm::new(
        Box::new(sideways()),
        Vec::new(),
        "linear".into(),
        sideways().space().clone(),
    );
    assert_eq!(
        passes_outputs(&richer, &THETA),
        sideways().predict_outputs(&THETA, &loading()).unwrap()
    );
    let both = ZeroOffset::new(Box::new(Viscoelastic::new(Box::new(sideways()), 1)));
    passes_outputs(&both, &[THETA[0], THETA[1], 0.4, 2.0, 0.25]);
}
