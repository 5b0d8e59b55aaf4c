//! The solid kernel: one implementation, over the node count `N` and the
//! reference dimension `D` (fixed-size local algebra), for every continuum
//! cell in every kinematics, with the pressure field of [`PressureSpace`].
//!
//! Residual and tangent are the exact first and second derivatives of the
//! condensed element functional (see [`super::pressure`]):
//!
//! ```text
//! r_u = int B^T P_iso dV + G^T p                 G_m = dv_m/du = int psi_m (dJ/dF : B) dV
//! K_uu = int B^T A_iso B dV + sum_m p_m int psi_m B^T (d2J/dF2) B dV  [+ G^T M^-1 Q M^-1 G]
//! ```
//!
//! with `p = s q` for the exact constraint (plus the rows `s (v - V)` and
//! the coupling `s G`), and `p = M^-1 int U'(theta) psi dV`,
//! `Q = int U''(theta) psi psi^T dV` for the penalty. The operator B holds
//! `dF_k / du_(a,c)`: `dN_a/dX_j` at `k = 3 c + j`, and in axisymmetry also
//! `N_a / R` at `k = 8` (hoop) for `c = 0`. In plane stress the material
//! point returns the condensed in-plane stress and tangent and there is no
//! pressure field.

use nalgebra::{Matrix3, SMatrix, SVector};
use palpate_material::Volumetric;

use super::{ElementInput, ElementKernel, ElementOutput, PressureSpace, Scratch};
use crate::kinematics::{jacobian_derivs_3d, Kinematics};
use crate::material::{AtPoint, PointMaterial};
use crate::mesh::CellType;
use crate::quadrature::QuadratureRule;
use crate::shape::ShapeEval;
use crate::FeError;

/// One column of B: the (at most four) components of `F` that the
/// displacement dof moves, and by how much.
#[derive(Debug, Clone, Copy, Default)]
struct BColumn {
    k: [usize; 4],
    v: [f64; 4],
    len: usize,
}

/// Reference geometry of one quadrature point.
struct PointGeometry<const N: usize> {
    n: [f64; N],
    /// `dN_a / dX_j` (components beyond `D` zero).
    g: [[f64; 3]; N],
    /// Interpolated reference position.
    x: [f64; 3],
    /// Reference volume weight (quadrature weight x det J x volume factor).
    dv: f64,
}

/// The solid kernel for `N`-node cells of reference dimension `D`.
pub struct SolidKernel<const N: usize, const D: usize> {
    cell: CellType,
    kin: Kinematics,
    pressure: PressureSpace,
    /// Shape functions and reference gradients at the quadrature points.
    shape: Vec<ShapeEval<N, D>>,
    weights: Vec<f64>,
}

impl<const N: usize, const D: usize> SolidKernel<N, D> {
    /// A kernel for `cell` with shape functions `shape` (full integration).
    pub fn new(
        cell: CellType,
        shape: fn(&[f64; 3]) -> ShapeEval<N, D>,
        kin: Kinematics,
        pressure: PressureSpace,
    ) -> Result<Self, FeError> {
        if cell.nodes() != N || cell.dim() != D || kin.dim() != D {
            return Err(FeError::InvalidConfig {
                field: "element".into(),
                reason: format!("{cell:?} does not fit a {N}-node, {D}D kernel in {kin:?}"),
            });
        }
        let rule = QuadratureRule::for_cell(cell);
        Ok(SolidKernel {
            cell,
            kin,
            pressure,
            shape: rule.points.iter().map(shape).collect(),
            weights: rule.weights,
        })
    }

    fn geometry(
        &self,
        x: &[[f64; 3]],
        (n, dns): &ShapeEval<N, D>,
        w: f64,
    ) -> Result<PointGeometry<N>, f64> {
        let mut jac = [[0.0; D]; D]; // jac[i][k] = dX_i / dxi_k
        let mut xp = [0.0; 3];
        for a in 0..N {
            for i in 0..D {
                xp[i] += n[a] * x[a][i];
                for k in 0..D {
                    jac[i][k] += x[a][i] * dns[a][k];
                }
            }
        }
        let mut g = [[0.0; 3]; N];
        let det;
        if D == 2 {
            det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
            if !(det > 0.0) {
                return Err(det);
            }
            // dN/dX = dN/dxi * (dxi/dX); closed-form 2x2 inverse of the Jacobian.
            let inv = [
                [jac[1][1] / det, -jac[0][1] / det],
                [-jac[1][0] / det, jac[0][0] / det],
            ];
            for a in 0..N {
                for j in 0..2 {
                    g[a][j] = dns[a][0] * inv[0][j] + dns[a][1] * inv[1][j];
                }
            }
        } else {
            let m = Matrix3::from_fn(|i, k| jac[i][k]);
            det = m.determinant();
            if !(det > 0.0) {
                return Err(det);
            }
            let Some(inv) = m.try_inverse() else {
                return Err(det);
            };
            for a in 0..N {
                for j in 0..3 {
                    g[a][j] = (0..3).map(|k| dns[a][k] * inv[(k, j)]).sum();
                }
            }
        }
        Ok(PointGeometry {
            n: *n,
            g,
            x: xp,
            dv: self.kin.volume_factor(xp[0]) * det * w,
        })
    }

    /// [`ElementKernel::evaluate`] with caller-owned scratch.
    fn evaluate_with(
        &self,
        input: &ElementInput,
        tangent: bool,
        out: &mut ElementOutput,
        scratch: &mut Scratch,
    ) -> Result<(), FeError> {
        let e = input.element;
        let nu = N * D;
        let np = self.pressure.len(D);
        let exact = matches!(input.volumetric, Volumetric::Incompressible) && np > 0;
        let nloc = nu + if exact { np } else { 0 };
        out.reset(nloc, tangent);
        let comps = self.kin.components();
        let (centre, h) = self.centre_and_size(input.x);
        // volume gradients G_m (per local dof) and the psi-weighted
        // B^T (d2J/dF2) B of each pressure mode
        scratch.reset(nu, if tangent { np } else { 0 });
        let hl = input.material.history_len();
        if input.history.len() != hl * self.weights.len() {
            return Err(FeError::InvalidConfig {
                field: format!("element {e}"),
                reason: format!(
                    "{} history values for {} points x {hl} per point",
                    input.history.len(),
                    self.weights.len()
                ),
            });
        }
        out.history.clear();
        out.history.resize(hl * self.weights.len(), 0.0);
        let Scratch { gv, d2v, points } = scratch;
        let (mut v, mut vref) = ([0.0; 4], [0.0; 4]);
        let mut mass = SMatrix::<f64, 4, 4>::identity();
        for m in 0..np {
            mass[(m, m)] = 0.0;
        }
        let (mut vol, mut vol_ref) = (0.0, 0.0);
        for (qp, (s, &w)) in self.shape.iter().zip(&self.weights).enumerate() {
            let p = self
                .geometry(input.x, s, w)
                .map_err(|det| FeError::InvalidMesh {
                    field: format!("element {e}"),
                    reason: format!(
                        "reference Jacobian {det:.3e} <= 0 (corners must be counter-clockwise)"
                    ),
                })?;
            let (mut f, cols) = self.gradient(&p, input.u);
            let det2 = f[(0, 0)] * f[(1, 1)] - f[(0, 1)] * f[(1, 0)];
            if D == 2 && !(det2 > 0.0) {
                return Err(FeError::InvertedElement {
                    element: e,
                    det_f: det2,
                });
            }
            let old = &input.history[qp * hl..(qp + 1) * hl];
            let point_material = AtPoint {
                material: input.material,
                old,
                dt: input.dt,
            };
            let Some((ps, amat)) =
                self.kin
                    .stress_tangent(&point_material, input.volumetric, &mut f, tangent)
            else {
                return Err(FeError::NonFiniteStress { element: e });
            };
            if hl > 0 {
                input.material.update_history(
                    &f,
                    input.dt,
                    old,
                    &mut out.history[qp * hl..(qp + 1) * hl],
                );
            }
            let (j, cof, hj) = jacobian_derivs_3d(&f);
            if !(j > 0.0) {
                return Err(FeError::InvertedElement {
                    element: e,
                    det_f: j,
                });
            }
            vol += j * p.dv;
            vol_ref += p.dv;
            let psi = self.pressure.eval(D, &p.x, &centre, h);
            points.push((psi, p.dv));
            for m in 0..np {
                v[m] += psi[m] * j * p.dv;
                vref[m] += psi[m] * p.dv;
                for n in 0..np {
                    mass[(m, n)] += psi[m] * psi[n] * p.dv;
                }
            }
            for a in 0..N {
                for c in 0..D {
                    let col = &cols[a][c];
                    let i = a * D + c;
                    out.residual[i] += dot(col, &ps) * p.dv;
                    if np > 0 {
                        let dj = dot(col, &cof) * p.dv;
                        for m in 0..np {
                            gv[i][m] += psi[m] * dj;
                        }
                    }
                }
            }
            if !tangent {
                continue;
            }
            // With the exact constraint the pressure is known (p = s q):
            // fold it into the material tangent, A + p(x) d2J/dF2, and do
            // one B product. The solid tangent is symmetric: the upper
            // triangle is computed and mirrored.
            let folded = exact.then(|| {
                let pg: f64 = (0..np).map(|m| psi[m] * input.scale * input.q[m]).sum();
                let mut at = amat;
                for &k in comps {
                    for &l in comps {
                        at[k][l] += pg * hj[k][l];
                    }
                }
                at
            });
            let at = folded.as_ref().unwrap_or(&amat);
            let split = split_of(np, exact);
            if !split && self.kin != Kinematics::Axisymmetric {
                // The common case (plane stress, plane strain, 3D; no
                // pressure split): every B column of dof (b, d) is
                // `dN_b/dX_l` at components `3 d + l`, so its product with
                // a row is a dense sum over `l` on the shape gradients
                // (the same sums as the general loop below, without its
                // indirect indices; ~30 % of R2's time was that loop)
                let dv = p.dv;
                for a in 0..N {
                    for c in 0..D {
                        let i = a * D + c;
                        let ta = row(&cols[a][c], at, comps);
                        let trow = &mut out.tangent[i * nloc..i * nloc + nu];
                        for (b, gb) in p.g.iter().enumerate().skip(a) {
                            let d0 = if b == a { c } else { 0 };
                            for d in d0..D {
                                let t = &ta[3 * d..3 * d + D];
                                let s: f64 = t.iter().zip(gb).map(|(x, g)| x * g).sum();
                                trow[b * D + d] += s * dv;
                            }
                        }
                    }
                }
                continue;
            }
            for a in 0..N {
                for c in 0..D {
                    let col = &cols[a][c];
                    let i = a * D + c;
                    let ta = row(col, at, comps);
                    let th = if split {
                        row(col, &hj, comps)
                    } else {
                        [0.0; 9]
                    };
                    for jx in i..nu {
                        let col2 = &cols[jx / D][jx % D];
                        out.tangent[i * nloc + jx] += dot(col2, &ta) * p.dv;
                        if split {
                            let hv = dot(col2, &th) * p.dv;
                            for m in 0..np {
                                d2v[(m * nu + i) * nu + jx] += psi[m] * hv;
                            }
                        }
                    }
                }
            }
        }
        if tangent {
            for i in 0..nu {
                for jx in i + 1..nu {
                    out.tangent[jx * nloc + i] = out.tangent[i * nloc + jx];
                    for m in 0..if split_of(np, exact) { np } else { 0 } {
                        d2v[(m * nu + jx) * nu + i] = d2v[(m * nu + i) * nu + jx];
                    }
                }
            }
        }
        out.volume = vol;
        out.ref_volume = vol_ref;
        if np == 0 {
            return Ok(());
        }
        // pressure coefficients p_m (and the penalty's Q)
        let mut pc = [0.0; 4];
        let mut penalty_q = None;
        match input.volumetric {
            Volumetric::Incompressible => {
                for m in 0..np {
                    pc[m] = input.scale * input.q[m];
                    out.residual[nu + m] = input.scale * (v[m] - vref[m]);
                }
            }
            Volumetric::D1(_) => {
                let chol = mass.cholesky().ok_or(FeError::InvertedElement {
                    element: e,
                    det_f: 0.0,
                })?;
                let theta = chol.solve(&SVector::<f64, 4>::from_fn(|m, _| v[m]));
                let mut rhs = SVector::<f64, 4>::zeros();
                let mut q = SMatrix::<f64, 4, 4>::zeros();
                for (psi, dv) in points.iter() {
                    let th: f64 = (0..np).map(|m| psi[m] * theta[m]).sum();
                    let (du, d2u) = (input.volumetric.du(th), input.volumetric.d2u(th));
                    for m in 0..np {
                        rhs[m] += du * psi[m] * dv;
                        for n in 0..np {
                            q[(m, n)] += d2u * psi[m] * psi[n] * dv;
                        }
                    }
                }
                let p = chol.solve(&rhs);
                for m in 0..np {
                    pc[m] = p[m];
                }
                if tangent {
                    // M^-1 Q M^-1
                    let mq = chol.solve(&q);
                    penalty_q = Some(chol.solve(&mq.transpose()));
                }
            }
        }
        out.pressure = pc[0];
        for i in 0..nu {
            for m in 0..np {
                out.residual[i] += pc[m] * gv[i][m];
            }
        }
        if !tangent {
            return Ok(());
        }
        if !exact {
            for i in 0..nu {
                for jx in 0..nu {
                    let mut s = 0.0;
                    for m in 0..np {
                        s += pc[m] * d2v[(m * nu + i) * nu + jx];
                    }
                    out.tangent[i * nloc + jx] += s;
                }
            }
        }
        if exact {
            for i in 0..nu {
                for m in 0..np {
                    let k = input.scale * gv[i][m];
                    out.tangent[i * nloc + nu + m] = k;
                    out.tangent[(nu + m) * nloc + i] = k;
                }
            }
        } else if let Some(q) = penalty_q {
            for i in 0..nu {
                for jx in 0..nu {
                    let mut s = 0.0;
                    for m in 0..np {
                        for n in 0..np {
                            s += gv[i][m] * q[(m, n)] * gv[jx][n];
                        }
                    }
                    out.tangent[i * nloc + jx] += s;
                }
            }
        }
        Ok(())
    }

    /// Centroid of the corner nodes and the cell size `h` (square root of
    /// the corner polygon's area in 2D, cube root of the volume in 3D).
    fn centre_and_size(&self, x: &[[f64; 3]]) -> ([f64; 3], f64) {
        let corners = match self.cell {
            CellType::Hex8 | CellType::Hex27 => 8,
            _ => 4,
        };
        let mut c = [0.0; 3];
        for p in &x[..corners] {
            for i in 0..3 {
                c[i] += p[i] / corners as f64;
            }
        }
        (c, cell_size(self.cell, x))
    }

    /// Deformation gradient and the B columns at a point.
    fn gradient(&self, p: &PointGeometry<N>, u: &[[f64; 3]]) -> (Matrix3<f64>, [[BColumn; 3]; N]) {
        let mut f = Matrix3::identity();
        let mut ur = 0.0;
        for a in 0..N {
            ur += p.n[a] * u[a][0];
            for i in 0..D {
                for j in 0..D {
                    f[(i, j)] += u[a][i] * p.g[a][j];
                }
            }
        }
        let hoop = self.kin == Kinematics::Axisymmetric;
        let mut df22 = 0.0;
        if D == 2 {
            let (f22, d) = self.kin.out_of_plane(p.x[0], ur);
            f[(2, 2)] = f22;
            df22 = d;
        }
        let mut cols = [[BColumn::default(); 3]; N];
        for a in 0..N {
            for c in 0..D {
                let col = &mut cols[a][c];
                for j in 0..D {
                    col.k[j] = 3 * c + j;
                    col.v[j] = p.g[a][j];
                }
                col.len = D;
                if hoop && c == 0 {
                    col.k[D] = 8;
                    col.v[D] = p.n[a] * df22;
                    col.len = D + 1;
                }
            }
        }
        (f, cols)
    }
}

/// Cell size used to scale multipliers and P1 functions: the square root
/// of the area of the corner polygon (2D) or the cube root of the volume of
/// the corner hexahedron, by the divergence theorem on its faces (3D).
pub fn cell_size(cell: CellType, x: &[[f64; 3]]) -> f64 {
    match cell {
        CellType::Hex8 | CellType::Hex27 => {
            // volume of the trilinear hexahedron = sum of 6 tetrahedra on the diagonal 0-6
            let tet = |a: usize, b: usize| {
                let d = |p: usize| [x[p][0] - x[0][0], x[p][1] - x[0][1], x[p][2] - x[0][2]];
                let (u, v, w) = (d(a), d(b), d(6));
                (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                    + u[2] * (v[0] * w[1] - v[1] * w[0]))
                    / 6.0
            };
            let v = tet(1, 2) + tet(2, 3) + tet(3, 7) + tet(7, 4) + tet(4, 5) + tet(5, 1);
            v.abs().cbrt()
        }
        _ => {
            let area2: f64 = (0..4)
                .map(|k| x[k][0] * x[(k + 1) % 4][1] - x[(k + 1) % 4][0] * x[k][1])
                .sum();
            (0.5 * area2).abs().sqrt()
        }
    }
}

/// Whether the pressure term is kept apart per mode (penalty) rather than
/// folded into the material tangent (exact constraint).
#[inline]
fn split_of(np: usize, exact: bool) -> bool {
    np > 0 && !exact
}

/// `t = sum_e v_e X[k_e][.]` over the active components.
#[inline]
fn row(col: &BColumn, x: &[[f64; 9]; 9], comps: &[usize]) -> [f64; 9] {
    let mut t = [0.0; 9];
    for e in 0..col.len {
        let (k, v) = (col.k[e], col.v[e]);
        for &l in comps {
            t[l] += v * x[k][l];
        }
    }
    t
}

#[inline]
fn dot(col: &BColumn, t: &[f64; 9]) -> f64 {
    let mut s = 0.0;
    for e in 0..col.len {
        s += t[col.k[e]] * col.v[e];
    }
    s
}

impl<const N: usize, const D: usize> ElementKernel for SolidKernel<N, D> {
    fn cell_type(&self) -> CellType {
        self.cell
    }

    fn kinematics(&self) -> Kinematics {
        self.kin
    }

    fn element_unknowns(&self, volumetric: Volumetric) -> usize {
        match volumetric {
            Volumetric::Incompressible => self.pressure.len(D),
            Volumetric::D1(_) => 0,
        }
    }

    fn quadrature_points(&self) -> usize {
        self.weights.len()
    }

    fn reference_volume(&self, x: &[[f64; 3]]) -> Result<f64, FeError> {
        let mut v = 0.0;
        for (s, &w) in self.shape.iter().zip(&self.weights) {
            v += self
                .geometry(x, s, w)
                .map_err(|det| FeError::InvalidMesh {
                    field: "element".into(),
                    reason: format!("reference Jacobian {det:.3e} <= 0"),
                })?
                .dv;
        }
        Ok(v)
    }

    fn evaluate(
        &self,
        input: &ElementInput,
        tangent: bool,
        out: &mut ElementOutput,
    ) -> Result<(), FeError> {
        // scratch kept in the output buffer between calls (no allocation
        // on the assembly's hot path once every cell has been seen)
        let mut scratch = std::mem::take(&mut out.scratch);
        let r = self.evaluate_with(input, tangent, out, &mut scratch);
        out.scratch = scratch;
        r
    }

    fn mean_cauchy_stress(&self, input: &ElementInput, pressure: f64) -> [f64; 6] {
        let mut s = [0.0; 6];
        let mut vsum = 0.0;
        let hl = input.material.history_len();
        for (qp, (sh, &w)) in self.shape.iter().zip(&self.weights).enumerate() {
            let Ok(p) = self.geometry(input.x, sh, w) else {
                continue;
            };
            let material = AtPoint {
                material: input.material,
                old: input.history.get(qp * hl..(qp + 1) * hl).unwrap_or(&[]),
                dt: input.dt,
            };
            let (mut f, _) = self.gradient(&p, input.u);
            let Some((_, _)) = self
                .kin
                .stress_tangent(&material, input.volumetric, &mut f, false)
            else {
                continue;
            };
            let j = f.determinant();
            let sig = match self.kin {
                Kinematics::PlaneStress { .. } => {
                    let (pt, _) =
                        crate::kinematics::total_stress_tangent(&material, input.volumetric, &f);
                    let pm = Matrix3::from_fn(|i, k| pt[3 * i + k]);
                    let sig = pm * f.transpose() / j;
                    // incompressible: the pressure that makes sigma_33 = 0
                    if matches!(input.volumetric, Volumetric::Incompressible) {
                        sig - Matrix3::identity() * sig[(2, 2)]
                    } else {
                        sig
                    }
                }
                _ => {
                    let (p_iso, _) = material.iso_stress_tangent(&f);
                    p_iso * f.transpose() / j + Matrix3::identity() * pressure
                }
            };
            for (k, (i, jj)) in [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)]
                .into_iter()
                .enumerate()
            {
                s[k] += sig[(i, jj)] * p.dv;
            }
            vsum += p.dv;
        }
        s.map(|v| v / vsum)
    }
}

#[cfg(test)]
#[path = "solid_tests.rs"]
mod tests;
