//! The sparse solvers' tests: one symbolic analysis for many numeric
//! factorisations, the symmetric LDL^T and its fallback, the pressures
//! ordered after their displacements, GMRES, and solves on kept factors.

use super::*;

#[test]
fn solves_an_unsymmetric_system_twice_with_one_symbolic_analysis() {
    // two overlapping "elements" on 3 unknowns, one constrained entry
    let eqs = vec![vec![0, 1], vec![1, 2, NONE]];
    let p = Pattern::new(3, &eqs);
    assert_eq!(p.nnz(), 7);
    let mut lu = SparseLu::new(&p).unwrap();
    for shift in [0.0, 1.0] {
        let mut vals = vec![0.0; p.nnz()];
        let k0 = [[4.0 + shift, 1.0], [2.0, 3.0]];
        let k1 = [[1.0, -1.0, 9.0], [0.5, 2.0, 9.0], [9.0, 9.0, 9.0]];
        for (e, k) in [
            (
                0usize,
                &k0[..].iter().map(|r| r.to_vec()).collect::<Vec<_>>(),
            ),
            (1, &k1[..].iter().map(|r| r.to_vec()).collect()),
        ] {
            let n = eqs[e].len();
            for i in 0..n {
                for j in 0..n {
                    let s = p.slots[e][i * n + j];
                    if s != NONE {
                        vals[s] += k[i][j];
                    }
                }
            }
        }
        // dense check: A = [[4+s,1,0],[2,4,-1],[0,0.5,2]]
        let a = [[4.0 + shift, 1.0, 0.0], [2.0, 4.0, -1.0], [0.0, 0.5, 2.0]];
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i][j] * x[j]).sum())
            .collect();
        lu.solve(&vals, &mut b).unwrap();
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-12, "{b:?}");
        }
    }
    assert_eq!(lu.factorisations, 2);
}

#[test]
fn the_symmetric_factorisation_solves_what_the_lu_solves_and_falls_back_on_a_zero_pivot() {
    // a symmetric tridiagonal (indefinite) system through 2-node "elements"
    let n = 40;
    let eqs: Vec<Vec<usize>> = (0..n - 1).map(|i| vec![i, i + 1]).collect();
    let p = Pattern::new(n, &eqs);
    let mut vals = vec![0.0; p.nnz()];
    for i in 0..n {
        let d = if i % 7 == 3 {
            -3.0
        } else {
            4.0 + i as f64 * 0.1
        };
        vals[p.slot(i, i).unwrap()] = d;
        if i + 1 < n {
            vals[p.slot(i, i + 1).unwrap()] = 1.0 + 0.01 * i as f64;
            vals[p.slot(i + 1, i).unwrap()] = 1.0 + 0.01 * i as f64;
        }
    }
    let rhs: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
    let mut lu = SparseLu::new(&p).unwrap();
    let mut x_lu = rhs.clone();
    lu.solve(&vals, &mut x_lu).unwrap();
    lu.set_symmetric(true).unwrap();
    let mut x_ldlt = rhs.clone();
    lu.solve(&vals, &mut x_ldlt).unwrap();
    assert_eq!(lu.ldlt_fallbacks, 0);
    for i in 0..n {
        assert!(
            (x_lu[i] - x_ldlt[i]).abs() < 1e-12,
            "{i}: {} vs {}",
            x_lu[i],
            x_ldlt[i]
        );
    }
    // a zero leading pivot in every ordering: [[0, 1], [1, 0]] blocks
    let eqs2 = vec![vec![0, 1]];
    let p2 = Pattern::new(2, &eqs2);
    let mut v2 = vec![0.0; p2.nnz()];
    v2[p2.slot(0, 1).unwrap()] = 1.0;
    v2[p2.slot(1, 0).unwrap()] = 1.0;
    let mut lu2 = SparseLu::new(&p2).unwrap();
    lu2.set_symmetric(true).unwrap();
    let mut b = vec![2.0, 3.0];
    lu2.solve(&v2, &mut b).unwrap();
    assert_eq!(lu2.ldlt_fallbacks, 1);
    assert!(
        (b[0] - 3.0).abs() < 1e-14 && (b[1] - 2.0).abs() < 1e-14,
        "{b:?}"
    );
}

/// A saddle-point system like an exactly incompressible mixed element's
/// (displacements with a positive definite block, pressures with a zero
/// diagonal): the LDL^T with the pressures ordered after their
/// displacements solves it without falling back to the LU (AMD alone
/// would take a pressure first: zero pivot), and GMRES preconditioned
/// with the symmetric part solves an unsymmetric perturbation of it,
/// both as the LU does.
#[test]
fn owned_unknowns_last_and_gmres_solve_a_saddle_point_system() {
    let (nu, np) = (24, 6);
    let n = nu + np;
    // "cells": 5 consecutive displacements and one pressure
    let eqs: Vec<Vec<usize>> = (0..np)
        .map(|j| {
            let mut v: Vec<usize> = (4 * j..(4 * j + 5).min(nu)).collect();
            v.push(nu + j);
            v
        })
        .collect();
    let p = Pattern::new(n, &eqs);
    let mut vals = vec![0.0; p.nnz()];
    let mut add = |r: usize, c: usize, v: f64| {
        vals[p.slot(r, c).unwrap()] += v;
    };
    for (j, e) in eqs.iter().enumerate() {
        let u = &e[..e.len() - 1];
        for (a, &r) in u.iter().enumerate() {
            add(r, r, 3.0 + 0.1 * r as f64);
            if a + 1 < u.len() {
                add(r, u[a + 1], -1.0);
                add(u[a + 1], r, -1.0);
            }
            let g = 0.5 + 0.2 * ((a + j) % 3) as f64;
            add(r, nu + j, g);
            add(nu + j, r, g);
        }
    }
    let rhs: Vec<f64> = (0..n).map(|i| ((i * 7) % 5) as f64 - 2.0).collect();
    let solve = |vals: &[f64], mode: &str| {
        let mut lu = SparseLu::new(&p).unwrap();
        lu.set_first_owned(nu);
        match mode {
            "ldlt" => lu.set_symmetric(true).unwrap(),
            "gmres" => lu.set_gmres(true).unwrap(),
            _ => {}
        }
        let mut x = rhs.clone();
        lu.solve(vals, &mut x).unwrap();
        (x, lu.ldlt_fallbacks, lu.gmres_solves, lu.gmres_fallbacks)
    };
    let (x_lu, ..) = solve(&vals, "lu");
    let (x_ldlt, fallbacks, ..) = solve(&vals, "ldlt");
    assert_eq!(fallbacks, 0);
    // an unsymmetric perturbation (friction-like, on a few displacements)
    let mut skew = vals.clone();
    for r in 0..6 {
        skew[p.slot(r, r + 1).unwrap()] += 0.4;
    }
    let (x_lu2, ..) = solve(&skew, "lu");
    let (x_gm, fallbacks, solves, gmres_fallbacks) = solve(&skew, "gmres");
    assert_eq!((fallbacks, solves, gmres_fallbacks), (0, 1, 0));
    for i in 0..n {
        assert!((x_lu[i] - x_ldlt[i]).abs() < 1e-10, "{i}");
        assert!((x_lu2[i] - x_gm[i]).abs() < 1e-8, "{i}");
    }
    // the ordering puts every pressure after its displacements
    let (fwd, inv) = owned_last_amd(p_symbolic(&p).as_ref(), nu).unwrap();
    assert_eq!(fwd.len(), n);
    for (j, e) in eqs.iter().enumerate() {
        let last = e[..e.len() - 1].iter().map(|&r| inv[r]).max().unwrap();
        assert!(inv[nu + j] > last, "pressure {j}");
    }
    // Kept factors: the perturbed system solved by GMRES on the
    // symmetric system's factors gives the LU's solution with no new
    // factorisation; with too few iterations allowed it factorises.
    let mut lu = SparseLu::new(&p).unwrap();
    lu.set_first_owned(nu);
    lu.set_gmres(true).unwrap();
    let mut x = rhs.clone();
    assert!(
        lu.solve_reusing(&vals, &mut x, 30).unwrap(),
        "no factors yet"
    );
    let mut x = rhs.clone();
    assert!(!lu.solve_reusing(&skew, &mut x, 30).unwrap());
    assert_eq!((lu.factorisations, lu.reused_solves), (1, 1));
    for i in 0..n {
        assert!((x_lu2[i] - x[i]).abs() < 1e-8, "{i}");
    }
    let mut far = skew.clone();
    far.iter_mut().for_each(|v| *v *= 1.0 + 0.5 * v.signum());
    let mut x = rhs.clone();
    assert!(
        lu.solve_reusing(&far, &mut x, 1).unwrap(),
        "one iteration is not enough"
    );
    assert_eq!((lu.factorisations, lu.reused_solves), (2, 1));
    let mut x_far = rhs.clone();
    solve_lu_of(&p, &far, &mut x_far);
    for i in 0..n {
        assert!((x_far[i] - x[i]).abs() < 1e-8, "{i}");
    }
}

fn solve_lu_of(p: &Pattern, vals: &[f64], x: &mut [f64]) {
    let mut lu = SparseLu::new(p).unwrap();
    lu.solve(vals, x).unwrap();
}

fn p_symbolic(p: &Pattern) -> SymbolicSparseColMat<usize> {
    SymbolicSparseColMat::new_checked(p.n, p.n, p.col_ptr.clone(), None, p.row_idx.clone())
}
