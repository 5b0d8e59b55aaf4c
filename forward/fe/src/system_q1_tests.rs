//! Q1's assembled tangent near the depth where its Newton stops (about 2 mm
//! with the 0.2 mm edge; docs/validation/fe.md "Q1") against finite
//! differences of the assembled residual. The generic cases of
//! `system_tests.rs` check every kinematics and contact law on small
//! meshes; this checks the state the stop is about: the punch's rounded
//! edge carrying the surface, under the lagged multipliers Q1 uses.
//!
//! Ignored because it first runs the ramp (seconds in release, minutes in
//! a debug build): `cargo test --release -p palpate-fe --lib
//! q1_tangent -- --ignored` (env `Q1_DEPTH`, default 1.95 mm).

use super::*;
use palpate_core::{Drive, Loading};

#[test]
#[ignore = "a diagnostic at a chosen depth (env Q1_DEPTH); cargo test -p palpate-fe --lib q1_tangent -- --ignored"]
fn q1_tangent_near_the_stop_equals_finite_differences() {
    let depth: f64 = std::env::var("Q1_DEPTH")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1.95);
    let mut m = crate::Q1Punch::new("neo-hookean".parse().unwrap());
    m.level = 1;
    if std::env::var("Q1_SPLIT").as_deref() == Ok("1") {
        m.contact_points = crate::ContactPoints::EdgeSplit;
    }
    if let Some(r) = std::env::var("Q1_REFINE").ok().and_then(|v| v.parse().ok()) {
        m.edge_refinement = r;
    }
    let n = (depth / 0.05).round().max(1.0) as usize;
    let drive: Vec<f64> = (1..=n).map(|k| depth * k as f64 / n as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    let (_, mut sys) = m.simulate(&[1e-3], &loading, None).unwrap();
    // the committed state; its multipliers were updated at the commit, so
    // its residual is not zero, which does not matter for the check
    let target = sys.committed.clone();
    sys.assemble(&target, true).unwrap();
    let (pattern, values) = (sys.pattern.clone(), sys.values.clone());
    let equations = sys.dofs.equations;
    let column = |e: usize| {
        let mut c = vec![0.0; equations];
        let (first, rows) = pattern.column(e);
        for (i, &r) in rows.iter().enumerate() {
            c[r] = values[first + i];
        }
        c
    };
    // every free displacement of the nodes within 0.7 mm of the edge in r
    // and 0.7 mm of the top
    let near: Vec<usize> = (0..sys.mesh.nodes.len())
        .filter(|&i| {
            let x = sys.mesh.nodes[i];
            (x[0] - m.punch_radius).abs() < 0.7 && x[1] > m.height - 0.7
        })
        .flat_map(|nd| [2 * nd, 2 * nd + 1])
        .filter(|&s| sys.dofs.equation(s) != NONE)
        .collect();
    assert!(near.len() > 40, "{} entries", near.len());
    let h = 1e-8;
    let mut worst = (0.0f64, 0usize);
    for &s in &near {
        let k = column(sys.dofs.equation(s));
        let u0 = sys.u[s];
        sys.u[s] = u0 + h;
        sys.assemble(&target, false).unwrap();
        let plus = sys.residual.clone();
        sys.u[s] = u0 - h;
        sys.assemble(&target, false).unwrap();
        let minus = sys.residual.clone();
        sys.u[s] = u0;
        let scale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for r in 0..equations {
            let fd = (plus[r] - minus[r]) / (2.0 * h);
            let err = (fd - k[r]).abs() / scale;
            if err > worst.0 {
                worst = (err, s);
            }
        }
    }
    let nd = worst.1 / 2;
    assert!(
        worst.0 < 1e-5,
        "column of node {nd} ({:?}) off by {:.2e} of its largest entry",
        sys.mesh.nodes[nd],
        worst.0
    );
}
