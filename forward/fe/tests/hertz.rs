//! Hertz: a rigid sphere of radius R = 2.5 mm pressed frictionlessly into
//! the N1 cylinder (70 mm x 80 mm, bonded base) of incompressible
//! neo-Hookean `ecoflex-nh`. For an incompressible half-space
//! (Hertz 1882; Johnson, *Contact Mechanics*, 1985, eq. 4.22)
//!
//! ```text
//! F = (4/3) E* sqrt(R) d^{3/2},   E* = E / (1 - nu^2) = 4 mu  (nu = 1/2, E = 3 mu)
//!   = (16/3) mu sqrt(R) d^{3/2},  mu = 2 C10
//! ```
//!
//! Hertz is the small-strain limit. The FE force falls below it in
//! proportion to a / R (a = sqrt(R d), the contact radius), the order of the
//! strains: -0.3 % at d = 0.002 R, -1.0 % at 0.016 R, -2.6 % at 0.06 R,
//! -3.7 % at 0.1 R. The deviation is not discretisation error: halving the
//! element size changes it by < 0.1 % (docs/validation/fe.md). Of it, -0.8 %
//! at 0.1 R is the sphere-versus-paraboloid difference (Sneddon 1965) and
//! the rest is finite-strain neo-Hookean behaviour.

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{N1Needle, ToolShape};

const C10: f64 = 1101.295e-6;
const R: f64 = 2.5;

fn hertz(d: f64) -> f64 {
    16.0 / 3.0 * (2.0 * C10) * R.sqrt() * d.powf(1.5)
}

/// Relative differences FE - Hertz at `depths` on a mesh graded from
/// `h_fine` over `fine_length`.
fn deviations(h_fine: f64, fine_length: f64, depths: &[f64], augment: bool) -> Vec<f64> {
    let mut m = N1Needle::new("neo-hookean".parse().unwrap());
    m.tool = ToolShape::Sphere { radius: R };
    m.friction = 0.0;
    m.grading = Some(Grading {
        h_fine,
        fine_length,
        growth: 1.3,
    });
    m.options.first_step = depths[0] / 2.0;
    if augment {
        // augment every increment to 1e-6 mm (the sphere has no cap/cone
        // junction to chatter at); without it the multipliers lag one
        // increment, which shifts the deviations below by < 0.15 %
        m.penetration_tol = 1e-6;
        m.options.max_augmentations = 20;
    }
    let f = m
        .predict(
            &[C10],
            &Loading::quasi_static(Drive::DisplacementMm, depths.to_vec()),
        )
        .unwrap();
    depths
        .iter()
        .zip(&f)
        .map(|(d, fe)| (fe - hertz(*d)) / hertz(*d))
        .collect()
}

#[test]
fn sphere_force_follows_hertz_with_a_finite_strain_deviation() {
    let depths = [0.05, 0.1, 0.15, 0.2, 0.25];
    let dev = deviations(0.04, 1.2, &depths, false);
    let msg = format!("{depths:?}: {dev:?}");
    // within 3 % up to 0.06 R, within 4 % up to 0.1 R
    for (d, r) in depths.iter().zip(&dev) {
        let bound = if *d <= 0.15 { 0.03 } else { 0.04 };
        assert!(r.abs() < bound, "{msg}");
    }
    // below Hertz, growing with depth (a finite-strain effect)
    assert!(dev.windows(2).all(|w| w[1] < w[0] && w[0] < 0.0), "{msg}");
}

/// The small-strain limit: the deviation goes to zero with the depth.
/// (15 s: run with `cargo test -p palpate-fe --test hertz -- --ignored`.)
#[test]
#[ignore]
fn sphere_force_tends_to_hertz_at_small_depth() {
    let depths = [0.005, 0.01, 0.02, 0.04];
    let dev = deviations(0.008, 0.4, &depths, true);
    assert!(dev[0].abs() < 0.005, "{depths:?}: {dev:?}");
    assert!(dev.iter().all(|r| r.abs() < 0.012), "{depths:?}: {dev:?}");
}
