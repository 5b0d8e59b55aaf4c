//! Mesa-Munera et al. (2011), Table 1: R^2 of needle-indentation simulations,
//! 2 x 2 factorial (material NH/RP x space axisymmetric/3D), two replicates.
//! The published analysis printed p = 0.001, 0.033, 0.046 (material, space,
//! interaction), eta^2 = 0.826, 0.079, 0.063, adjusted R^2 = 94.57 %,
//! Ryan-Joiner p > 0.1 and Bartlett p = 0.409.
//!
//! The table's R^2 values are printed to 5 decimals; computed from them,
//! most published numbers agree on rounding, three differ by one unit of the
//! last printed digit (p of material 0.000496, eta^2 of the interaction
//! 0.06371, adjusted R^2 94.579 %) and Bartlett's p by two (0.4109). No
//! perturbation of the data within their rounding (+-5e-6) reproduces all
//! printed values at once (docs/validation/anova.md), so the test asserts
//! each value within the stated number of units of its last printed digit.

use palpate_uq::anova::{analyse, AnovaOptions, RunsTable};
use palpate_uq::stats::PBound;
use std::path::Path;

fn table1() -> palpate_uq::anova::Analysis {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/mesa2011/published-table1.csv");
    let t = RunsTable::read(&path).unwrap();
    let factors = vec![t.factor("material").unwrap(), t.factor("space").unwrap()];
    let y = t.numeric("r2").unwrap();
    analyse("r2", &factors, &y, &AnovaOptions::default()).unwrap()
}

/// |got - printed| <= units * 10^-decimals.
fn near(got: f64, printed: f64, decimals: i32, units: f64) -> bool {
    (got - printed).abs() <= units * 10f64.powi(-decimals) + 1e-12
}

#[test]
fn table1_reproduces_the_published_analysis() {
    let a = table1();
    let t = &a.table;
    assert!(t.balanced);
    let names: Vec<&str> = t.terms.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["material", "space", "material:space"]);
    let p: Vec<f64> = t.terms.iter().map(|r| r.p.unwrap()).collect();
    let eta: Vec<f64> = t.terms.iter().map(|r| r.eta_sq).collect();
    // Agree on rounding to 3 decimals:
    assert!(
        near(p[1], 0.033, 3, 0.5) && near(p[2], 0.046, 3, 0.5),
        "{p:?}"
    );
    assert!(
        near(eta[0], 0.826, 3, 0.5) && near(eta[1], 0.079, 3, 0.5),
        "{eta:?}"
    );
    // One unit of the last printed digit:
    assert!(near(p[0], 0.001, 3, 1.0), "{p:?}");
    assert!(near(eta[2], 0.063, 3, 1.0), "{eta:?}");
    assert!(
        near(100.0 * t.adj_r2.unwrap(), 94.57, 2, 1.0),
        "{:?}",
        t.adj_r2
    );
    // Significance conclusions at alpha = 0.05 are the published ones.
    assert!(p.iter().all(|&p| p < 0.05));
    let rj = a.ryan_joiner.as_ref().unwrap();
    assert_eq!(rj.p_bound, PBound::Above, "{rj:?}");
    assert_eq!(rj.p_text(), "> 0.100");
    // Bartlett: two units of the last printed digit (0.4109 vs 0.409).
    let b = a.bartlett.as_ref().unwrap();
    assert!(near(b.p, 0.409, 3, 2.0), "{b:?}");
    // Levene (median) is undefined with two runs per cell.
    assert!(a.levene.is_none());
    assert!(
        a.notes.iter().any(|n| n.contains("Levene")),
        "{:?}",
        a.notes
    );
}

#[test]
fn table1_sums_of_squares_add_up() {
    let a = table1();
    let t = &a.table;
    let sum: f64 = t.terms.iter().map(|r| r.ss).sum::<f64>() + t.residual.ss;
    assert!(
        (sum - t.total.ss).abs() < 1e-12 * t.total.ss.max(1e-30) + 1e-18,
        "{sum} vs {}",
        t.total.ss
    );
    assert_eq!(t.residual.df, 4);
    assert_eq!(t.total.df, 7);
    // Balanced 2x2: t^2 of each coefficient equals F.
    for r in &t.terms {
        let tval = r.coefficients[0] / r.coefficient_se[0].unwrap();
        assert!(
            (tval * tval - r.f.unwrap()).abs() < 1e-9 * r.f.unwrap(),
            "{r:?}"
        );
    }
    // The material effect is the difference of the level means.
    let me = &a.main_effects[0];
    let effect = me.means[1] - me.means[0];
    assert!((2.0 * t.terms[0].coefficients[0] - effect).abs() < 1e-14);
}
