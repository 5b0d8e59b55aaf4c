//! palpate's ANOVA, normality and equal-variance tests against statsmodels
//! and scipy (docs/validation/anova_statsmodels.py writes
//! docs/validation/anova_reference.json): 6 significant digits.

use palpate_uq::anova::{analyse, lenth, AnovaOptions, FactorColumn};
use palpate_uq::stats::{levene, LeveneCenter};
use serde_json::Value;
use std::path::Path;

fn reference() -> Value {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/anova_reference.json");
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// Agreement to 6 significant digits (relative 5e-7, or absolute for values near 0).
fn sig6(got: f64, want: f64, what: &str) {
    let tol = 5e-7 * want.abs().max(1e-300);
    assert!(
        (got - want).abs() <= tol || (got - want).abs() < 1e-15,
        "{what}: got {got}, statsmodels/scipy {want}"
    );
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

fn check_case(name: &str) {
    let r = &reference()[name];
    let factors: Vec<String> = r["factors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    let response = r["response"].as_str().unwrap();
    let cols: Vec<FactorColumn> = factors
        .iter()
        .map(|n| {
            let v: Vec<&str> = r["data"][n]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_str().unwrap())
                .collect();
            FactorColumn::from_names(n.as_str(), &v)
        })
        .collect();
    let y: Vec<f64> = r["data"][response]
        .as_array()
        .unwrap()
        .iter()
        .map(f)
        .collect();
    let a = analyse(response, &cols, &y, &AnovaOptions::default()).unwrap();
    for want in r["terms"].as_array().unwrap() {
        let tn = want["name"].as_str().unwrap();
        let got = a
            .table
            .term(tn)
            .unwrap_or_else(|| panic!("{name}: no term {tn}"));
        assert_eq!(
            got.df as u64,
            want["df"].as_u64().unwrap(),
            "{name} {tn} df"
        );
        sig6(got.ss, f(&want["ss"]), &format!("{name} {tn} ss"));
        sig6(got.ms.unwrap(), f(&want["ms"]), &format!("{name} {tn} ms"));
        sig6(got.f.unwrap(), f(&want["f"]), &format!("{name} {tn} F"));
        sig6(got.p.unwrap(), f(&want["p"]), &format!("{name} {tn} p"));
        sig6(
            got.eta_sq,
            f(&want["eta_sq"]),
            &format!("{name} {tn} eta_sq"),
        );
        sig6(
            got.partial_eta_sq.unwrap(),
            f(&want["partial_eta_sq"]),
            &format!("{name} {tn} partial_eta_sq"),
        );
    }
    assert_eq!(
        a.table.residual.df as u64,
        r["residual"]["df"].as_u64().unwrap()
    );
    sig6(
        a.table.residual.ss,
        f(&r["residual"]["ss"]),
        &format!("{name} SSE"),
    );
    sig6(a.table.r2, f(&r["r2"]), &format!("{name} r2"));
    sig6(
        a.table.adj_r2.unwrap(),
        f(&r["adj_r2"]),
        &format!("{name} adj_r2"),
    );
    let ad = a.anderson_darling.as_ref().unwrap();
    sig6(
        ad.a2,
        f(&r["anderson_darling"]["a2"]),
        &format!("{name} AD"),
    );
    sig6(
        ad.p,
        f(&r["anderson_darling"]["p"]),
        &format!("{name} AD p"),
    );
    let rj = a.ryan_joiner.as_ref().unwrap();
    sig6(rj.r, f(&r["ryan_joiner"]["r"]), &format!("{name} RJ r"));
    sig6(rj.p, f(&r["ryan_joiner"]["p"]), &format!("{name} RJ p"));
    let b = a.bartlett.as_ref().unwrap();
    sig6(
        b.statistic,
        f(&r["bartlett"]["statistic"]),
        &format!("{name} Bartlett"),
    );
    sig6(b.p, f(&r["bartlett"]["p"]), &format!("{name} Bartlett p"));
    if r["levene"].is_null() {
        assert!(a.levene.is_none(), "{name}: Levene should be undefined");
    } else {
        let l = a.levene.as_ref().unwrap();
        sig6(
            l.statistic,
            f(&r["levene"]["statistic"]),
            &format!("{name} Levene"),
        );
        sig6(l.p, f(&r["levene"]["p"]), &format!("{name} Levene p"));
        let groups: Vec<Vec<f64>> = palpate_uq::anova::cells(&cols)
            .iter()
            .map(|g| g.iter().map(|&i| y[i]).collect())
            .collect();
        let lm = levene(&groups, LeveneCenter::Mean).unwrap();
        sig6(
            lm.statistic,
            f(&r["levene_mean"]["statistic"]),
            &format!("{name} Levene (mean)"),
        );
        sig6(
            lm.p,
            f(&r["levene_mean"]["p"]),
            &format!("{name} Levene (mean) p"),
        );
    }
}

#[test]
fn table1_matches_statsmodels() {
    check_case("table1");
}

#[test]
fn three_by_two_with_multi_df_terms_matches_statsmodels() {
    check_case("threebytwo");
}

#[test]
fn unbalanced_sequential_ss_match_statsmodels_type1() {
    check_case("unbalanced");
}

#[test]
fn lenth_matches_an_independent_scipy_computation() {
    let r = &reference()["filtration"]["lenth"];
    let effects: Vec<f64> = reference()["filtration"]["effects"]
        .as_object()
        .unwrap()
        .values()
        .map(f)
        .collect();
    let l = lenth(&effects, 0.05).unwrap();
    sig6(l.s0, f(&r["s0"]), "s0");
    sig6(l.pse, f(&r["pse"]), "PSE");
    sig6(l.me, f(&r["me"]), "ME");
    sig6(l.sme, f(&r["sme"]), "SME");
}
