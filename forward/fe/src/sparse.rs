//! The global sparse tangent: a compressed-column pattern built once from the
//! element connectivity, and faer's sparse LU (unsymmetric, partial pivoting)
//! whose symbolic analysis (ordering, elimination structure) is computed once
//! and reused for every numeric factorisation. Optionally a symmetric LDL^T
//! factorisation instead: of the tangent itself when it is symmetric, or of
//! its symmetric part as the preconditioner of GMRES ([`crate::gmres`]) when
//! it is not (3D meshes, where the LU's fill is many times the LDL^T's).

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

use crate::gmres::{gmres, GmresOutcome};
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
    /// The LU's symbolic analysis, made at the first LU factorisation (a
    /// run that only uses the LDL^T never pays for it).
    lu: Option<LuSymbolic>,
    numeric: NumericLu<usize, f64>,
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
    /// How the LDL^T is used: `None` not at all, `Some(false)` the tangent
    /// is symmetric, `Some(true)` GMRES on the tangent with the LDL^T of its
    /// symmetric part as preconditioner.
    mode: Option<bool>,
    /// Equations from this one on are owned unknowns (pressures: zero or
    /// negative diagonal), ordered after their neighbours for the LDL^T.
    first_owned: usize,
    /// The values of the last factorised matrix (GMRES multiplies by it).
    values: Vec<f64>,
    /// Slot of the transposed entry of each slot (GMRES mode).
    transpose: Vec<usize>,
    /// GMRES solves and their iterations; solves that fell back to the LU.
    pub gmres_solves: usize,
    pub gmres_iterations: usize,
    pub gmres_fallbacks: usize,
    /// Solves of [`SparseLu::solve_reusing`] done on kept factors.
    pub reused_solves: usize,
}

/// The LU's symbolic analysis and its scratch.
struct LuSymbolic {
    symbolic: SymbolicLu<usize>,
    factor_scratch: MemBuffer,
    solve_scratch: MemBuffer,
}

/// GMRES relative residual target and iteration limit (one restart cycle).
const GMRES_TOLERANCE: f64 = 1e-10;

const GMRES_MAX_ITERATIONS: usize = 80;

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
    /// Symbolic analysis of `pattern` (the LU's is made on first use).
    pub fn new(pattern: &Pattern) -> Result<SparseLu, FeError> {
        let symbolic_mat = SymbolicSparseColMat::new_checked(
            pattern.n,
            pattern.n,
            pattern.col_ptr.clone(),
            None,
            pattern.row_idx.clone(),
        );
        Ok(SparseLu {
            symbolic_mat,
            lu: None,
            numeric: NumericLu::new(),
            factorisations: 0,
            factored: false,
            ldlt: None,
            ldlt_factored: false,
            ldlt_fallbacks: 0,
            mode: None,
            first_owned: pattern.n,
            values: Vec::new(),
            transpose: Vec::new(),
            gmres_solves: 0,
            gmres_iterations: 0,
            gmres_fallbacks: 0,
            reused_solves: 0,
        })
    }

    /// Marks the equations from `first` on as owned unknowns (the pressures
    /// of a mixed element): the LDL^T orders each right after the last of
    /// its displacement neighbours, so its pivot is the (negative) Schur
    /// complement of the displacements already eliminated, never the zero
    /// diagonal of an exactly incompressible element.
    pub fn set_first_owned(&mut self, first: usize) {
        if first != self.first_owned {
            self.first_owned = first.min(self.symbolic_mat.nrows());
            self.ldlt = None;
            self.mode = None;
        }
    }

    fn lu_symbolic(&mut self) -> Result<&mut LuSymbolic, FeError> {
        if self.lu.is_none() {
            let symbolic = factorize_symbolic_lu(
                self.symbolic_mat.as_ref(),
                LuSymbolicParams {
                    supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                    ..Default::default()
                },
            )
            .map_err(|e| FeError::Factorisation {
                reason: format!("symbolic analysis: {e:?}"),
            })?;
            let factor_scratch = MemBuffer::new(
                symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            );
            let solve_scratch = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
            self.lu = Some(LuSymbolic {
                symbolic,
                factor_scratch,
                solve_scratch,
            });
        }
        Ok(self.lu.as_mut().expect("made above"))
    }

    /// Uses a symmetric LDL^T factorisation (the lower triangle of the
    /// matrix) instead of the LU from now on (`true`), or the LU again
    /// (`false`). Only for matrices that are symmetric: the upper triangle
    /// is not read. A factorisation that meets a zero pivot falls back to
    /// the LU (counted in [`SparseLu::ldlt_fallbacks`]).
    pub fn set_symmetric(&mut self, symmetric: bool) -> Result<(), FeError> {
        self.set_mode(symmetric.then_some(false))
    }

    /// Solves with GMRES preconditioned by the LDL^T of the matrix's
    /// symmetric part `(A + A^T) / 2` (`true`; a solve that does not reach
    /// a relative residual of 1e-10 in 80 iterations falls back to the LU),
    /// or with the LU again (`false`). For unsymmetric tangents whose
    /// unsymmetric part is small and local (frictional contact on a 3D
    /// body).
    pub fn set_gmres(&mut self, gmres: bool) -> Result<(), FeError> {
        self.set_mode(gmres.then_some(true))
    }

    fn set_mode(&mut self, mode: Option<bool>) -> Result<(), FeError> {
        if mode == self.mode {
            return Ok(());
        }
        self.mode = mode;
        self.factored = false;
        self.ldlt_factored = false;
        if mode.is_none() {
            self.ldlt = None;
            return Ok(());
        }
        if mode == Some(true) && self.transpose.is_empty() {
            let m = self.symbolic_mat.as_ref();
            let mut t = vec![NONE; m.compute_nnz()];
            for c in 0..m.ncols() {
                let start = m.col_ptr()[c];
                for (k, &r) in m.row_idx()[start..m.col_ptr()[c + 1]].iter().enumerate() {
                    let rows = &m.row_idx()[m.col_ptr()[r]..m.col_ptr()[r + 1]];
                    t[start + k] =
                        rows.binary_search(&c)
                            .map(|i| m.col_ptr()[r] + i)
                            .map_err(|_| FeError::Factorisation {
                                reason: "GMRES needs a structurally symmetric pattern".into(),
                            })?;
                }
            }
            self.transpose = t;
        }
        if self.ldlt.is_some() {
            return Ok(());
        }
        let (fwd, inv) = owned_last_amd(self.symbolic_mat.as_ref(), self.first_owned)?;
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, fwd.len());
        let symbolic = factorize_symbolic_cholesky(
            self.symbolic_mat.as_ref(),
            Side::Lower,
            SymmetricOrdering::Custom(perm),
            CholeskySymbolicParams {
                // faer's AUTO picks the simplicial factorisation for R2's
                // 2D tangent (11,144 unknowns), 2.2x slower there than the
                // supernodal one (58 -> 26 ms a factorisation);
                // 3D tangents (N3) were supernodal already
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
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

    /// Stored entries of the LDL^T factor (when enabled).
    pub fn ldlt_len(&self) -> Option<usize> {
        self.ldlt.as_ref().map(|l| l.symbolic.len_val())
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
        if let Some(gmres) = self.mode {
            let sym;
            let factor_values: &[f64] = if gmres {
                self.values.clear();
                self.values.extend_from_slice(values);
                sym = values
                    .iter()
                    .zip(&self.transpose)
                    .map(|(v, &t)| 0.5 * (v + values[t]))
                    .collect::<Vec<f64>>();
                &sym
            } else {
                values
            };
            let mat = SparseColMatRef::new(self.symbolic_mat.as_ref(), factor_values);
            let l = self.ldlt.as_mut().expect("made by set_mode");
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
        self.factorize_lu(values)
    }

    fn factorize_lu(&mut self, values: &[f64]) -> Result<(), FeError> {
        self.lu_symbolic()?;
        let lu = self.lu.as_mut().expect("made above");
        let mat = SparseColMatRef::new(self.symbolic_mat.as_ref(), values);
        lu.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                MemStack::new(&mut lu.factor_scratch),
                Default::default(),
            )
            .map_err(|e| FeError::Factorisation {
                reason: format!("{e:?}"),
            })?;
        self.factorisations += 1;
        self.factored = true;
        self.ldlt_factored = false;
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
        if self.ldlt_factored && self.mode == Some(true) {
            self.gmres_solves += 1;
            let b = rhs.to_vec();
            match self.gmres_on_factors(&b, rhs, GMRES_MAX_ITERATIONS) {
                GmresOutcome::Converged { iterations } => {
                    self.gmres_iterations += iterations;
                }
                GmresOutcome::NotConverged { iterations } => {
                    self.gmres_iterations += iterations;
                    self.gmres_fallbacks += 1;
                    let values = std::mem::take(&mut self.values);
                    let r = self.factorize_lu(&values);
                    self.values = values;
                    r?;
                    rhs.copy_from_slice(&b);
                    self.solve_lu(rhs)?;
                    // the LU stays the factorisation of this matrix
                    return check_finite(rhs);
                }
            }
            return check_finite(rhs);
        }
        match self.ldlt.as_mut() {
            Some(l) if self.ldlt_factored => LdltRef::new(&l.symbolic, &l.l_values)
                .solve_in_place_with_conj(
                    Conj::No,
                    faer::ColMut::from_slice_mut(rhs).as_mat_mut(),
                    Par::Seq,
                    MemStack::new(&mut l.solve_scratch),
                ),
            _ => self.solve_lu(rhs)?,
        }
        check_finite(rhs)
    }

    /// GMRES on the matrix `self.values` preconditioned with the kept
    /// LDL^T factors, from `x = 0`, at most `max_iterations`.
    fn gmres_on_factors(
        &mut self,
        b: &[f64],
        x: &mut [f64],
        max_iterations: usize,
    ) -> GmresOutcome {
        let l = self.ldlt.as_mut().expect("factored");
        let mat = SparseColMatRef::new(self.symbolic_mat.as_ref(), &self.values);
        gmres(
            |x: &[f64], y: &mut [f64]| {
                y.iter_mut().for_each(|v| *v = 0.0);
                for c in 0..mat.ncols() {
                    let xc = x[c];
                    if xc == 0.0 {
                        continue;
                    }
                    let (rows, vals) = (mat.row_idx_of_col_raw(c), mat.val_of_col(c));
                    for (&r, &v) in rows.iter().zip(vals) {
                        y[r] += v * xc;
                    }
                }
            },
            |z: &mut [f64]| {
                LdltRef::new(&l.symbolic, &l.l_values).solve_in_place_with_conj(
                    Conj::No,
                    faer::ColMut::from_slice_mut(z).as_mat_mut(),
                    Par::Seq,
                    MemStack::new(&mut l.solve_scratch),
                )
            },
            b,
            x,
            GMRES_TOLERANCE,
            max_iterations,
        )
    }

    /// Solves the matrix with values `values` (pattern order), overwriting
    /// `rhs`, by GMRES preconditioned with the LDL^T factors kept from an
    /// earlier matrix (a stale preconditioner: the Newton step is still the
    /// exact one, to GMRES's tolerance, with no new factorisation) when that
    /// converges within `limit` iterations; otherwise factorises `values`
    /// and solves as [`SparseLu::solve`]. Returns whether it factorised.
    /// Only in GMRES mode ([`SparseLu::set_gmres`]) with factors at hand;
    /// otherwise it is [`SparseLu::solve`].
    ///
    /// Refactorising only when the preconditioner has drifted is the
    /// "frozen preconditioner" inexact Newton of Knoll & Keyes (2004, J.
    /// Comput. Phys. 193:357, section 3.2): the factorisation, the dominant
    /// cost of a 3D solve, is then paid once per several Newton iterations
    /// or increments instead of once per iteration.
    pub fn solve_reusing(
        &mut self,
        values: &[f64],
        rhs: &mut [f64],
        limit: usize,
    ) -> Result<bool, FeError> {
        if self.mode == Some(true) && self.ldlt_factored && limit > 0 {
            self.values.clear();
            self.values.extend_from_slice(values);
            let b = rhs.to_vec();
            match self.gmres_on_factors(&b, rhs, limit) {
                GmresOutcome::Converged { iterations } if check_finite(rhs).is_ok() => {
                    self.gmres_solves += 1;
                    self.gmres_iterations += iterations;
                    self.reused_solves += 1;
                    return Ok(false);
                }
                GmresOutcome::Converged { iterations }
                | GmresOutcome::NotConverged { iterations } => {
                    self.gmres_iterations += iterations;
                    rhs.copy_from_slice(&b);
                }
            }
        }
        self.solve(values, rhs)?;
        Ok(true)
    }

    fn solve_lu(&mut self, rhs: &mut [f64]) -> Result<(), FeError> {
        let lu = self.lu.as_mut().ok_or_else(|| FeError::Factorisation {
            reason: "no LU factorisation to solve with".into(),
        })?;
        LuRef::new_unchecked(&lu.symbolic, &self.numeric).solve_in_place_with_conj(
            Conj::No,
            faer::ColMut::from_slice_mut(rhs).as_mat_mut(),
            Par::Seq,
            MemStack::new(&mut lu.solve_scratch),
        );
        Ok(())
    }
}

fn check_finite(x: &[f64]) -> Result<(), FeError> {
    if x.iter().any(|v| !v.is_finite()) {
        return Err(FeError::Factorisation {
            reason: "singular tangent (non-finite solution)".into(),
        });
    }
    Ok(())
}

/// The fill-reducing ordering of the LDL^T: approximate minimum degree
/// (faer's AMD) on the pattern of the equations before `first_owned` (the
/// displacements), then each owned unknown (a pressure) placed right after
/// the last of its neighbours in that order. Its pivot is then the Schur
/// complement `-g^T K^-1 g` of its eliminated displacements, negative for a
/// positive definite displacement block, where AMD on the whole pattern
/// would pick the pressures first (lowest degree) and meet their zero
/// diagonal. Returns the forward and inverse permutations.
fn owned_last_amd(
    a: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    first_owned: usize,
) -> Result<(Vec<usize>, Vec<usize>), FeError> {
    let n = a.ncols();
    let m = first_owned.min(n);
    // the displacement block's pattern
    let mut col_ptr = Vec::with_capacity(m + 1);
    let mut row_idx = Vec::new();
    col_ptr.push(0);
    for c in 0..m {
        row_idx.extend(a.row_idx_of_col_raw(c).iter().copied().filter(|&r| r < m));
        col_ptr.push(row_idx.len());
    }
    let mut fwd_m = vec![0usize; m];
    let mut inv_m = vec![0usize; m];
    if m > 0 {
        let sub = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
        let nnz = sub.compute_nnz();
        let mut mem = MemBuffer::try_new(faer::sparse::linalg::amd::order_scratch::<usize>(m, nnz))
            .map_err(|_| FeError::Factorisation {
                reason: "out of memory for the AMD ordering".into(),
            })?;
        faer::sparse::linalg::amd::order(
            &mut fwd_m,
            &mut inv_m,
            sub.as_ref(),
            Default::default(),
            MemStack::new(&mut mem),
        )
        .map_err(|e| FeError::Factorisation {
            reason: format!("AMD ordering: {e:?}"),
        })?;
    }
    // owned unknowns by the position of their last displacement neighbour
    let mut after: Vec<Vec<usize>> = vec![Vec::new(); m + 1];
    for p in m..n {
        let last = a
            .row_idx_of_col_raw(p)
            .iter()
            .filter(|&&r| r < m)
            .map(|&r| inv_m[r])
            .max();
        after[last.map_or(m, |t| t)].push(p);
    }
    let mut fwd = Vec::with_capacity(n);
    for (t, &e) in fwd_m.iter().enumerate() {
        fwd.push(e);
        fwd.extend_from_slice(&after[t]);
    }
    fwd.extend_from_slice(&after[m]);
    let mut inv = vec![0usize; n];
    for (i, &e) in fwd.iter().enumerate() {
        inv[e] = i;
    }
    Ok((fwd, inv))
}

#[cfg(test)]
#[path = "sparse_tests.rs"]
mod tests;
