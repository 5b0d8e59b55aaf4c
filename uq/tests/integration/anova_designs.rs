//! Designs and Lenth's method: the 2^(4-1) half fraction with I = ABCD, and
//! Montgomery's filtration-rate example analysed by Lenth's PSE.

use palpate_uq::anova::{analyse, AnovaOptions, FactorColumn};
use palpate_uq::doe::{Design, Factor};

fn two_level(names: &[&str]) -> Vec<Factor> {
    names.iter().map(|n| Factor::new(*n, ["-", "+"])).collect()
}

#[test]
fn half_fraction_2_4_1_is_resolution_iv_with_the_textbook_aliases() {
    // Montgomery, Design and Analysis of Experiments, 8th ed., sec. 8.2:
    // D = ABC gives I = ABCD; main effects are aliased with three-factor
    // interactions and two-factor interactions with each other in pairs.
    let d = Design::fractional(two_level(&["A", "B", "C", "D"]), &["D=ABC"], 1).unwrap();
    assert_eq!(d.len(), 8);
    let words: Vec<String> = d
        .defining_relation()
        .iter()
        .map(|w| w.to_string())
        .collect();
    assert_eq!(words, ["ABCD"]);
    assert_eq!(d.resolution(), Some(4));
    let chains: Vec<String> = d.alias_chains(2).iter().map(|c| c.to_string()).collect();
    assert_eq!(
        chains,
        ["A + BCD", "B + ACD", "C + ABD", "D + ABC", "AB + CD", "AC + BD", "AD + BC"]
    );
    // D = ABC in every run, and all 8 runs are distinct.
    for r in &d.runs {
        let abc = d.coded(r, 0) * d.coded(r, 1) * d.coded(r, 2);
        assert_eq!(d.coded(r, 3), abc);
    }
    let mut levels: Vec<Vec<usize>> = d.runs.iter().map(|r| r.levels.clone()).collect();
    levels.sort();
    levels.dedup();
    assert_eq!(levels.len(), 8);
    // The negative fraction I = -ABCD.
    let neg = Design::fractional(two_level(&["A", "B", "C", "D"]), &["D=-ABC"], 1).unwrap();
    assert_eq!(neg.defining_relation()[0].to_string(), "-ABCD");
    assert_eq!(neg.alias_chains(1)[0].to_string(), "A - BCD");
}

#[test]
fn quarter_fraction_resolution_and_generator_errors() {
    // 2^(6-2) with E = ABC, F = BCD: I = ABCE = BCDF = ADEF, resolution IV.
    let d = Design::fractional(
        two_level(&["A", "B", "C", "D", "E", "F"]),
        &["E=ABC", "F=BCD"],
        2,
    )
    .unwrap();
    assert_eq!(d.len(), 32);
    let words: Vec<String> = d
        .defining_relation()
        .iter()
        .map(|w| w.to_string())
        .collect();
    assert_eq!(words, ["ABCE", "ADEF", "BCDF"]);
    assert_eq!(d.resolution(), Some(4));
    assert!(Design::fractional(two_level(&["A", "B", "C", "D"]), &["D=AE"], 1).is_err());
    assert!(
        Design::fractional(two_level(&["A", "B", "C", "D", "E"]), &["D=ABC", "E=AD"], 1).is_err()
    );
    let three = vec![
        Factor::new("A", ["1", "2", "3"]),
        Factor::new("B", ["-", "+"]),
        Factor::new("C", ["-", "+"]),
    ];
    assert!(Design::fractional(three, &["C=AB"], 1).is_err());
    assert_eq!(
        Design::full_factorial(two_level(&["A", "B"]), 1)
            .unwrap()
            .resolution(),
        None
    );
}

#[test]
fn fractional_effect_estimates_the_sum_of_aliased_effects() {
    // Response y = 3 A + 2 BCD (coded): in the half fraction A and BCD are
    // aliased, so the estimated A effect is 2 (3 + 2) = 10.
    let d = Design::fractional(two_level(&["A", "B", "C", "D"]), &["D=ABC"], 1)
        .unwrap()
        .randomised(11);
    let y: Vec<f64> = d
        .runs
        .iter()
        .map(|r| 3.0 * d.coded(r, 0) + 2.0 * d.coded(r, 1) * d.coded(r, 2) * d.coded(r, 3))
        .collect();
    let factors: Vec<FactorColumn> = (0..4)
        .map(|f| FactorColumn {
            name: d.factors[f].name.clone(),
            levels: d.factors[f].levels.clone(),
            codes: d.runs.iter().map(|r| r.levels[f]).collect(),
        })
        .collect();
    let a = analyse(
        "y",
        &factors,
        &y,
        &AnovaOptions {
            max_order: Some(2),
            ..Default::default()
        },
    )
    .unwrap();
    let t = a.table.term("A").unwrap();
    assert!((2.0 * t.coefficients[0] - 10.0).abs() < 1e-12, "{t:?}");
    // AB, AC, AD each alias with CD, BD, BC: the later ones have no df.
    assert_eq!(a.table.term("C:D").unwrap().df, 0);
    assert_eq!(a.table.term("A:B").unwrap().df, 1);
    assert!(
        a.notes
            .iter()
            .any(|n| n.contains("C:D") && n.contains("aliased")),
        "{:?}",
        a.notes
    );
}

#[test]
fn montgomery_filtration_rate_by_lenths_method() {
    // Montgomery, Design and Analysis of Experiments, 8th ed., Example 6.2
    // (pilot-plant filtration rate, unreplicated 2^4, runs in standard
    // order). Published effects: A 21.625, C 9.875, D 14.625, AC -18.125,
    // AD 16.625; Lenth's method in the same text: PSE = 1.5 x 1.75 = 2.625,
    // ME = 6.75, SME = 13.70 (d = 15/3 = 5).
    let rate = [
        45.0, 71.0, 48.0, 65.0, 68.0, 60.0, 80.0, 65.0, 43.0, 100.0, 45.0, 104.0, 75.0, 86.0, 70.0,
        96.0,
    ];
    let d = Design::full_factorial(two_level(&["A", "B", "C", "D"]), 1).unwrap();
    let factors: Vec<FactorColumn> = (0..4)
        .map(|f| FactorColumn {
            name: d.factors[f].name.clone(),
            levels: d.factors[f].levels.clone(),
            codes: d.runs.iter().map(|r| r.levels[f]).collect(),
        })
        .collect();
    let a = analyse("rate", &factors, &rate, &AnovaOptions::default()).unwrap();
    assert_eq!(a.table.residual.df, 0);
    let p = a.pareto.as_ref().unwrap();
    assert_eq!(p.method, "lenth");
    let effect = |n: &str| {
        p.effects
            .iter()
            .find(|e| e.term == n)
            .unwrap()
            .effect
            .unwrap()
    };
    for (n, want) in [
        ("A", 21.625),
        ("C", 9.875),
        ("D", 14.625),
        ("A:C", -18.125),
        ("A:D", 16.625),
        ("A:B:C:D", 1.375),
    ] {
        assert!((effect(n) - want).abs() < 1e-12, "{n}: {}", effect(n));
    }
    let l = p.lenth.as_ref().unwrap();
    assert!((l.s0 - 3.9375).abs() < 1e-12);
    assert!((l.pse - 2.625).abs() < 1e-12, "{l:?}");
    assert!((l.me - 6.75).abs() < 0.005, "{l:?}");
    assert!((l.sme - 13.70).abs() < 0.005, "{l:?}");
    // Largest five effects are A, A:C, A:D, D, C (above ME); none else is.
    let top: Vec<&str> = p.effects.iter().take(5).map(|e| e.term.as_str()).collect();
    assert_eq!(top, ["A", "A:C", "A:D", "D", "C"]);
    assert!(p.effects[4].standardised.abs() > p.reference);
    assert!(p.effects[5].standardised.abs() < p.reference);
    // No residual checks without error df.
    assert!(a.ryan_joiner.is_none() && a.table.terms.iter().all(|t| t.p.is_none()));
}
