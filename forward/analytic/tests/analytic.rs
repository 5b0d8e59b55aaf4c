//! Verification of the analytic forward models against hand-computed values,
//! the CalculiX-project reference table of C1, closed-form and brute-force
//! viscoelastic responses, and the "effect off" property of every enrichment.

use palpate_analytic::{
    c1_area_mm2, lateral_stress_free, C1Compression, C1Geometry, Compressible, Homogeneous, Mode,
};
use palpate_core::enrichable::{effects_of, embed, enrich};
use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace, ParamSpec, Table,
};
use palpate_enrich::{qlv_convolve, ToolCompliance, Viscoelastic, ZeroOffset};
use palpate_material::{Law, Volumetric};
use std::path::Path;

fn test_data(rel: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(rel)
}

fn close(a: f64, b: f64, rel: f64, what: &str) {
    let tol = rel * a.abs().max(b.abs()).max(1e-300);
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (rel tol {rel})");
}

/// 0..2 mm at 0.4 mm/s, `n` samples.
fn c1_ramp(n: usize) -> Loading {
    let d: Vec<f64> = (0..n).map(|i| 2.0 * i as f64 / (n - 1) as f64).collect();
    let t = d.iter().map(|x| x / 0.4).collect();
    Loading::timed(Drive::DisplacementMm, t, d)
}

const ECOFLEX_NH: [f64; 1] = [1101.295e-6];
const ECOFLEX_RP2: [f64; 2] = [686.428e-6, 1929.606e-6];

#[test]
fn neo_hookean_homogeneous_closed_forms() {
    let c10 = 0.3;
    let s: Vec<f64> = vec![0.5, 0.8, 1.0, 1.3, 2.0, 4.0];
    let load = Loading::quasi_static(Drive::Stretch, s.clone());
    // Uniaxial 2 C10 (s - s^-2), equibiaxial 2 C10 (s - s^-5), planar 2 C10 (s - s^-3).
    type Shape = fn(f64) -> f64;
    let cases: [(Mode, Shape); 3] = [
        (Mode::Uniaxial, |s| s - s.powi(-2)),
        (Mode::Equibiaxial, |s| s - s.powi(-5)),
        (Mode::Planar, |s| s - s.powi(-3)),
    ];
    for (mode, shape) in cases {
        let m = Homogeneous::new(Law::NeoHookean, mode);
        assert_eq!(m.observable(), Observable::NominalStressMPa);
        let p = m.predict(&[c10], &load).unwrap();
        for (si, pi) in s.iter().zip(&p) {
            let want = 2.0 * c10 * shape(*si);
            assert!(
                (pi - want).abs() <= 1e-12 * (1.0 + want.abs()),
                "{mode} at {si}: {pi} vs {want}"
            );
        }
    }
    // Mooney-Rivlin uniaxial: 2 (s - s^-2) (C10 + C01 / s).
    let m = Homogeneous::new(Law::MooneyRivlin, Mode::Uniaxial);
    let p = m.predict(&[0.2, 0.05], &load).unwrap();
    for (si, pi) in s.iter().zip(&p) {
        let want = 2.0 * (si - si.powi(-2)) * (0.2 + 0.05 / si);
        close(*pi, want, 1e-10, "Mooney-Rivlin uniaxial");
    }
}

/// A stretch at or beyond Gent's limit is an error that names the limit (not a NaN stress, not
/// a finite stress from beyond the pole); inside it the model answers.
#[test]
fn gent_beyond_its_limit_is_a_named_error() {
    let m = Homogeneous::new(Law::Gent, Mode::Uniaxial);
    let p = [0.3, 20.0];
    let inside = m
        .predict(
            &p,
            &Loading::quasi_static(Drive::Stretch, vec![0.5, 2.0, 4.5]),
        )
        .unwrap();
    assert!(inside.iter().all(|v| v.is_finite()));
    // s = 5: I1 - 3 = 22.4 > Jm = 20.
    let err = m
        .predict(&p, &Loading::quasi_static(Drive::Stretch, vec![2.0, 5.0]))
        .unwrap_err();
    let text = err.to_string();
    assert!(
        matches!(err, ForwardError::Unphysical { drive, .. } if drive == 5.0)
            && text.contains("limit Jm = 20"),
        "{text}"
    );
}

#[test]
fn c1_force_matches_the_reference_table_at_2_mm() {
    let table = Table::read(test_data("calculix/c1/analytic_uniaxial.csv")).unwrap();
    let strain = table.column("strain").unwrap();
    let row = strain
        .iter()
        .position(|e| (e - 2.0 / 9.0).abs() < 1e-5)
        .expect("strain 2/9 in the table");
    let area = c1_area_mm2(&C1Geometry::default());
    close(area, std::f64::consts::PI * 19.0 * 19.0, 1e-15, "area");
    let load = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 2.0]);
    for (law, theta, col) in [
        (Law::NeoHookean, &ECOFLEX_NH[..], "stress_nh_MPa"),
        (
            Law::ReducedPolynomial(2),
            &ECOFLEX_RP2[..],
            "stress_rp2_MPa",
        ),
    ] {
        let model = C1Compression::new(law);
        assert_eq!(model.observable(), Observable::ForceN);
        let f = model.predict(theta, &load).unwrap();
        assert_eq!(f[0], 0.0);
        let want = table.column(col).unwrap()[row] * area;
        // The table has 10 significant digits and a strain rounded to 1e-6.
        close(f[1], want, 2e-5, col);
        assert!(f[1] > 0.0, "compression force is positive");
    }
    // Hand value: neo-Hookean, lambda = 7/9: F = -2 C10 (l - l^-2) A.
    let l: f64 = 7.0 / 9.0;
    let hand = -2.0 * ECOFLEX_NH[0] * (l - l.powi(-2)) * area;
    let f = C1Compression::new(Law::NeoHookean)
        .predict(&ECOFLEX_NH, &load)
        .unwrap();
    close(f[1], hand, 1e-13, "neo-Hookean C1 hand value");
}

/// A linear spring F = E d, as the elastic base of the closed-form QLV test.
struct LinearSpring {
    space: ParamSpace,
}
impl LinearSpring {
    fn new() -> Self {
        LinearSpring {
            space: ParamSpace::new(vec![ParamSpec::new("E", "N/mm", 0.0, f64::INFINITY, 1.0)]),
        }
    }
}
struct SpringEval;
impl Evaluator for SpringEval {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        for (o, d) in out.iter_mut().zip(&loading.drive) {
            *o = theta[0] * d;
        }
        Ok(())
    }
}
impl ForwardModel for LinearSpring {
    fn name(&self) -> String {
        "linear spring".into()
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(SpringEval)
    }
}

#[test]
fn qlv_ramp_and_hold_of_a_linear_spring_matches_the_closed_form() {
    // d = v t up to t_r, then held: F(t) = E v [g_inf t + sum g_i tau_i (1 - e^{-t/tau_i})] in the
    // ramp, E v [g_inf t_r + sum g_i tau_i (e^{-(t - t_r)/tau_i} - e^{-t/tau_i})] in the hold.
    let (e, v, t_r) = (3.0, 0.8, 0.5);
    let (g, tau) = ([0.3, 0.2], [0.4, 6.0]);
    let time: Vec<f64> = (0..=600).map(|k| k as f64 * 0.05).collect();
    let drive: Vec<f64> = time.iter().map(|t| v * t.min(t_r)).collect();
    let load = Loading::timed(Drive::DisplacementMm, time.clone(), drive);
    let model = Viscoelastic::new(Box::new(LinearSpring::new()), 2);
    let f = model
        .predict(&[e, g[0], tau[0], g[1], tau[1]], &load)
        .unwrap();
    let g_inf = 1.0 - g[0] - g[1];
    for (t, fk) in time.iter().zip(&f) {
        let want = if *t <= t_r {
            e * v
                * (g_inf * t
                    + (0..2)
                        .map(|i| g[i] * tau[i] * (1.0 - (-t / tau[i]).exp()))
                        .sum::<f64>())
        } else {
            e * v
                * (g_inf * t_r
                    + (0..2)
                        .map(|i| {
                            g[i] * tau[i] * ((-(t - t_r) / tau[i]).exp() - (-t / tau[i]).exp())
                        })
                        .sum::<f64>())
        };
        assert!(
            (fk - want).abs() < 1e-12 * e * v * t_r,
            "t = {t}: {fk} vs {want}"
        );
    }
    // Long-time limit: the hold relaxes to g_inf of the instantaneous elastic force.
    assert!((f.last().unwrap() - g_inf * e * v * t_r).abs() < 0.02 * e * v * t_r);
}

#[test]
fn qlv_recursion_matches_a_brute_force_convolution() {
    // Nonlinear elastic response (C1 neo-Hookean) on an irregular, ramp-hold-unload history.
    let time: Vec<f64> = vec![0.0, 0.3, 0.5, 1.1, 2.0, 2.0, 3.5, 6.0, 9.0, 9.7, 11.0];
    let drive: Vec<f64> = vec![0.1, 0.4, 0.9, 1.6, 2.0, 2.0, 2.0, 2.0, 2.0, 1.2, 0.0];
    let load = Loading::timed(Drive::DisplacementMm, time.clone(), drive);
    let base = C1Compression::new(Law::NeoHookean);
    let fe = base.predict(&ECOFLEX_NH, &load).unwrap();
    let prony = [0.35, 0.7, 0.25, 5.0];
    let model = Viscoelastic::new(Box::new(base.clone()), 2);
    let f = model
        .predict(
            &[ECOFLEX_NH[0], prony[0], prony[1], prony[2], prony[3]],
            &load,
        )
        .unwrap();
    let mut recursion = vec![0.0; fe.len()];
    qlv_convolve(&time, &fe, &prony, &mut recursion);
    assert_eq!(f, recursion);
    let relax = |t: f64| {
        1.0 - prony[0] * (1.0 - (-t / prony[1]).exp()) - prony[2] * (1.0 - (-t / prony[3]).exp())
    };
    for k in 0..time.len() {
        // F(t_k) = G(t_k - t_0) Fe_0 + sum over fine sub-intervals of G(t_k - s_mid) dFe (midpoint rule).
        let mut brute = relax(time[k] - time[0]) * fe[0];
        for j in 1..=k {
            let sub = 4000;
            let dfe = (fe[j] - fe[j - 1]) / sub as f64;
            for m in 0..sub {
                let s = time[j - 1] + (m as f64 + 0.5) / sub as f64 * (time[j] - time[j - 1]);
                brute += relax(time[k] - s) * dfe;
            }
        }
        assert!(
            (f[k] - brute).abs() < 1e-7 * (1.0 + fe[k].abs()),
            "t = {}: {} vs {brute}",
            time[k],
            f[k]
        );
    }
}

#[test]
fn zero_offset_shifts_the_contact_point() {
    let base = C1Compression::new(Law::NeoHookean);
    let model = ZeroOffset::new(Box::new(base.clone()));
    let d: Vec<f64> = (0..=20).map(|i| 0.1 * i as f64).collect();
    let load = Loading::quasi_static(Drive::DisplacementMm, d.clone());
    let d0 = 0.35;
    let f = model.predict(&[ECOFLEX_NH[0], d0], &load).unwrap();
    for (di, fi) in d.iter().zip(&f) {
        let want = if *di > d0 {
            base.predict(
                &ECOFLEX_NH,
                &Loading::quasi_static(Drive::DisplacementMm, vec![di - d0]),
            )
            .unwrap()[0]
        } else {
            0.0
        };
        close(*fi, want, 1e-14, "zero offset");
    }
}

#[test]
fn tool_compliance_satisfies_the_series_spring_relation() {
    let base = C1Compression::new(Law::ReducedPolynomial(2));
    let c = 0.05; // mm/N
                  // True tool travel u; recorded d = u + c F(u).
    let u: Vec<f64> = (0..=40).map(|i| 0.05 * i as f64).collect();
    let fu = base
        .predict(
            &ECOFLEX_RP2,
            &Loading::quasi_static(Drive::DisplacementMm, u.clone()),
        )
        .unwrap();
    let d: Vec<f64> = u.iter().zip(&fu).map(|(ui, fi)| ui + c * fi).collect();
    let model = ToolCompliance::new(Box::new(base));
    let f = model
        .predict(
            &[ECOFLEX_RP2[0], ECOFLEX_RP2[1], c],
            &Loading::quasi_static(Drive::DisplacementMm, d),
        )
        .unwrap();
    for (a, b) in f.iter().zip(&fu) {
        assert!((a - b).abs() < 1e-8, "{a} vs {b}");
    }
}

/// Around a relaxing specimen (QLV, one Prony term) and a compliance stiff
/// against it, the solved travel still satisfies d = u + c F(u) sample by
/// sample through a ramp and a hold.
#[test]
fn tool_compliance_holds_around_a_relaxing_specimen() {
    let base = Viscoelastic::new(Box::new(C1Compression::new(Law::NeoHookean)), 1);
    let theta_base = [2e-2, 0.6, 0.5]; // C10 MPa, g1, tau1 s
    let time: Vec<f64> = (0..=60).map(|i| 0.05 * i as f64).collect();
    let u: Vec<f64> = time.iter().map(|t| 1.5 * t.min(1.0)).collect();
    let fu = base
        .predict(
            &theta_base,
            &Loading::timed(Drive::DisplacementMm, time.clone(), u.clone()),
        )
        .unwrap();
    let peak = fu.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    // mm/N: the machine deflects as far as the tool travels at the peak
    let c = 1.5 / peak;
    let d: Vec<f64> = u.iter().zip(&fu).map(|(ui, fi)| ui + c * fi).collect();
    let model = ToolCompliance::new(Box::new(base));
    let f = model
        .predict(
            &[theta_base[0], theta_base[1], theta_base[2], c],
            &Loading::timed(Drive::DisplacementMm, time, d),
        )
        .unwrap();
    for (a, b) in f.iter().zip(&fu) {
        assert!((a - b).abs() < 1e-7 * peak, "{a} vs {b}");
    }
}

/// Independent compressible neo-Hookean C1: Psi(l, m) = C10 (J^-2/3 (l^2 + 2 m^2) - 3) + (J - 1)^2 / D1,
/// J = l m^2; the lateral stretch m makes dPsi/dm = 0 (bisection), P = dPsi/dl (central difference).
fn compressible_nh_hand(c10: f64, d1: f64, l: f64) -> f64 {
    let psi = |l: f64, m: f64| {
        let j = l * m * m;
        c10 * (j.powf(-2.0 / 3.0) * (l * l + 2.0 * m * m) - 3.0) + (j - 1.0).powi(2) / d1
    };
    let dpsi_dm = |m: f64| {
        let h = 1e-7 * m;
        (psi(l, m + h) - psi(l, m - h)) / (2.0 * h)
    };
    let (mut lo, mut hi) = (0.5, 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if dpsi_dm(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let m = 0.5 * (lo + hi);
    let h = 1e-6;
    (psi(l + h, m) - psi(l - h, m)) / (2.0 * h)
}

#[test]
fn compressible_c1_matches_an_independent_solve_and_the_incompressible_limit() {
    let c10 = ECOFLEX_NH[0];
    let area = c1_area_mm2(&C1Geometry::default());
    let load = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.5, 1.0, 2.0]);
    let model = Compressible::new(Law::NeoHookean);
    let incompressible = C1Compression::new(Law::NeoHookean)
        .predict(&[c10], &load)
        .unwrap();
    // K = 2 / D1 = 10 mu: D1 = 0.2 / mu = 0.1 / C10.
    let d1 = 0.1 / c10;
    let f = model.predict(&[c10, d1], &load).unwrap();
    for (k, d) in load.drive.iter().enumerate().skip(1) {
        let hand = -compressible_nh_hand(c10, d1, 1.0 - d / 9.0) * area;
        close(f[k], hand, 1e-5, "compressible neo-Hookean");
        assert!(
            f[k] < incompressible[k],
            "a compressible cylinder is softer"
        );
    }
    // The fast principal-stretch solve agrees with the material crate's general one, for several laws.
    for (law, theta) in [
        (Law::NeoHookean, vec![c10]),
        (Law::ReducedPolynomial(2), ECOFLEX_RP2.to_vec()),
        (Law::MooneyRivlin, vec![3e-4, 1e-4]),
        (Law::Ogden(2), vec![1e-3, 2.5, 4e-4, -2.0]),
    ] {
        let mu = law.shear_modulus(&theta);
        for d1 in [0.05 / mu, 1.0 / mu] {
            for l in [0.6, 0.8, 0.95, 1.2] {
                let fast = lateral_stress_free(&law, &theta, d1, l).unwrap();
                let general = palpate_material::homogeneous::uniaxial_compressible(
                    &law,
                    &theta,
                    Volumetric::D1(d1),
                    l,
                )
                .unwrap();
                close(fast.0, general.0, 1e-8, "compressible nominal stress");
                close(fast.1, general.1, 1e-10, "lateral stretch");
            }
        }
    }
    let nearly = model.predict(&[c10, 1e-6 / c10], &load).unwrap();
    for (a, b) in nearly.iter().zip(&incompressible) {
        assert!((a - b).abs() <= 1e-4 * b.abs() + 1e-15, "{a} vs {b}");
    }
}

#[test]
fn every_enrichment_switched_off_reproduces_the_base_exactly() {
    let load = c1_ramp(41);
    for (law, theta) in [
        (Law::NeoHookean, &ECOFLEX_NH[..]),
        (Law::ReducedPolynomial(2), &ECOFLEX_RP2[..]),
    ] {
        let base = C1Compression::new(law);
        let want = base.predict(theta, &load).unwrap();
        let effects = base.effects();
        for e in [
            Effect::MaterialForm,
            Effect::Viscoelasticity,
            Effect::ZeroOffset,
            Effect::Compressibility,
            Effect::ToolCompliance,
        ] {
            assert!(effects.contains(&e), "{e} offered by {}", base.name());
            let rich = base.enrich(e).unwrap();
            let off = embed(rich.as_ref(), theta);
            assert_eq!(off.len(), rich.space().len(), "{e}");
            rich.space().check(&off).unwrap();
            assert_eq!(
                rich.predict(&off, &load).unwrap(),
                want,
                "{e} off on {}",
                base.name()
            );
            // And the effect does something when switched on.
            let mut on = off.clone();
            let k = theta.len();
            on[k] = match e {
                Effect::ZeroOffset => 0.2,
                Effect::Compressibility => 0.5 / theta[0],
                Effect::ToolCompliance => 0.05,
                Effect::Viscoelasticity => 0.2,
                _ => theta[0],
            };
            let changed = rich.predict(&on, &load).unwrap();
            assert!(
                changed.iter().zip(&want).any(|(a, b)| (a - b).abs() > 1e-6),
                "{e} on"
            );
        }
        // Chains of wrappers also switch off exactly.
        let visco = base.enrich(Effect::Viscoelasticity).unwrap();
        let both = enrich(visco.as_ref(), Effect::ZeroOffset).unwrap();
        let off = embed(both.as_ref(), &embed(visco.as_ref(), theta));
        assert_eq!(both.predict(&off, &load).unwrap(), want);
        assert!(!effects_of(both.as_ref()).contains(&Effect::Viscoelasticity));
        assert!(enrich(both.as_ref(), Effect::Viscoelasticity).is_err());
    }
    // The richer law's added coefficient is a stiffening term: C20 >= 0, off at 0.
    let rp2 = C1Compression::new(Law::NeoHookean)
        .enrich(Effect::MaterialForm)
        .unwrap();
    assert_eq!(
        rp2.space().names(),
        vec!["C10".to_string(), "C20".to_string()]
    );
    assert_eq!(rp2.space().params[1].lower, 0.0);
    assert!(rp2.space().params[1].initial > 0.0);
    assert!(matches!(
        rp2.predict(&[1e-3, -1e-4], &load),
        Err(ForwardError::InvalidParameter { .. })
    ));
    for effect in [Effect::Friction, Effect::Inclusion] {
        assert!(C1Compression::new(Law::NeoHookean).enrich(effect).is_err());
    }
    // Homogeneous tests offer a richer law and viscoelasticity.
    let h = Homogeneous::new(Law::NeoHookean, Mode::Uniaxial);
    let load = Loading::timed(Drive::Stretch, vec![0.0, 1.0, 2.0], vec![1.0, 1.5, 2.0]);
    let want = h.predict(&[0.3], &load).unwrap();
    for e in h.effects() {
        let rich = h.enrich(e).unwrap();
        assert_eq!(
            rich.predict(&embed(rich.as_ref(), &[0.3]), &load).unwrap(),
            want,
            "{e}"
        );
    }
}

#[test]
fn bad_parameters_and_histories_are_errors_not_panics() {
    let c1 = C1Compression::new(Law::NeoHookean);
    let load = c1_ramp(11);
    assert!(matches!(
        c1.predict(&[-1e-3], &load),
        Err(ForwardError::InvalidParameter { .. })
    ));
    assert!(matches!(
        c1.predict(&[1e-3, 1.0], &load),
        Err(ForwardError::WrongParameterCount { .. })
    ));
    assert!(c1.predict(&[f64::NAN], &load).is_err());
    let crushing = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 9.0]);
    assert!(matches!(
        c1.predict(&[1e-3], &crushing),
        Err(ForwardError::Unphysical { .. })
    ));
    let stretch = Loading::quasi_static(Drive::Stretch, vec![1.0]);
    assert!(matches!(
        c1.predict(&[1e-3], &stretch),
        Err(ForwardError::InvalidLoading(_))
    ));
    let bad_geometry = C1Compression::with_geometry(
        Law::NeoHookean,
        C1Geometry {
            diameter_mm: -1.0,
            height_mm: 9.0,
        },
    );
    assert!(matches!(
        bad_geometry.predict(&[1e-3], &load),
        Err(ForwardError::InvalidConfig { .. })
    ));

    let visco = Viscoelastic::new(Box::new(c1.clone()), 2);
    let untimed = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 1.0]);
    assert!(matches!(
        visco.predict(&[1e-3, 0.2, 1.0, 0.1, 10.0], &untimed),
        Err(ForwardError::InvalidLoading(_))
    ));
    for (theta, name) in [
        ([1e-3, 0.6, 1.0, 0.5, 10.0], "g2"),    // sum g > 1
        ([1e-3, 0.2, 0.0, 0.1, 1.0], "tau1_s"), // zero relaxation time
        ([1e-3, -0.1, 1.0, 0.1, 10.0], "g1"),   // negative g
    ] {
        match visco.predict(&theta, &load) {
            Err(ForwardError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{theta:?}: expected an error naming {name}, got {other:?}"),
        }
    }
    let h = Homogeneous::new(Law::NeoHookean, Mode::Planar);
    assert!(h
        .predict(&[0.1], &Loading::quasi_static(Drive::Stretch, vec![-1.0]))
        .is_err());
    let comp = Compressible::new(Law::NeoHookean);
    assert!(matches!(
        comp.predict(&[1e-3, -1.0], &load),
        Err(ForwardError::InvalidParameter { .. })
    ));
    let tc = ToolCompliance::new(Box::new(c1));
    assert!(matches!(
        tc.predict(&[1e-3, -0.1], &load),
        Err(ForwardError::InvalidParameter { .. })
    ));
}

#[test]
fn models_run_through_trait_objects() {
    let models: Vec<Box<dyn ForwardModel>> = vec![
        Box::new(C1Compression::new(Law::NeoHookean)),
        Box::new(Compressible::new(Law::NeoHookean)),
        Box::new(ZeroOffset::new(Box::new(C1Compression::new(
            Law::NeoHookean,
        )))),
        Box::new(ToolCompliance::new(Box::new(C1Compression::new(
            Law::NeoHookean,
        )))),
        Box::new(Viscoelastic::new(
            Box::new(C1Compression::new(Law::NeoHookean)),
            1,
        )),
    ];
    let load = c1_ramp(21);
    for m in &models {
        let theta = embed(m.as_ref(), &ECOFLEX_NH);
        let f = m.predict(&theta, &load).unwrap();
        assert_eq!(f.len(), load.len(), "{}", m.name());
        assert!(f[20] > 0.0, "{}", m.name());
    }
}
