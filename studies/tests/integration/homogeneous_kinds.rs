//! Every homogeneous test kind recovers known parameters from synthetic data
//! written in the file conventions of the guide (stretch or strain, nominal
//! or true stress, MPa or kPa, time), joint fits honour weights, and bad
//! files get an error naming the file, line and column.

use palpate_analytic::{GeneralBiaxial, Homogeneous, Mode, SimpleShear, ViscousUniaxial};
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_enrich::Viscoelastic;
use palpate_inverse::ResidualKind;
use palpate_material::Law;
use palpate_studies::cli::calibrate::{read_data, split_data};
use palpate_studies::model::calibration::{calibrate, parse_method, Calibration, Request};
use palpate_studies::model::Viscous;
use palpate_studies::records::TestData;
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn fit(law: Law, data: &[TestData], viscous: Option<Viscous>) -> Calibration {
    calibrate(Request {
        law,
        model: None,
        fitted: data,
        predict: &[],
        residual: ResidualKind::Absolute,
        method: parse_method("lm").unwrap(),
        fixed: Vec::new(),
        observer: None,
        viscous,
    })
    .unwrap()
}

fn read(spec: &str) -> anyhow::Result<Vec<TestData>> {
    read_data(&[spec.to_string()], None)
}

fn assert_params(c: &Calibration, want: &[(&str, f64)], tol: f64) {
    for (name, v) in want {
        let got = c.params.get(name).unwrap().value;
        assert!(
            (got - v).abs() <= tol * v.abs(),
            "{}: {name} = {got}, expected {v} (R2 {})",
            c.law,
            c.r2
        );
    }
}

#[test]
fn uniaxial_tension_and_compression_from_strain_and_true_stress() {
    let dir = tempfile::tempdir().unwrap();
    let (law, p) = (Law::MooneyRivlin, [0.2, 0.05]);
    let m = Homogeneous::new(law, Mode::Uniaxial);
    let mut text = String::from("# synthetic\nstrain,true_stress_kPa\n");
    for k in 0..30 {
        let s = 0.5 + 2.0 * k as f64 / 29.0;
        // Cauchy stress = nominal * stretch, in kPa
        text += &format!("{},{}\n", s - 1.0, m.stress(&p, s) * s * 1e3);
    }
    let f = write(dir.path(), "u.csv", &text);
    let data = read(&format!("uniaxial={}", f.display())).unwrap();
    assert!(
        data[0].loading.drive.iter().any(|&s| s < 1.0)
            && data[0].loading.drive.iter().any(|&s| s > 1.0)
    );
    let c = fit(law, &data, None);
    assert_params(&c, &[("C10", 0.2), ("C01", 0.05)], 1e-6);
}

#[test]
fn equibiaxial_planar_and_general_biaxial() {
    let dir = tempfile::tempdir().unwrap();
    let (law, p) = (Law::ReducedPolynomial(3), [0.2, -0.01, 0.002]);
    let mut eq = String::from("stretch,stress_MPa\n");
    let mut pl = String::from("true_strain,stress_MPa\n");
    for k in 1..20 {
        let s = 1.0 + 2.0 * k as f64 / 19.0;
        eq += &format!(
            "{s},{}\n",
            Homogeneous::new(law, Mode::Equibiaxial).stress(&p, s)
        );
        pl += &format!(
            "{},{}\n",
            s.ln(),
            Homogeneous::new(law, Mode::Planar).stress(&p, s)
        );
    }
    let e = write(dir.path(), "e.csv", &eq);
    let q = write(dir.path(), "p.csv", &pl);
    let data = read_data(
        &[
            format!("biaxial={}", e.display()),
            format!("planar={}", q.display()),
        ],
        None,
    )
    .unwrap();
    assert_eq!(
        data[0].test,
        palpate_studies::records::TestKind::Homogeneous(Mode::Equibiaxial)
    );
    let c = fit(law, &data, None);
    assert_params(&c, &[("C10", 0.2), ("C20", -0.01), ("C30", 0.002)], 1e-5);

    // General biaxial (Kawabata's layout) with a one-term Ogden.
    let (law, p) = (Law::Ogden(1), [0.4, 3.0]);
    let g = GeneralBiaxial::new(law);
    let mut text = String::from("lambda1,lambda2,stress1_MPa,stress2_MPa\n");
    for l1 in [1.1, 1.5, 2.0, 2.8] {
        for l2 in [0.8, 1.0, 1.3, l1] {
            let (a, b) = g.stresses(&p, l1, l2);
            text += &format!("{l1},{l2},{a},{b}\n");
        }
    }
    let f = write(dir.path(), "g.csv", &text);
    let data = read(&format!("biaxial={}", f.display())).unwrap();
    assert_eq!(
        data[0].test,
        palpate_studies::records::TestKind::GeneralBiaxial
    );
    assert_eq!(data[0].observed.len(), 32);
    let c = fit(law, &data, None);
    assert_params(&c, &[("mu1", 0.4), ("alpha1", 3.0)], 1e-5);
}

#[test]
fn simple_shear_alone_and_superposed_on_axial_stretches() {
    let dir = tempfile::tempdir().unwrap();
    // Mooney-Rivlin in plain shear gives only C10 + C01; at two axial stretches
    // P12 = 2 gamma (lambda C10 + C01) separates them.
    let (law, p) = (Law::MooneyRivlin, [0.002, 0.0005]);
    let mut specs = Vec::new();
    for (lambda, name) in [(0.8, "a.csv"), (1.2, "b.csv")] {
        let m = SimpleShear::new(law, lambda).unwrap();
        let mut text = String::from("amount_of_shear,shear_stress_kPa\n");
        for k in 0..21 {
            let g = -0.2 + 0.4 * k as f64 / 20.0;
            text += &format!("{g},{}\n", m.stress(&p, g) * 1e3);
        }
        let f = write(dir.path(), name, &text);
        specs.push(format!(
            "simple_shear[axial_stretch={lambda}]={}",
            f.display()
        ));
    }
    let data = read_data(&specs, None).unwrap();
    assert_eq!(data[1].axial_stretch, 1.2);
    let c = fit(law, &data, None);
    assert_params(&c, &[("C10", 0.002), ("C01", 0.0005)], 1e-6);
    // Plain simple shear of a Yeoh solid to gamma = 1 identifies C10 and C20.
    let (law, p) = (Law::ReducedPolynomial(2), [0.3, 0.05]);
    let m = SimpleShear::new(law, 1.0).unwrap();
    let mut text = String::from("amount_of_shear,shear_stress_MPa\n");
    for k in 0..21 {
        let g = k as f64 / 20.0;
        text += &format!("{g},{}\n", m.stress(&p, g));
    }
    let f = write(dir.path(), "s.csv", &text);
    let c = fit(
        law,
        &read(&format!("simple_shear={}", f.display())).unwrap(),
        None,
    );
    assert_params(&c, &[("C10", 0.3), ("C20", 0.05)], 1e-6);
}

/// Ramp to `s` in 2 s, hold to 60 s, back down at the same rate.
fn history(s: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut t, mut d) = (Vec::new(), Vec::new());
    for k in 0..=40 {
        t.push(2.0 * k as f64 / 40.0);
        d.push(1.0 + (s - 1.0) * k as f64 / 40.0);
    }
    for k in 1..=60 {
        t.push(2.0 + 58.0 * (k as f64 / 60.0).powi(2));
        d.push(s);
    }
    (t, d)
}

#[test]
fn viscoelastic_uniaxial_records_recover_prony_terms() {
    let dir = tempfile::tempdir().unwrap();
    let law = Law::NeoHookean;
    for (viscous, theta) in [
        (Viscous::Qlv(1), [0.05, 0.4, 5.0]),
        (Viscous::Finite(1), [0.05, 0.4, 5.0]),
    ] {
        let model: Box<dyn ForwardModel> = match viscous {
            Viscous::Qlv(n) => Box::new(Viscoelastic::new(
                Box::new(Homogeneous::new(law, Mode::Uniaxial)),
                n,
            )),
            Viscous::Finite(n) => Box::new(ViscousUniaxial::new(law, n).unwrap()),
        };
        let mut specs = Vec::new();
        for s in [1.5, 3.0] {
            let (t, d) = history(s);
            let y = model
                .predict(
                    &theta,
                    &Loading::timed(Drive::Stretch, t.clone(), d.clone()),
                )
                .unwrap();
            let mut text = String::from("time_s,strain,stress_MPa\n");
            for k in 0..t.len() {
                text += &format!("{},{},{}\n", t[k], d[k] - 1.0, y[k]);
            }
            let f = write(dir.path(), &format!("r{s}.csv"), &text);
            specs.push(format!("uniaxial={}", f.display()));
        }
        let data = read_data(&specs, None).unwrap();
        assert!(data[0].loading.time.is_some());
        let c = fit(law, &data, Some(viscous));
        assert_params(&c, &[("C10", 0.05), ("g1", 0.4), ("tau1_s", 5.0)], 1e-4);
    }
}

/// One load-unload cycle to stretch `s` at the nominal strain rate `rate`
/// (1/s), as the VHB records: up and straight back down.
fn cycle(s: f64, rate: f64) -> (Vec<f64>, Vec<f64>) {
    let half = (s - 1.0) / rate;
    let (mut t, mut d) = (Vec::new(), Vec::new());
    for k in 0..=80 {
        let u = k as f64 / 40.0;
        t.push(half * u);
        d.push(1.0 + (s - 1.0) * if u <= 1.0 { u } else { 2.0 - u });
    }
    (t, d)
}

#[test]
fn viscoelastic_load_unload_cycles_at_several_rates_recover_prony_terms() {
    let dir = tempfile::tempdir().unwrap();
    // Yeoh with two Prony terms whose times (1 s, 30 s) bracket the cycle
    // times (10 s to 200 s): the three rates separate them.
    let law = Law::ReducedPolynomial(2);
    let theta = [0.04, 0.002, 0.5, 1.0, 0.2, 30.0];
    for viscous in [Viscous::Qlv(2), Viscous::Finite(2)] {
        let model: Box<dyn ForwardModel> = match viscous {
            Viscous::Qlv(n) => Box::new(Viscoelastic::new(
                Box::new(Homogeneous::new(law, Mode::Uniaxial)),
                n,
            )),
            Viscous::Finite(n) => Box::new(ViscousUniaxial::new(law, n).unwrap()),
        };
        let mut specs = Vec::new();
        for rate in [0.01, 0.05, 0.2] {
            let (t, d) = cycle(2.0, rate);
            let y = model
                .predict(
                    &theta,
                    &Loading::timed(Drive::Stretch, t.clone(), d.clone()),
                )
                .unwrap();
            // Hysteresis: the unloading branch lies below the loading one.
            assert!(
                y[30] > y[50] + 1e-3,
                "{viscous:?} rate {rate}: no hysteresis"
            );
            let mut text = String::from("time_s,stretch,stress_kPa\n");
            for k in 0..t.len() {
                text += &format!("{},{},{}\n", t[k], d[k], y[k] * 1e3);
            }
            let f = write(dir.path(), &format!("c{rate}.csv"), &text);
            specs.push(format!("uniaxial={}", f.display()));
        }
        let data = read_data(&specs, None).unwrap();
        let c = fit(law, &data, Some(viscous));
        assert_params(&c, &[("C10", 0.04), ("C20", 0.002)], 1e-4);
        // The terms may come out in either order: compared sorted by tau.
        let v = |n: &str| c.params.get(n).unwrap().value;
        let mut terms = [(v("tau1_s"), v("g1")), (v("tau2_s"), v("g2"))];
        terms.sort_by(|a, b| a.0.total_cmp(&b.0));
        for ((tau, g), (tau0, g0)) in terms.iter().zip([(1.0, 0.5), (30.0, 0.2)]) {
            assert!(
                (tau - tau0).abs() <= 1e-4 * tau0 && (g - g0).abs() <= 1e-4 * g0,
                "{viscous:?}: (tau, g) = ({tau}, {g}), expected ({tau0}, {g0}); R2 {}",
                c.r2
            );
        }
    }
}

#[test]
fn weights_pull_a_joint_fit_towards_the_heavier_record() {
    let dir = tempfile::tempdir().unwrap();
    let m = Homogeneous::new(Law::NeoHookean, Mode::Uniaxial);
    let mut files = Vec::new();
    for (c10, name) in [(0.1, "soft.csv"), (0.2, "stiff.csv")] {
        let mut text = String::from("stretch,stress_MPa\n");
        for k in 1..10 {
            let s = 1.0 + 0.1 * k as f64;
            text += &format!("{s},{}\n", m.stress(&[c10], s));
        }
        files.push(write(dir.path(), name, &text));
    }
    let c10 = |w: f64| {
        let data = read_data(
            &[
                format!("uniaxial={}", files[0].display()),
                format!("uniaxial[weight={w}]={}", files[1].display()),
            ],
            None,
        )
        .unwrap();
        fit(Law::NeoHookean, &data, None)
            .params
            .get("C10")
            .unwrap()
            .value
    };
    assert!((c10(1.0) - 0.15).abs() < 1e-3);
    assert!((c10(100.0) - 0.2).abs() < 1e-3, "{}", c10(100.0));
}

fn error(spec: &str) -> String {
    format!("{:#}", read(spec).unwrap_err())
}

#[test]
fn bad_files_name_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A stretch of zero, a strain below -1 (negative stretch).
    let f = write(d, "zero.csv", "# c\nstretch,stress_MPa\n1,0\n0,1\n");
    let e = error(&format!("uniaxial={}", f.display()));
    assert!(
        e.contains("zero.csv:4") && e.contains("`stretch`") && e.contains("positive"),
        "{e}"
    );
    let f = write(d, "neg.csv", "strain,stress_MPa\n0,0\n-1.5,1\n");
    let e = error(&format!("uniaxial={}", f.display()));
    assert!(e.contains("neg.csv:3") && e.contains("`strain`"), "{e}");
    // A shear file with a stretch column.
    let f = write(
        d,
        "sh.csv",
        "stretch,amount_of_shear,shear_stress_MPa\n1,0,0\n1,0.1,1\n",
    );
    let e = error(&format!("simple_shear={}", f.display()));
    assert!(
        e.contains("sh.csv:1:") && e.contains("`stretch`") && e.contains("axial_stretch"),
        "{e}"
    );
    // A shear file given as uniaxial.
    let f = write(
        d,
        "sh2.csv",
        "amount_of_shear,shear_stress_MPa\n0,0\n0.1,1\n",
    );
    let e = error(&format!("uniaxial={}", f.display()));
    assert!(
        e.contains("sh2.csv:1:") && e.contains("`amount_of_shear`") && e.contains("simple_shear"),
        "{e}"
    );
    // Inconsistent units: stress_MPa and stress_kPa that disagree (same numbers).
    let f = write(
        d,
        "u.csv",
        "stretch,stress_MPa,stress_kPa\n1,0,0\n1.1,0.2,0.2\n",
    );
    let e = error(&format!("uniaxial={}", f.display()));
    assert!(
        e.contains("u.csv:3") && e.contains("`stress_kPa`") && e.contains("units"),
        "{e}"
    );
    // ... stretch and strain that disagree (strain written in percent).
    let f = write(d, "s.csv", "stretch,strain,stress_MPa\n1,0,0\n1.1,10,0.2\n");
    let e = error(&format!("uniaxial={}", f.display()));
    assert!(e.contains("s.csv:3") && e.contains("`strain`"), "{e}");
    // ... a stress with no unit.
    // (after two comment lines: the header is line 3)
    let f = write(d, "n.csv", "# a\n# b\nstretch,stress\n1,0\n1.1,0.2\n");
    let e = error(&format!("uniaxial={}", f.display()));
    assert!(
        e.contains("n.csv:3:") && e.contains("`stress`") && e.contains("stress_MPa"),
        "{e}"
    );
    // An axial stretch on a uniaxial record, a bad option, a bad weight.
    let f = write(d, "ok.csv", "stretch,stress_MPa\n1,0\n1.1,0.2\n");
    assert!(
        error(&format!("uniaxial[axial_stretch=0.8]={}", f.display())).contains("simple-shear")
    );
    assert!(error(&format!("uniaxial[wieght=2]={}", f.display())).contains("unknown data option"));
    assert!(error(&format!("uniaxial[weight=-2]={}", f.display())).contains("positive"));
    assert!(split_data("uniaxial[weight=2").is_err());
    // General biaxial with one stress column missing.
    let f = write(
        d,
        "g.csv",
        "lambda1,lambda2,stress1_MPa\n1,1,0\n1.1,1,0.2\n",
    );
    let e = error(&format!("biaxial={}", f.display()));
    assert!(e.contains("g.csv:1:") && e.contains("stress2_MPa"), "{e}");
}
