//! Treloar (1944) fits of five laws to uniaxial data alone and to the three
//! modes jointly, with absolute and relative residuals, compared with an
//! independent scipy implementation (`docs/validation/treloar_scipy.py`,
//! output committed as `docs/validation/treloar_scipy.json`): SSE to 4
//! significant digits always, parameters where our report says the fit is
//! identifiable. Both sides run the same deterministic starting points and
//! keep the best SSE.
//!
//! Gent, Veronda-Westmann and Humphrey are compared the same way with
//! `docs/validation/laws/treloar_scipy_laws.py` (output
//! `docs/validation/laws/treloar_scipy_laws.json`).
//!
//! `TRELOAR_TABLE=1 cargo test -p palpate-tests --test integration treloar_fits:: -- --nocapture`
//! prints the markdown table of `docs/validation/treloar.md`.

use palpate_analytic::{Homogeneous, Mode};
use palpate_core::{Drive, Loading, Table};
use palpate_inverse::{fit, BoundSide, DataSet, FitOptions, FitReport, Objective, ResidualKind};
use palpate_material::{Law, OGDEN_ALPHA_BOUND};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn treloar() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/data/treloar")
}

fn data_set(law: Law, mode: &str) -> DataSet {
    let file = match mode {
        "uniaxial" => "uniaxial.csv",
        "equibiaxial" => "biaxial.csv",
        "planar" => "pure_shear.csv",
        other => panic!("unknown mode {other}"),
    };
    let table = Table::read(treloar().join(file)).unwrap();
    let stretch = table.column("stretch").unwrap().to_vec();
    let stress = table.column("stress_MPa").unwrap().to_vec();
    let model = Homogeneous::new(law, mode.parse::<Mode>().unwrap());
    DataSet::new(
        mode,
        Arc::new(model),
        Loading::quasi_static(Drive::Stretch, stretch),
        stress,
    )
}

fn law_of(name: &str) -> Law {
    match name {
        "neo_hookean" => Law::NeoHookean,
        "mooney_rivlin" => Law::MooneyRivlin,
        "yeoh" => Law::ReducedPolynomial(3),
        "arruda_boyce" => Law::ArrudaBoyce,
        "ogden3" => Law::Ogden(3),
        "gent" => Law::Gent,
        "veronda_westmann" => Law::VerondaWestmann,
        "humphrey" => Law::Humphrey,
        other => panic!("unknown law {other}"),
    }
}

/// Best fit over the reference's starting points.
fn best_fit(case: &Value) -> FitReport {
    let law = law_of(case["law"].as_str().unwrap());
    let modes: Vec<&str> = case["data"].as_str().unwrap().split('+').collect();
    let residual: ResidualKind = case["residual"].as_str().unwrap().parse().unwrap();
    let sets = modes.iter().map(|m| data_set(law, m)).collect();
    let objective = Objective::new(sets, residual, &[]).unwrap();
    let mut best: Option<FitReport> = None;
    for start in case["starts"].as_array().unwrap() {
        let start: Vec<f64> = start
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let options = FitOptions {
            start: Some(start),
            ..FitOptions::default()
        };
        // Some random Ogden starts are outside the law's domain (sum mu <= 0): skipped, as in scipy.
        match fit(&objective, &options) {
            Ok(r) => {
                if best.as_ref().is_none_or(|b| r.sse < b.sse) {
                    best = Some(r);
                }
            }
            Err(e) if std::env::var("TRELOAR_TABLE").is_ok() => eprintln!("start failed: {e}"),
            Err(_) => {}
        }
    }
    // Polish: restart from the best point (fresh damping and scaling) while
    // the SSE still drops, as degenerate Ogden terms (mu_i -> 0) stall the
    // scaled LM of the first run.
    let mut best = best.expect("at least one start succeeds");
    for _ in 0..20 {
        let options = FitOptions {
            start: Some(best.theta()),
            ..FitOptions::default()
        };
        match fit(&objective, &options) {
            Ok(r) if r.sse < best.sse * (1.0 - 1e-9) => best = r,
            _ => break,
        }
    }
    best
}

fn reference() -> Value {
    reference_at("treloar_scipy.json")
}

/// A reference JSON under `docs/validation/`.
fn reference_at(file: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs/validation")
        .join(file);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Parameters by name, with Ogden terms `(mu_i, alpha_i)` renumbered in
/// increasing alpha: the response is the same whatever the terms' order, so
/// either side may label them differently.
fn canonical(params: Vec<(String, f64)>) -> Vec<(String, f64)> {
    let value = |n: &str| params.iter().find(|(m, _)| m == n).map(|(_, v)| *v);
    let mut terms: Vec<(f64, f64)> = (1..)
        .map_while(|i| Some((value(&format!("mu{i}"))?, value(&format!("alpha{i}"))?)))
        .collect();
    let mut out: Vec<(String, f64)> = if terms.is_empty() {
        params.clone()
    } else {
        terms.sort_by(|a, b| a.1.total_cmp(&b.1));
        terms
            .iter()
            .enumerate()
            .flat_map(|(k, (mu, alpha))| {
                [
                    (format!("mu{}", k + 1), *mu),
                    (format!("alpha{}", k + 1), *alpha),
                ]
            })
            .collect()
    };
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn check(law: &str) {
    check_against(law, &reference());
}

fn check_against(law: &str, reference: &Value) {
    let mut cases = 0;
    let table = std::env::var("TRELOAR_TABLE").is_ok();
    for case in reference["fits"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["law"] == law)
    {
        cases += 1;
        let r = best_fit(case);
        let label = format!("{} / {} / {}", law, case["data"], case["residual"]);
        let sse_ref = case["sse"].as_f64().unwrap();
        if table {
            let params: Vec<String> = r
                .parameters
                .iter()
                .map(|p| format!("{} = {:.5e}", p.name, p.value))
                .collect();
            eprintln!(
                "| {} | {} | {} | {:.6e} | {:.6e} | {} | {:.5} | {} |",
                law,
                case["data"].as_str().unwrap(),
                case["residual"].as_str().unwrap(),
                r.sse,
                sse_ref,
                params.join(", "),
                r.r_squared,
                if r.identifiability.identifiable {
                    "yes".to_string()
                } else {
                    format!("no ({})", r.identifiability.reason)
                },
            );
        }
        // Optima on a box bound (Ogden alpha2 = 20) are reached by the
        // boundary polish, optima on a law's admissibility limit
        // (Mooney-Rivlin C10 + C01 = 0) by the wall slide: every case is
        // held to 4 significant digits (and never below the reference).
        assert!(
            (r.sse - sse_ref).abs() <= 5e-5 * sse_ref,
            "{label}: SSE {} vs scipy {sse_ref}",
            r.sse
        );
        assert_eq!(r.n_residuals as u64, case["n"].as_u64().unwrap(), "{label}");
        if r.identifiability.identifiable {
            let ours = canonical(
                r.parameters
                    .iter()
                    .map(|p| (p.name.clone(), p.value))
                    .collect(),
            );
            let theirs = canonical(
                case["params"]
                    .as_object()
                    .unwrap()
                    .iter()
                    .map(|(n, v)| (n.clone(), v.as_f64().unwrap()))
                    .collect(),
            );
            assert_eq!(ours.len(), theirs.len(), "{label}");
            for ((name, got), (_, v)) in ours.iter().zip(&theirs) {
                assert!(
                    (got - v).abs() <= 5e-5 * v.abs(),
                    "{label}: {name} = {got} vs scipy {v}"
                );
            }
        }
    }
    assert_eq!(cases, 4, "{law}: the reference has 4 fits of each law");
}

#[test]
fn neo_hookean_matches_scipy() {
    check("neo_hookean");
}

#[test]
fn mooney_rivlin_matches_scipy() {
    check("mooney_rivlin");
}

#[test]
fn yeoh_matches_scipy() {
    check("yeoh");
}

#[test]
fn arruda_boyce_matches_scipy() {
    check("arruda_boyce");
}

#[test]
fn ogden3_matches_scipy_with_one_exponent_on_its_bound_and_is_not_identifiable_on_uniaxial_data() {
    check("ogden3");
    let reference = reference();
    let case = |residual: &str| {
        reference["fits"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["law"] == "ogden3" && c["data"] == "uniaxial" && c["residual"] == residual)
            .unwrap()
            .clone()
    };
    // Absolute residuals: the optimum has one exponent on its upper bound
    // (OGDEN_ALPHA_BOUND, with its mu -> 0: any bound is a regularisation
    // there), reported as such. At the bound 50 a second term vanishes too
    // (mu ~ 2e-4, |corr(mu, alpha)| > 0.999), so the fit is reported not
    // identifiable (at the old bound 20 the other five were); the dominant
    // term still matches scipy's.
    let c = case("absolute");
    let r = best_fit(&c);
    let on_bound: Vec<_> = r
        .parameters
        .iter()
        .filter(|p| p.name.starts_with("alpha") && p.at_bound.is_some())
        .collect();
    assert_eq!(on_bound.len(), 1, "{:?}", r.parameters);
    assert_eq!(on_bound[0].value, OGDEN_ALPHA_BOUND);
    assert_eq!(on_bound[0].at_bound, Some(BoundSide::Upper));
    assert!(!r.identifiability.identifiable, "{:?}", r.identifiability);
    let dominant = |p: Vec<(String, f64)>| {
        let p = canonical(p);
        let v = |n: String| p.iter().find(|(m, _)| *m == n).unwrap().1;
        (1..=3)
            .map(|i| (v(format!("mu{i}")), v(format!("alpha{i}"))))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap()
    };
    let ours = dominant(
        r.parameters
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .collect(),
    );
    let theirs = dominant(
        c["params"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(n, v)| (n.clone(), v.as_f64().unwrap()))
            .collect(),
    );
    assert!(
        (ours.0 - theirs.0).abs() <= 1e-4 * theirs.0
            && (ours.1 - theirs.1).abs() <= 1e-4 * theirs.1.abs(),
        "dominant term {ours:?} vs scipy {theirs:?}"
    );
    // Relative residuals: an interior optimum with a vanishing term
    // (mu2 ~ 2e-9), reported not identifiable.
    let r = best_fit(&case("relative"));
    assert!(!r.identifiability.identifiable, "{:?}", r.identifiability);
}

fn laws_reference() -> Value {
    reference_at("laws/treloar_scipy_laws.json")
}

#[test]
fn gent_matches_scipy() {
    check_against("gent", &laws_reference());
}

#[test]
fn veronda_westmann_matches_scipy() {
    check_against("veronda_westmann", &laws_reference());
}

#[test]
fn humphrey_matches_scipy() {
    check_against("humphrey", &laws_reference());
}
