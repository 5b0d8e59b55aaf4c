//! Exact parameter sensitivities by direct differentiation through the
//! converged increments (`palpate_fe::sensitivity`) against central finite
//! differences of whole runs: the axisymmetric cylinder (frictionless and
//! bonded base, a sphere and the needle, exact and penalty
//! incompressibility), the N3 block in 3D, Coulomb friction with stick
//! and slip, and Prony weights and times through ramp, hold and unload; and
//! the history's derivatives shown necessary (dropping them is wrong).
//!
//! Small meshes (a 10 mm cylinder, a 6 mm block) keep each test within a
//! few seconds; the Newton tolerance is tightened to 1e-12 so that the
//! finite differences of whole runs resolve 1e-6 of the derivatives.

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{Bulk, FeModel, N1Needle, N3Needle, Setup, Support, ToolShape};

const C10: f64 = 1101.295e-6;

/// A 10 mm cylinder under a tool, graded from 0.5 mm elements.
fn cylinder(law: &str, tool: ToolShape, friction: f64) -> N1Needle {
    let mut m = N1Needle::new(law.parse().unwrap());
    m.radius = 10.0;
    m.height = 10.0;
    m.tool = tool;
    m.friction = friction;
    m.grading = Some(Grading {
        h_fine: 0.5,
        fine_length: 2.0,
        growth: 1.5,
    });
    m.options.tolerance = 1e-12;
    m.options.max_step = 0.25;
    m
}

fn sphere() -> ToolShape {
    ToolShape::Sphere { radius: 3.0 }
}

/// The derivatives of the first output against central differences of
/// whole runs with steps `rel * |theta_j|`; returns per parameter the
/// largest deviation relative to the largest derivative of that parameter.
fn deviations<S: Setup>(
    m: &FeModel<S>,
    theta: &[f64],
    loading: &Loading,
    rel: f64,
    drop_history: bool,
) -> Vec<f64> {
    let sim = if drop_history {
        m.simulate_sensitivities_without_history(theta, loading)
    } else {
        m.simulate_sensitivities(theta, loading)
    }
    .unwrap();
    // the differentiation leaves the run as it was
    assert_eq!(sim.forces, m.predict(theta, loading).unwrap());
    assert_eq!(sim.derivatives.len(), loading.len());
    (0..theta.len())
        .map(|j| {
            let h = rel * theta[j].abs();
            let at = |s: f64| {
                let mut t = theta.to_vec();
                t[j] += s * h;
                m.predict(&t, loading).unwrap()
            };
            let (p, q) = (at(1.0), at(-1.0));
            let fd: Vec<f64> = p.iter().zip(&q).map(|(a, b)| (a - b) / (2.0 * h)).collect();
            let exact: Vec<f64> = sim.derivatives.iter().map(|d| d[j][0]).collect();
            let scale = fd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let dev = exact
                .iter()
                .zip(&fd)
                .fold(0.0f64, |a, (e, f)| a.max((e - f).abs()));
            eprintln!(
                "{} parameter {j}: exact {exact:?}\n  fd {fd:?}\n  deviation {:.3e}",
                m.name(),
                dev / scale
            );
            assert!(scale > 0.0, "parameter {j}: no output depends on it");
            dev / scale
        })
        .collect()
}

fn depths(d: &[f64]) -> Loading {
    Loading::quasi_static(Drive::DisplacementMm, d.to_vec())
}

/// Neo-Hookean, exact incompressibility, a sphere on the bonded cylinder
/// with friction 0.3 (fixed): dF/dC10 (which the force is nearly
/// proportional to) to 1e-6.
#[test]
fn cylinder_neo_hookean_bonded_sphere() {
    let m = cylinder("neo-hookean", sphere(), 0.3);
    let loading = depths(&[0.5, 1.0, 1.5]);
    let dev = deviations(&m, &[C10], &loading, 1e-4, false);
    assert!(dev.iter().all(|d| *d < 1e-6), "{dev:?}");
    // the capability estimators see gives the force and its columns
    let (forces, columns) = m
        .as_sensitivities()
        .expect("every FE model offers sensitivities")
        .predict_with_jacobian(&[C10], &loading)
        .unwrap();
    let sim = m.simulate_sensitivities(&[C10], &loading).unwrap();
    assert_eq!(forces, sim.forces);
    let first: Vec<f64> = sim.derivatives.iter().map(|d| d[0][0]).collect();
    assert_eq!(columns, vec![first]);
}

/// Reduced polynomial (C10, C20) with a bulk modulus of 100 mu (the penalty
/// path, the bulk following the parameters), frictionless needle, the base
/// sliding: both derivatives to 1e-6.
#[test]
fn cylinder_reduced_polynomial_penalty_bulk_sliding_base() {
    let mut m = cylinder("reduced-polynomial:2", ToolShape::n1_needle(), 0.0);
    m.bulk = Bulk::Ratio(100.0);
    m.base = Support::Sliding;
    let dev = deviations(
        &m,
        &[686.428e-6, 1929.606e-6],
        &depths(&[0.5, 1.0, 2.0]),
        1e-4,
        false,
    );
    assert!(dev.iter().all(|d| *d < 1e-6), "{dev:?}");
}

/// The N3 block in 3D (8-node mixed hexahedra, GMRES on the symmetric
/// part's factors), a frictionless sphere: dF/dC10 to 1e-6.
#[test]
fn block_3d_neo_hookean_sphere() {
    let mut m = N3Needle::new("neo-hookean".parse().unwrap());
    m.tool = ToolShape::Sphere { radius: 3.0 };
    m.friction = 0.0;
    m.size = [5.0, 5.0, 5.0];
    m.grading = Some(Grading {
        h_fine: 1.0,
        fine_length: 2.0,
        growth: 1.6,
    });
    m.options.tolerance = 1e-12;
    m.options.max_step = 0.25;
    let dev = deviations(&m, &[C10], &depths(&[0.25, 0.5]), 1e-4, false);
    assert!(dev.iter().all(|d| *d < 1e-6), "{dev:?}");
}

/// The needle with Coulomb friction as a parameter: points stick and slip
/// (both seen at the last state); dF/dC10 and dF/dfriction to 1e-6, the
/// stick points carrying their derivatives. Dropping the history's
/// derivatives (stick points, multipliers, committed positions) is wrong
/// by more than 1e-3.
#[test]
fn friction_with_stick_and_slip() {
    let mut m = cylinder("neo-hookean", ToolShape::n1_needle(), 0.3);
    m.set_friction_parameter(true);
    let theta = [C10, 0.3];
    let loading = depths(&[0.5, 1.0, 1.5, 2.0]);
    let (_, sys) = m.simulate(&theta, &loading, None).unwrap();
    let contact = sys
        .part::<palpate_fe::contact::RigidContact>(1)
        .expect("the tool's contact");
    let (active, slipping) = (contact.active(), contact.slipping());
    assert!(
        slipping > 0 && slipping < active,
        "stick and slip: {active} in contact, {slipping} slipping"
    );
    let dev = deviations(&m, &theta, &loading, 1e-4, false);
    assert!(dev.iter().all(|d| *d < 1e-6), "{dev:?}");
    let dropped = deviations(&m, &theta, &loading, 1e-4, true);
    assert!(dropped.iter().any(|d| *d > 1e-3), "{dropped:?}");
}

/// A one-term Prony series as parameters (g1, tau1) with C10 through a
/// ramp to 1 mm in 1 s, a 2 s hold and an unload to 0.4 mm in 1 s, with a
/// fixed time step: all three derivatives to 1e-6, the internal variables
/// carrying theirs; dropping them is wrong by more than 1e-3.
#[test]
fn prony_through_ramp_hold_unload() {
    let mut m = cylinder("neo-hookean", sphere(), 0.0);
    m.set_prony_parameters(1);
    m.options.max_time_step = Some(0.1);
    let time = vec![0.5, 1.0, 2.0, 3.0, 3.5, 4.0];
    let drive = vec![0.5, 1.0, 1.0, 1.0, 0.7, 0.4];
    let loading = Loading::timed(Drive::DisplacementMm, time, drive);
    let theta = [C10, 0.4, 0.5];
    let dev = deviations(&m, &theta, &loading, 1e-4, false);
    assert!(dev.iter().all(|d| *d < 1e-6), "{dev:?}");
    let dropped = deviations(&m, &theta, &loading, 1e-4, true);
    assert!(dropped.iter().any(|d| *d > 1e-3), "{dropped:?}");
}
