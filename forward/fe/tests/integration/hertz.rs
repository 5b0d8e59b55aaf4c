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
//! and for the exact sphere instead of its paraboloid (Sneddon 1965, "The
//! relation between load and penetration in the axisymmetric Boussinesq
//! problem for a punch of arbitrary profile", *Int. J. Eng. Sci.* 3, 47):
//!
//! ```text
//! d = (a / 2) ln((R + a) / (R - a)),
//! F = (E* / 2) [(a^2 + R^2) ln((R + a) / (R - a)) - 2 a R]   (F = Hertz (1 - d / 10R + ...))
//! ```
//!
//! Both are small-strain half-space solutions. The FE force at d = 0.1 R is
//! 3.7 % below Hertz, 2.7 % below Sneddon; docs/validation/fe.md ("Hertz")
//! splits this into the sphere shape (-1.0 %), the finite cylinder (-1.0 %,
//! measured by enlarging it) and finite deformation (-1.7 %, growing like
//! a / R), and an independent CalculiX model of the same problem
//! (docs/validation/hertz/) is 4.0 % below Hertz: ours is 0.2-0.4 % above
//! it, within its own uncertainty. The 3 % criterion holds against
//! Hertz to 0.1 R on a near-half-space (the N1 cylinder enlarged 10x, the
//! body Hertz's formula assumes), against Sneddon to 0.1 R on the N1
//! cylinder, and against Hertz to 0.06 R on the N1 cylinder.

use std::path::Path;
use std::sync::OnceLock;

use palpate_core::data::Table;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{N1Needle, ToolShape};

const C10: f64 = 1101.295e-6;
const MU: f64 = 2.0 * C10;
const R: f64 = 2.5;
/// Depths of the default run (0.02 R .. 0.1 R).
const DEPTHS: [f64; 5] = [0.05, 0.1, 0.15, 0.2, 0.25];
/// The CalculiX curve compared with (docs/validation/hertz/nh_n20_d6.inp:
/// neo-Hookean, K = 1000 mu, 0.05 mm CAX8R under the sphere, face-to-face
/// penalty contact 100 MPa/mm).
const CCX_REFERENCE: &str = "ccx_nh_k1000_n20_p100.csv";
/// Its uncertainty (docs/validation/fe.md, "Hertz"): mesh (0.1 against
/// 0.05 mm CAX8R: 0.6 % at 0.05 mm, <= 0.2 % from 0.1 mm), contact ripple
/// (+-0.2 %), penalty (10 against 100 MPa/mm: <= 0.2 % at 0.05 mm, so
/// <= 0.03 % at 100), K = 1000 mu against exact incompressibility (0.1 %).
const CCX_TOLERANCE: f64 = 0.0075;

/// Hertz (paraboloid) force of an incompressible half-space, E* = 4 mu.
fn hertz(d: f64) -> f64 {
    16.0 / 3.0 * MU * R.sqrt() * d.powf(1.5)
}

/// Sneddon's exact-sphere force of an incompressible half-space, E* = 4 mu:
/// the contact radius solves `d = (a/2) ln((R+a)/(R-a))` (bisection; the
/// right side increases with `a`).
fn sneddon(d: f64) -> f64 {
    let depth_of = |a: f64| 0.5 * a * ((R + a) / (R - a)).ln();
    let (mut lo, mut hi) = (0.0, R * (1.0 - 1e-12));
    for _ in 0..200 {
        let a = 0.5 * (lo + hi);
        if depth_of(a) > d {
            hi = a;
        } else {
            lo = a;
        }
    }
    let a = 0.5 * (lo + hi);
    let l = ((R + a) / (R - a)).ln();
    0.5 * 4.0 * MU * ((a * a + R * R) * l - 2.0 * a * R)
}

/// The sphere on the N1 cylinder scaled by `scale` (1 = N1), mesh graded
/// from `h_fine` over `fine_length` (growth 1.3).
fn sphere_model(h_fine: f64, fine_length: f64, scale: f64, first_depth: f64) -> N1Needle {
    let mut m = N1Needle::new("neo-hookean".parse().unwrap());
    m.tool = ToolShape::Sphere { radius: R };
    m.friction = 0.0;
    m.radius *= scale;
    m.height *= scale;
    m.grading = Some(Grading {
        h_fine,
        fine_length,
        growth: 1.3,
    });
    m.options.first_step = first_depth / 2.0;
    m
}

fn forces(m: &N1Needle, depths: &[f64]) -> Vec<f64> {
    m.predict(
        &[C10],
        &Loading::quasi_static(Drive::DisplacementMm, depths.to_vec()),
    )
    .unwrap()
}

/// Relative differences `f / reference - 1`.
fn deviations(f: &[f64], depths: &[f64], reference: fn(f64) -> f64) -> Vec<f64> {
    depths
        .iter()
        .zip(f)
        .map(|(d, f)| f / reference(*d) - 1.0)
        .collect()
}

/// The default run (0.04 mm elements over 1.2 mm, 2650 elements, ~3 s),
/// shared by the tests below.
fn default_forces() -> &'static [f64] {
    static F: OnceLock<Vec<f64>> = OnceLock::new();
    F.get_or_init(|| forces(&sphere_model(0.04, 1.2, 1.0, DEPTHS[0]), &DEPTHS))
}

#[test]
fn sneddon_tends_to_hertz_and_is_below_it_by_d_over_10r() {
    for d in [1e-4, 0.01, 0.05, 0.25] {
        let rel = sneddon(d) / hertz(d) - 1.0;
        assert!((rel + d / (10.0 * R)).abs() < 0.05 * d / R, "{d}: {rel}");
    }
}

#[test]
fn sphere_force_within_3_percent_of_sneddon_up_to_0_1_r() {
    let dev = deviations(default_forces(), &DEPTHS, sneddon);
    let msg = format!("{DEPTHS:?}: {dev:?}");
    eprintln!("{msg}");
    assert!(dev.iter().all(|r| r.abs() < 0.03), "{msg}");
}

#[test]
fn sphere_force_within_3_percent_of_hertz_up_to_0_06_r_and_4_percent_up_to_0_1_r() {
    let dev = deviations(default_forces(), &DEPTHS, hertz);
    let msg = format!("{DEPTHS:?}: {dev:?}");
    eprintln!("{msg}");
    for (d, r) in DEPTHS.iter().zip(&dev) {
        let bound = if *d <= 0.06 * R + 1e-12 { 0.03 } else { 0.04 };
        assert!(r.abs() < bound, "{msg}");
    }
    // below Hertz, growing with depth
    assert!(dev.windows(2).all(|w| w[1] < w[0] && w[0] < 0.0), "{msg}");
}

/// A CalculiX force curve written by docs/validation/hertz/post_hertz.py:
/// (depth mm, force N).
fn calculix_curve(file: &str) -> Vec<(f64, f64)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs/validation/hertz")
        .join(file);
    let t = Table::read(&path).unwrap();
    let (d, f) = (t.column("depth_mm").unwrap(), t.column("force_N").unwrap());
    d.iter().copied().zip(f.iter().copied()).collect()
}

/// CalculiX force at `depth` (an output depth of the curve).
fn at(curve: &[(f64, f64)], depth: f64) -> f64 {
    curve
        .iter()
        .find(|(d, _)| (d - depth).abs() < 1e-9)
        .map(|(_, f)| *f)
        .unwrap_or_else(|| panic!("no CalculiX output at {depth} mm"))
}

#[test]
fn sphere_force_matches_calculix() {
    let ccx = calculix_curve(CCX_REFERENCE);
    let ours = default_forces();
    let rel: Vec<f64> = DEPTHS
        .iter()
        .zip(ours)
        .map(|(d, f)| f / at(&ccx, *d) - 1.0)
        .collect();
    let msg = format!("{DEPTHS:?}: ours / CalculiX - 1 = {rel:?}");
    eprintln!("{msg}");
    assert!(rel.iter().all(|r| r.abs() < CCX_TOLERANCE), "{msg}");
    // the independent solver is itself more than 3 % below Hertz at 0.1 R:
    // a 3 % agreement with Hertz is not reachable on this cylinder
    let d = 0.1 * R;
    assert!(at(&ccx, d) / hertz(d) - 1.0 < -0.03, "{msg}");
}
/// The finite cylinder: the same FE on a 10x larger one (350 x 800 mm,
/// same mesh near the axis) is 0.8 % stiffer at 0.1 R (3x: 0.7 %, 30x:
/// 0.98 %, the 1/size behaviour of a far-field correction), and that
/// near-half-space is 1-2.5 % below Sneddon, in proportion to a / R: the
/// finite-deformation part of the deviation.
///
/// Hertz's formula is a half-space result: on this near-half-space the FE
/// force is within 3 % of it at every depth up to 0.1 R (the test's
/// criterion; -2.8 % at 0.1 R), while on the N1-sized cylinder the finite
/// body takes another 0.8-1 % off.
#[test]
fn near_half_space_is_within_3_percent_of_hertz_up_to_0_1_r() {
    let big = forces(&sphere_model(0.04, 1.2, 10.0, DEPTHS[0]), &DEPTHS);
    let n1 = default_forces();
    let stiffening: Vec<f64> = big.iter().zip(n1).map(|(b, f)| b / f - 1.0).collect();
    let dev = deviations(&big, &DEPTHS, sneddon);
    let msg = format!("{DEPTHS:?}: big / N1 - 1 = {stiffening:?}, big / Sneddon - 1 = {dev:?}");
    eprintln!("{msg}");
    let last = DEPTHS.len() - 1;
    assert!(
        stiffening[last] > 0.005 && stiffening[last] < 0.015,
        "{msg}"
    );
    assert!(stiffening.iter().all(|s| *s > 0.0), "{msg}");
    assert!(dev[last] > -0.025 && dev[last] < -0.01, "{msg}");
    let vs_hertz = deviations(&big, &DEPTHS, hertz);
    assert!(
        vs_hertz.iter().all(|r| r.abs() < 0.03),
        "{DEPTHS:?}: big / Hertz - 1 = {vs_hertz:?}"
    );
    // in proportion to a / R = sqrt(d / R) within 25 %: the ratio of the
    // deviations at 0.1 R and 0.02 R against sqrt(5)
    let ratio = dev[last] / dev[0];
    assert!((ratio / 5f64.sqrt() - 1.0).abs() < 0.25, "{msg}");
}

/// The small-strain limit: the deviation goes to zero with the depth, and
/// CalculiX on a 0.025 mm CAX8R mesh agrees.
/// (20 s: `cargo test -p palpate-fe --test integration hertz:: -- --ignored`.)
#[test]
#[ignore = "20 s; cargo test -p palpate-fe --test integration hertz:: -- --ignored"]
fn sphere_force_tends_to_hertz_at_small_depth() {
    let depths = [0.005, 0.01, 0.02, 0.04];
    let mut m = sphere_model(0.008, 0.4, 1.0, depths[0]);
    // augment every increment to 1e-6 mm (the sphere has no cap/cone
    // junction to chatter at); without it the multipliers lag one
    // increment, which shifts the deviations by < 0.15 %
    m.penetration_tol = 1e-6;
    m.options.max_augmentations = 20;
    let f = forces(&m, &depths);
    let dev = deviations(&f, &depths, hertz);
    let ccx = calculix_curve("ccx_nh_k1000_small_p100.csv");
    let rel: Vec<f64> = depths
        .iter()
        .zip(&f)
        .map(|(d, f)| f / at(&ccx, *d) - 1.0)
        .collect();
    let msg = format!("{depths:?}: ours / Hertz - 1 = {dev:?}, ours / CalculiX - 1 = {rel:?}");
    eprintln!("{msg}");
    assert!(dev[0].abs() < 0.005, "{msg}");
    assert!(dev.iter().all(|r| r.abs() < 0.012), "{msg}");
    assert!(rel.iter().all(|r| r.abs() < CCX_TOLERANCE), "{msg}");
}
