//! The fits of the real measurements against an independent scipy
//! implementation (`docs/validation/real_data_scipy.py`, output committed as
//! `docs/validation/real_data_scipy.json`): every kind of record (uniaxial
//! tension/compression, general and equibiaxial biaxial, planar, simple
//! shear alone and on an axial stretch with kPa override and weights, QLV and
//! finite-strain viscoelastic VHB records), single and joint fits, absolute
//! and normalised residuals. Both sides run the same starting points and keep
//! the best SSE (ours also from `calibrate`'s optimum); SSE agrees to 1e-4,
//! parameters where our report calls the fit identifiable and no parameter
//! sits on a bound (Ogden exponents in plain shear by magnitude: the
//! response is even in alpha there). The product path
//! (`calibrate`, its own starts) is held to 1 % of the scipy SSE.
//!
//! `REAL_TABLE=1 cargo test -p palpate-studies --test integration real_data_fits:: -- --nocapture`
//! prints the table of `docs/validation/real-data.md`.

use palpate_inverse::{fit, DataSet, FitOptions, FitReport, Objective, ResidualKind};
use palpate_material::Law;
use palpate_studies::cli::calibrate::read_data;
use palpate_studies::model::calibration::{calibrate, parse_method, Request};
use palpate_studies::model::{build, Viscous};
use palpate_studies::records::TestData;
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

fn law_of(name: &str) -> Law {
    match name {
        "neo_hookean" => Law::NeoHookean,
        "mooney_rivlin" => Law::MooneyRivlin,
        "yeoh" => Law::ReducedPolynomial(3),
        n if n.starts_with("ogden") => Law::Ogden(n[5..].parse().unwrap()),
        other => panic!("unknown law {other}"),
    }
}

fn records(case: &Value) -> Vec<TestData> {
    let real = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real");
    let specs: Vec<String> = case["data"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            let d = d.as_str().unwrap();
            let (head, path) = d.rsplit_once('=').unwrap();
            format!("{head}={}", real.join(path).display())
        })
        .collect();
    read_data(&specs, None).unwrap()
}

fn viscous(case: &Value) -> Option<Viscous> {
    case["viscous"].as_str().map(|v| Viscous::parse(v).unwrap())
}

/// Best fit over the reference's starting points, polished.
fn best_fit(case: &Value, data: &[TestData], also: Vec<f64>) -> FitReport {
    let law = law_of(case["law"].as_str().unwrap());
    let residual: ResidualKind = case["residual"].as_str().unwrap().parse().unwrap();
    let sets: Vec<DataSet> = data
        .iter()
        .map(|d| {
            d.dataset(Arc::from(
                build(&palpate_studies::model::record_spec(d, law, viscous(case))).unwrap(),
            ))
        })
        .collect();
    let objective = Objective::new(sets, residual, &[]).unwrap();
    let mut best: Option<FitReport> = None;
    let starts = case["starts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            s.as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect::<Vec<f64>>()
        })
        .chain(std::iter::once(also));
    for start in starts {
        let options = FitOptions {
            start: Some(start),
            ..FitOptions::default()
        };
        if let Ok(r) = fit(&objective, &options) {
            if best.as_ref().is_none_or(|b| r.sse < b.sse) {
                best = Some(r);
            }
        }
    }
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

/// Parameters with the interchangeable terms in canonical order: Ogden
/// pairs `(mu_i, alpha_i)` by alpha, Prony pairs `(g_i, tau_i)` by tau (the
/// response is symmetric in the terms, so either side may label them
/// differently).
fn canonical(params: Vec<(String, f64)>) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for (first, second) in [("mu", "alpha"), ("g", "tau")] {
        let mut pairs: Vec<(f64, f64)> = Vec::new();
        for (n, v) in &params {
            let Some(i) = n.strip_prefix(first).filter(|i| i.parse::<usize>().is_ok()) else {
                continue;
            };
            let partner = params
                .iter()
                .find(|(m, _)| {
                    m.strip_prefix(second)
                        .map(|r| r.trim_end_matches("_s") == i)
                        .unwrap_or(false)
                })
                .unwrap();
            pairs.push((*v, partner.1));
        }
        pairs.sort_by(|a, b| a.1.total_cmp(&b.1));
        for (k, (a, b)) in pairs.into_iter().enumerate() {
            out.push((format!("{first}{}", k + 1), a));
            out.push((format!("{second}{}", k + 1), b));
        }
    }
    for (n, v) in &params {
        let paired = ["mu", "alpha", "g", "tau"].iter().any(|p| {
            n.strip_prefix(p)
                .is_some_and(|r| r.trim_end_matches("_s").parse::<usize>().is_ok())
        });
        if !paired {
            out.push((n.clone(), *v));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn reference() -> Value {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/real_data_scipy.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn check(prefix: &str) {
    let reference = reference();
    let table = std::env::var("REAL_TABLE").is_ok();
    let cases: Vec<&Value> = reference["fits"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["id"].as_str().unwrap().starts_with(prefix))
        .collect();
    assert!(!cases.is_empty(), "no case {prefix}");
    for case in cases {
        let id = case["id"].as_str().unwrap();
        let data = records(case);
        let sse_ref = case["sse"].as_f64().unwrap();
        let product = calibrate(Request {
            law: law_of(case["law"].as_str().unwrap()),
            model: None,
            fitted: &data,
            predict: &[],
            residual: case["residual"].as_str().unwrap().parse().unwrap(),
            method: parse_method("lm").unwrap(),
            fixed: Vec::new(),
            observer: None,
            viscous: viscous(case),
        })
        .unwrap();
        // The reference's starts, and the product's optimum as one more start.
        let r = best_fit(case, &data, product.fit.theta());
        if table {
            let params: Vec<String> = r
                .parameters
                .iter()
                .map(|p| {
                    format!(
                        "{} = {:.4e}{}",
                        p.name,
                        p.value,
                        if p.at_bound.is_some() { " (bound)" } else { "" }
                    )
                })
                .collect();
            eprintln!(
                "| {id} | {:.6e} | {:.6e} | {:.6e} | {} | {:.4} | {} |",
                r.sse,
                sse_ref,
                product.sse,
                params.join(", "),
                r.r_squared,
                if r.identifiability.identifiable {
                    "yes".to_string()
                } else {
                    format!("no ({})", r.identifiability.reason)
                },
            );
        }
        assert!(
            (r.sse - sse_ref).abs() <= 1e-4 * sse_ref,
            "{id}: SSE {} vs scipy {sse_ref}",
            r.sse
        );
        assert!(
            product.sse <= 1.01 * sse_ref,
            "{id}: calibrate's own starts reach SSE {} vs scipy {sse_ref}",
            product.sse
        );
        assert_eq!(r.n_residuals as u64, case["n"].as_u64().unwrap(), "{id}");
        let on_bound = r.parameters.iter().any(|p| p.at_bound.is_some());
        if r.identifiability.identifiable && !on_bound {
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
            // Plain simple shear: principal stretches (l, 1, 1/l), so a
            // one-term Ogden response is even in alpha and either side may
            // land on +alpha or -alpha with the same SSE: compare |alpha|.
            let even_in_alpha = case["data"]
                .as_array()
                .unwrap()
                .iter()
                .all(|d| d.as_str().unwrap().starts_with("simple_shear="));
            for ((name, got), (_, v)) in ours.iter().zip(&theirs) {
                let (got, v) = if even_in_alpha && name.starts_with("alpha") {
                    (&got.abs(), &v.abs())
                } else {
                    (got, v)
                };
                assert!(
                    (got - v).abs() <= 1e-3 * v.abs().max(1e-12),
                    "{id}: {name} = {got} vs scipy {v}"
                );
            }
        }
    }
}

#[test]
fn brain_regions_match_scipy() {
    for r in [
        "cortex",
        "basal_ganglia",
        "corona_radiata-",
        "corpus_callosum",
    ] {
        check(r);
    }
}

#[test]
fn kawabata_and_meunier_match_scipy() {
    check("kawabata");
    check("meunier");
}

#[test]
fn marechal_silicones_match_scipy() {
    check("marechal");
}

#[test]
fn vhb_viscoelastic_fits_match_scipy() {
    check("vhb");
}
