//! The exact friction derivative away from the truth: the needle with
//! Coulomb friction 0.345 (a point a calibration towards friction 0.8
//! visits) pushed 7 mm into a 20 mm cylinder, where contact points switch
//! between stick and slip from increment to increment. The exact columns
//! of C10 and the friction against central differences of whole runs.
//!
//! The whole runs' forces are only piecewise smooth in the friction (every
//! switch between stick and slip is a kink), so their differences use a
//! step of 1e-4 of the parameter, small enough to fall between kinks here
//! (steps of 1e-3 and 1e-2 straddle some and move the differences by up to
//! 15 % and a factor 8 at 1.5 to 3 mm, while the exact column stays put).

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{N1Needle, ToolShape};

const C10: f64 = 1101.295e-6;

/// The exact derivatives of the force at every depth against central
/// differences of whole runs (step 1e-4 of each parameter): per parameter,
/// the largest deviation relative to the largest difference quotient.
#[test]
fn friction_derivative_through_stick_slip_switches() {
    let mut m = N1Needle::new("neo-hookean".parse().unwrap());
    m.radius = 20.0;
    m.height = 20.0;
    m.tool = ToolShape::n1_needle();
    m.friction = 0.345;
    m.grading = Some(Grading {
        h_fine: 0.5,
        fine_length: 2.0,
        growth: 1.5,
    });
    m.options.tolerance = 1e-12;
    m.options.max_step = 0.25;
    m.set_friction_parameter(true);
    let theta = [C10, 0.345];
    let depths: Vec<f64> = (1..=14).map(|k| 0.5 * k as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths);
    let sim = m.simulate_sensitivities(&theta, &loading).unwrap();
    assert_eq!(sim.forces, m.predict(&theta, &loading).unwrap());
    for j in 0..theta.len() {
        let h = 1e-4 * theta[j];
        let at = |s: f64| {
            let mut t = theta.to_vec();
            t[j] += s * h;
            m.predict(&t, &loading).unwrap()
        };
        let (p, q) = (at(1.0), at(-1.0));
        let fd: Vec<f64> = p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect();
        let exact: Vec<f64> = sim.derivatives.iter().map(|d| d[j][0]).collect();
        let scale = fd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let worst = exact
            .iter()
            .zip(&fd)
            .fold(0.0f64, |a, (e, f)| a.max((e - f).abs()))
            / scale;
        eprintln!("parameter {j}: exact {exact:?}\n  fd {fd:?}\n  deviation {worst:.3e}");
        // without the branches held, the friction column at 7 mm was 3.28
        // N against 0.068 N from the whole runs
        assert!(scale > 0.0 && worst < 1e-6, "parameter {j}: {worst:.3e}");
    }
}
