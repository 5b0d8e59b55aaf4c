//! The simple-shear, general-biaxial and finite-strain viscoelastic
//! kinematics against finite differences of the law's energy and against
//! closed forms.

use palpate_analytic::{GeneralBiaxial, Homogeneous, Mode, SimpleShear, ViscousUniaxial};
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_enrich::Viscoelastic;
use palpate_material::Law;

fn laws() -> Vec<(Law, Vec<f64>)> {
    vec![
        (Law::NeoHookean, vec![0.3]),
        (Law::MooneyRivlin, vec![0.2, 0.05]),
        (Law::ReducedPolynomial(3), vec![0.2, -0.01, 0.002]),
        (Law::ArrudaBoyce, vec![0.4, 3.0]),
        (Law::Ogden(1), vec![0.5, -8.0]),
        (Law::Ogden(2), vec![0.4, 2.5, 0.05, -3.0]),
        (Law::Gent, vec![0.4, 10.0]),
        (Law::VerondaWestmann, vec![1.0, 0.3]),
        (Law::Humphrey, vec![0.5, 0.6]),
    ]
}

/// Central difference of `f` at `x` with step `h`.
fn fd(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    (f(x + h) - f(x - h)) / (2.0 * h)
}

#[test]
fn shear_stress_is_the_derivative_of_the_energy_along_the_shear() {
    for (law, p) in laws() {
        for lambda in [0.75, 1.0, 1.25] {
            let m = SimpleShear::new(law, lambda).unwrap();
            for gamma in [-0.3, 0.05, 0.2, 0.6] {
                let energy = |g: f64| {
                    let f = m.deformation(g);
                    // principal stretches of F (det F = 1)
                    let c = f.transpose() * f;
                    let e = nalgebra::SymmetricEigen::new(c).eigenvalues;
                    law.isochoric_energy(&p, [e[0].sqrt(), e[1].sqrt(), e[2].sqrt()])
                };
                let want = fd(energy, gamma, 1e-5) / lambda;
                let got = m.stress(&p, gamma);
                assert!(
                    (got - want).abs() <= 1e-6 * want.abs().max(1e-3),
                    "{law} lambda {lambda} gamma {gamma}: P12 {got} vs dW/dgamma / lambda {want}"
                );
            }
        }
    }
}

#[test]
fn shear_closed_forms() {
    // neo-Hookean: P12 = 2 C10 gamma lambda; Mooney-Rivlin: 2 gamma (lambda C10 + C01).
    let nh = SimpleShear::new(Law::NeoHookean, 1.0).unwrap();
    assert!((nh.stress(&[0.3], 0.2) - 2.0 * 0.3 * 0.2).abs() < 1e-12);
    let mr = SimpleShear::new(Law::MooneyRivlin, 0.8).unwrap();
    let want = 2.0 * 0.15 * (0.8 * 0.2 + 0.05);
    assert!((mr.stress(&[0.2, 0.05], 0.15) - want).abs() < 1e-12);
    // Odd in gamma.
    let og = SimpleShear::new(Law::Ogden(1), 1.1).unwrap();
    let p = [0.5, -8.0];
    assert!((og.stress(&p, 0.1) + og.stress(&p, -0.1)).abs() < 1e-12);
    assert!(SimpleShear::new(Law::NeoHookean, 0.0).is_err());
}

#[test]
fn biaxial_stresses_are_derivatives_of_the_reduced_energy() {
    for (law, p) in laws() {
        let m = GeneralBiaxial::new(law);
        for (l1, l2) in [
            (1.04, 0.981),
            (1.3, 1.09),
            (2.5, 0.775),
            (0.9, 1.2),
            (1.6, 1.6),
        ] {
            let w = |a: f64, b: f64| law.isochoric_energy(&p, [a, b, 1.0 / (a * b)]);
            let want1 = fd(|a| w(a, l2), l1, 1e-6);
            let want2 = fd(|b| w(l1, b), l2, 1e-6);
            let (p1, p2) = m.stresses(&p, l1, l2);
            for (got, want) in [(p1, want1), (p2, want2)] {
                assert!(
                    (got - want).abs() <= 1e-6 * want.abs().max(1e-3),
                    "{law} ({l1}, {l2}): {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn biaxial_reduces_to_the_classical_modes() {
    for (law, p) in laws() {
        let m = GeneralBiaxial::new(law);
        for s in [0.8, 1.2, 2.0] {
            let eq = Homogeneous::new(law, Mode::Equibiaxial).stress(&p, s);
            let pl = Homogeneous::new(law, Mode::Planar).stress(&p, s);
            let (a, b) = m.stresses(&p, s, s);
            assert!(
                (a - eq).abs() < 1e-9 * eq.abs().max(1e-3)
                    && (b - eq).abs() < 1e-9 * eq.abs().max(1e-3)
            );
            let (a, _) = m.stresses(&p, s, 1.0);
            assert!(
                (a - pl).abs() < 1e-9 * pl.abs().max(1e-3),
                "{law} planar {a} {pl}"
            );
            // uniaxial: l2 = s^-1/2 gives P2 = 0 and P1 the uniaxial stress
            let un = Homogeneous::new(law, Mode::Uniaxial).stress(&p, s);
            let (a, b) = m.stresses(&p, s, 1.0 / s.sqrt());
            assert!(
                (a - un).abs() < 1e-9 * un.abs().max(1e-3) && b.abs() < 1e-9,
                "{law} uniaxial"
            );
        }
    }
    // The paired layout: predict gives P1, P2 of each row in turn.
    let m = GeneralBiaxial::new(Law::NeoHookean);
    let loading = Loading::quasi_static(Drive::Stretch, vec![1.2, 1.0, 1.5, 1.5]);
    let out = m.predict(&[0.2], &loading).unwrap();
    let (a, b) = m.stresses(&[0.2], 1.2, 1.0);
    assert_eq!(out[..2], [a, b]);
    assert!(m
        .predict(&[0.2], &Loading::quasi_static(Drive::Stretch, vec![1.2]))
        .is_err());
}

/// A ramp to `s` in `ramp` s then a hold to `hold` s.
fn ramp_hold(s: f64, ramp: f64, hold: f64) -> Loading {
    let mut t = Vec::new();
    let mut d = Vec::new();
    for k in 0..=50 {
        let x = k as f64 / 50.0;
        t.push(x * ramp);
        d.push(1.0 + x * (s - 1.0));
    }
    for k in 1..=100 {
        t.push(ramp + (hold - ramp) * k as f64 / 100.0);
        d.push(s);
    }
    Loading::timed(Drive::Stretch, t, d)
}

#[test]
fn finite_strain_viscoelastic_limits() {
    let law = Law::NeoHookean;
    let m = ViscousUniaxial::new(law, 2).unwrap();
    let el = Homogeneous::new(law, Mode::Uniaxial);
    // A fast ramp then a long hold: instantaneous ~ elastic, relaxed = g_inf elastic.
    let theta = [0.1, 0.3, 1.0, 0.2, 50.0];
    let loading = ramp_hold(2.0, 1e-4, 5e3);
    let out = m.predict(&theta, &loading).unwrap();
    let pe = el.stress(&[0.1], 2.0);
    assert!((out[50] - pe).abs() < 1e-3 * pe, "{} vs {pe}", out[50]);
    assert!((out.last().unwrap() - 0.5 * pe).abs() < 1e-6 * pe);
    // No viscous terms: the elastic response at every sample.
    let out = m.predict(&[0.1, 0.0, 1.0, 0.0, 1.0], &loading).unwrap();
    for (o, s) in out.iter().zip(&loading.drive) {
        assert!((o - el.stress(&[0.1], *s)).abs() < 1e-12);
    }
    // Small strain: agrees with QLV on the nominal stress to second order.
    let qlv = Viscoelastic::new(Box::new(el.clone()), 2);
    let small = ramp_hold(1.01, 2.0, 100.0);
    let a = m.predict(&theta, &small).unwrap();
    let b = qlv.predict(&theta, &small).unwrap();
    let k = 50;
    assert!(
        (a[k] - b[k]).abs() < 2e-2 * b[k].abs(),
        "{} vs {}",
        a[k],
        b[k]
    );
    // Untimed history and a weight sum above 1 are errors.
    assert!(m
        .predict(
            &theta,
            &Loading::quasi_static(Drive::Stretch, vec![1.0, 1.1])
        )
        .is_err());
    assert!(m.predict(&[0.1, 0.7, 1.0, 0.6, 5.0], &loading).is_err());
}
