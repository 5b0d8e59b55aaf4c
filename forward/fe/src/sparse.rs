//! The global sparse tangent: a compressed-column pattern built once from the
//! element connectivity, and faer's sparse LU (unsymmetric, partial pivoting)
//! whose symbolic analysis (ordering, elimination structure) is computed once
//! and reused for every numeric factorisation.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, Par, Side};

use crate::FeError;

/// Marks a constrained (eliminated) degree of freedom.
pub const NONE: usize = usize::MAX;

/// Compressed-column sparsity pattern with, for each element, the value slot
/// of each local (row, column) pair.
#[derive(Debug, Clone)]
pub struct Pattern {
    pub n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Per element, `nloc * nloc` slots (row-major local), [`NONE`] when constrained.
    pub slots: Vec<Vec<usize>>,
}

impl Pattern {
    /// Pattern of the square system of size `n` whose elements couple the
    /// global equations `element_eqs[e]` ([`NONE`] entries are skipped).
    pub fn new(n: usize, element_eqs: &[Vec<usize>]) -> Pattern {
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for eqs in element_eqs {
            for &c in eqs.iter().filter(|&&c| c != NONE) {
                cols[c].extend(eqs.iter().copied().filter(|&r| r != NONE));
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for c in cols.iter_mut() {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        let slot = |r: usize, c: usize| -> usize {
            let s = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            col_ptr[c] + s.binary_search(&r).unwrap_or(0)
        };
        let slots = element_eqs
            .iter()
            .map(|eqs| {
                let mut v = Vec::with_capacity(eqs.len() * eqs.len());
                for &r in eqs {
                    for &c in eqs {
                        v.push(if r == NONE || c == NONE {
                            NONE
                        } else {
                            slot(r, c)
                        });
                    }
                }
                v
            })
            .collect();
        Pattern {
            n,
            col_ptr,
            row_idx,
            slots,
        }
    }

    /// First slot and sorted row indices of column `c`.
    pub fn column(&self, c: usize) -> (usize, &[usize]) {
        (
            self.col_ptr[c],
            &self.row_idx[self.col_ptr[c]..self.col_ptr[c + 1]],
        )
    }

    /// Slot of entry (r, c); `None` when it is not in the pattern.
    pub fn slot(&self, r: usize, c: usize) -> Option<usize> {
        let (start, rows) = self.column(c);
        rows.binary_search(&r).ok().map(|k| start + k)
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
}

/// A sparse LU solver that keeps the symbolic factorisation (column
/// ordering and elimination structure) and the numeric storage and scratch
/// between factorisations. Runs sequentially inside faer: the element loop
/// and the callers (several evaluators) hold the cores.
pub struct SparseLu {
    symbolic_mat: SymbolicSparseColMat<usize>,
    symbolic_lu: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_scratch: MemBuffer,
    solve_scratch: MemBuffer,
    /// Number of numeric factorisations done.
    pub factorisations: usize,
    /// Whether `numeric` holds valid factors.
    factored: bool,
    /// The symmetric factorisation, when enabled ([`SparseLu::set_symmetric`]).
    ldlt: Option<Ldlt>,
    /// Which factors the last factorisation left: `true` the LDL^T ones.
    ldlt_factored: bool,
    /// Symmetric factorisations that met a zero pivot and fell back to LU.
    pub ldlt_fallbacks: usize,
}

/// A sparse LDL^T factorisation (faer's supernodal Cholesky without
/// pivoting: fill-reducing AMD ordering computed once), for tangents that are
/// symmetric (hyperelastic bodies, frictionless contact). About half the
/// work of the LU with partial pivoting; no pivoting, so a zero pivot is an
/// error and the caller falls back to the LU.
struct Ldlt {
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    factor_scratch: MemBuffer,
    solve_scratch: MemBuffer,
}

impl SparseLu {
    /// Symbolic analysis of `pattern`.
    pub fn new(pattern: &Pattern) -> Result<SparseLu, FeError> {
        let symbolic_mat = SymbolicSparseColMat::new_checked(
            pattern.n,
            pattern.n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        let symbolic_lu = factorize_symbolic_lu(
            symbolic_mat.as_ref(),
            LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(|e| FeError::Factorisation {
            reason: format!("symbolic analysis: {e:?}"),
        })?;
        let factor_scratch = MemBuffer::new(
            symbolic_lu.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
        );
        let solve_scratch = MemBuffer::new(symbolic_lu.solve_in_place_scratch::<f64>(1, Par::Seq));
        Ok(SparseLu {
            symbolic_mat,
            symbolic_lu,
            numeric: NumericLu::new(),
            factor_scratch,
            solve_scratch,
            factorisations: 0,
            factored: false,
            ldlt: None,
            ldlt_factored: false,
            ldlt_fallbacks: 0,
        })
    }

    /// Uses a symmetric LDL^T factorisation (the lower triangle of the
    /// matrix) instead of the LU from now on (`true`), or the LU again
    /// (`false`). Only for matrices that are symmetric: the upper triangle
    /// is not read. A factorisation that meets a zero pivot falls back to
    /// the LU (counted in [`SparseLu::ldlt_fallbacks`]).
    pub fn set_symmetric(&mut self, symmetric: bool) -> Result<(), FeError> {
        if !symmetric {
            self.ldlt = None;
            self.ldlt_factored = false;
            self.factored = false;
            return Ok(());
        }
        if self.ldlt.is_some() {
            return Ok(());
        }
        let symbolic = factorize_symbolic_cholesky(
            self.symbolic_mat.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| FeError::Factorisation {
            reason: format!("symbolic LDL^T analysis: {e:?}"),
        })?;
        let factor_scratch = MemBuffer::new(
            symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
        );
        let solve_scratch = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        self.ldlt = Some(Ldlt {
            l_values: vec![0.0; symbolic.len_val()],
            symbolic,
            factor_scratch,
            solve_scratch,
        });
        Ok(())
    }

    /// Factorises the matrix with values `values` (in pattern order) and
    /// overwrites `rhs` with the solution.
    pub fn solve(&mut self, values: &[f64], rhs: &mut [f64]) -> Result<(), FeError> {
        self.factorize(values)?;
        self.solve_factored(rhs)
    }

    /// Numeric factorisation of the matrix with values `values`; the factors
    /// are kept for [`SparseLu::solve_factored`].
    pub fn factorize(&mut self, values: &[f64]) -> Result<(), FeError> {
        self.factored = false;
        self.ldlt_factored = false;
        let mat = SparseColMatRef::new(self.symbolic_mat.as_ref(), values);
        if let Some(l) = self.ldlt.as_mut() {
            let ok = l
                .symbolic
                .factorize_numeric_ldlt(
                    &mut l.l_values,
                    mat,
                    Side::Lower,
                    LdltRegularization::default(),
                    Par::Seq,
                    MemStack::new(&mut l.factor_scratch),
                    Default::default(),
                )
                .is_ok()
                && l.l_values.iter().all(|v| v.is_finite());
            if ok {
                self.factorisations += 1;
                self.factored = true;
                self.ldlt_factored = true;
                return Ok(());
            }
            self.ldlt_fallbacks += 1;
        }
        self.symbolic_lu
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                MemStack::new(&mut self.factor_scratch),
                Default::default(),
            )
            .map_err(|e| FeError::Factorisation {
                reason: format!("{e:?}"),
            })?;
        self.factorisations += 1;
        self.factored = true;
        Ok(())
    }

    /// Overwrites `rhs` with the solution for the last factorised matrix
    /// (a chord step of a modified Newton method when the matrix changed since).
    pub fn solve_factored(&mut self, rhs: &mut [f64]) -> Result<(), FeError> {
        if !self.factored {
            return Err(FeError::Factorisation {
                reason: "no factorisation to solve with".into(),
            });
        }
        match self.ldlt.as_mut() {
            Some(l) if self.ldlt_factored => LdltRef::new(&l.symbolic, &l.l_values)
                .solve_in_place_with_conj(
                    Conj::No,
                    faer::ColMut::from_slice_mut(rhs).as_mat_mut(),
                    Par::Seq,
                    MemStack::new(&mut l.solve_scratch),
                ),
            _ => LuRef::new_unchecked(&self.symbolic_lu, &self.numeric).solve_in_place_with_conj(
                Conj::No,
                faer::ColMut::from_slice_mut(rhs).as_mat_mut(),
                Par::Seq,
                MemStack::new(&mut self.solve_scratch),
            ),
        }
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(FeError::Factorisation {
                reason: "singular tangent (non-finite solution)".into(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
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
}
