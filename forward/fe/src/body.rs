//! A solid body: the cells of some mesh regions, one element kernel, and a
//! material per region (so a stiff inclusion is a region with another
//! material, not code).

use std::sync::Arc;

use palpate_material::Volumetric;
use rayon::prelude::*;

use crate::contribution::{Assembly, AssemblyContext, Contribution};
use crate::kernel::{solid::cell_size, ElementInput, ElementKernel, ElementOutput};
use crate::material::PointMaterial;
use crate::mesh::jacobian::corner_jacobians;
use crate::mesh::Mesh;
use crate::FeError;

/// A material with its volumetric treatment, shared between threads.
#[derive(Clone)]
pub struct RegionMaterial {
    pub material: Arc<dyn PointMaterial>,
    pub volumetric: Volumetric,
}

/// The cells of the named regions of a mesh with one kernel.
pub struct SolidBody {
    name: String,
    kernel: Box<dyn ElementKernel>,
    regions: Vec<String>,
    /// Mesh cell index, node list and reference coordinates of each cell.
    cells: Vec<usize>,
    nodes: Vec<Vec<usize>>,
    x: Vec<Vec<[f64; 3]>>,
    /// Region (index into `regions`) of each cell.
    region_of: Vec<usize>,
    size: Vec<f64>,
    /// Materials per region, set before a run.
    materials: Vec<Option<RegionMaterial>>,
    /// Whether the body owns pressure multipliers (exact incompressibility).
    exact: bool,
    unknowns_per_cell: usize,
    first: usize,
    outs: Vec<ElementOutput>,
    u_local: Vec<Vec<[f64; 3]>>,
    /// Committed material history per cell (the trial history of the last
    /// assembly is in `outs[k].history`).
    history: Vec<Vec<f64>>,
}

impl SolidBody {
    /// The body made of the cells of `regions` (a cell in two listed
    /// regions takes the material of the first). `exact` makes the pressure
    /// a Lagrange multiplier per cell (the laws must then be incompressible);
    /// otherwise a penalty `D1` is condensed in the element.
    ///
    /// Errors name what is wrong: a mesh that fails [`Mesh::validate`] (a
    /// missing node), an unknown region, a kernel for another cell type, or
    /// an inverted cell (a corner Jacobian determinant `<= 0` in 2D, `< 0`
    /// in 3D, or a non-positive reference volume), never a panic.
    pub fn new(
        name: &str,
        mesh: &Mesh,
        regions: &[&str],
        kernel: Box<dyn ElementKernel>,
        exact: bool,
    ) -> Result<SolidBody, FeError> {
        if kernel.cell_type() != mesh.cell_type {
            return Err(FeError::InvalidConfig {
                field: format!("body `{name}`"),
                reason: format!(
                    "kernel for {:?} cells on a mesh of {:?}",
                    kernel.cell_type(),
                    mesh.cell_type
                ),
            });
        }
        mesh.validate()?;
        let mut region_of = vec![usize::MAX; mesh.cell_count()];
        for (r, region) in regions.iter().enumerate() {
            for &c in mesh.region(region)? {
                if region_of[c] == usize::MAX {
                    region_of[c] = r;
                }
            }
        }
        let cells: Vec<usize> = (0..mesh.cell_count())
            .filter(|&c| region_of[c] != usize::MAX)
            .collect();
        let nodes: Vec<Vec<usize>> = cells.iter().map(|&c| mesh.cell(c).to_vec()).collect();
        let x: Vec<Vec<[f64; 3]>> = nodes
            .iter()
            .map(|ns| ns.iter().map(|&n| mesh.nodes[n]).collect())
            .collect();
        for (k, xs) in x.iter().enumerate() {
            // The corner test catches what the quadrature points can miss
            // (a quadratic cell folded at a corner by a misplaced mid-node);
            // the same rule as the Gmsh reader's.
            let jac = corner_jacobians(mesh.cell_type, xs);
            let bad = jac.iter().position(|&j| {
                if mesh.dim == 2 {
                    !(j > 0.0)
                } else {
                    !(j >= 0.0)
                }
            });
            if let Some(c) = bad {
                return Err(FeError::InvalidMesh {
                    field: format!("cell {}", cells[k]),
                    reason: format!(
                        "inverted: Jacobian determinant {:.3e} at corner {c} ({})",
                        jac[c],
                        if mesh.dim == 2 {
                            "corners must turn counter-clockwise"
                        } else {
                            "the bottom face 0-1-2-3 must turn counter-clockwise seen from the top face"
                        }
                    ),
                });
            }
            let v = kernel
                .reference_volume(xs)
                .map_err(|e| FeError::InvalidMesh {
                    field: format!("cell {}", cells[k]),
                    reason: match e {
                        FeError::InvalidMesh { reason, .. } => format!("inverted: {reason}"),
                        other => other.to_string(),
                    },
                })?;
            if !(v > 0.0) {
                return Err(FeError::InvalidMesh {
                    field: format!("cell {}", cells[k]),
                    reason: format!("reference volume {v:.3e} <= 0"),
                });
            }
        }
        let size = x.iter().map(|xs| cell_size(mesh.cell_type, xs)).collect();
        let unknowns_per_cell = if exact {
            kernel.element_unknowns(Volumetric::Incompressible)
        } else {
            0
        };
        let n = cells.len();
        let np = mesh.cell_type.nodes();
        Ok(SolidBody {
            name: name.into(),
            kernel,
            regions: regions.iter().map(|s| s.to_string()).collect(),
            region_of: cells.iter().map(|&c| region_of[c]).collect(),
            cells,
            nodes,
            x,
            size,
            materials: vec![None; regions.len()],
            exact,
            unknowns_per_cell,
            first: 0,
            outs: vec![ElementOutput::default(); n],
            u_local: vec![vec![[0.0; 3]; np]; n],
            history: vec![Vec::new(); n],
        })
    }

    /// Sets the material of region `region`. Its volumetric treatment must
    /// match the body's (`Incompressible` exactly when the body is exact).
    pub fn set_material(&mut self, region: &str, material: RegionMaterial) -> Result<(), FeError> {
        let Some(r) = self.regions.iter().position(|s| s == region) else {
            return Err(FeError::InvalidConfig {
                field: format!("material of region `{region}`"),
                reason: format!(
                    "body `{}` has no such region (have: {})",
                    self.name,
                    self.regions.join(", ")
                ),
            });
        };
        let wants_exact = matches!(material.volumetric, Volumetric::Incompressible);
        if wants_exact != self.exact && self.kernel.kinematics().needs_pressure() {
            return Err(FeError::InvalidConfig {
                field: "volumetric".into(),
                reason: format!(
                    "body `{}` was built for {} incompressibility, region `{region}` given {:?}",
                    self.name,
                    if self.exact { "exact" } else { "penalty" },
                    material.volumetric
                ),
            });
        }
        self.materials[r] = Some(material);
        // a new material starts from zero history
        self.reset(&[]);
        Ok(())
    }

    /// The kernel.
    pub fn kernel(&self) -> &dyn ElementKernel {
        &*self.kernel
    }

    /// Mesh cell indices of the body.
    pub fn cells(&self) -> &[usize] {
        &self.cells
    }

    /// Cell pressures (mean stress at the centre, MPa, tension positive) of the last assembly.
    pub fn pressures(&self) -> Vec<f64> {
        self.outs.iter().map(|o| o.pressure).collect()
    }

    /// Volume-average Cauchy stress of every cell at state `u` (see
    /// [`ElementKernel::mean_cauchy_stress`]).
    pub fn mean_cauchy_stresses(&self, u: &[f64], dim: usize) -> Vec<[f64; 6]> {
        (0..self.cells.len())
            .map(|k| {
                let ul: Vec<[f64; 3]> = self.nodes[k]
                    .iter()
                    .map(|&n| std::array::from_fn(|c| if c < dim { u[n * dim + c] } else { 0.0 }))
                    .collect();
                let Some(m) = &self.materials[self.region_of[k]] else {
                    return [f64::NAN; 6];
                };
                let input = ElementInput {
                    element: self.cells[k],
                    x: &self.x[k],
                    u: &ul,
                    q: &[],
                    material: &*m.material,
                    volumetric: m.volumetric,
                    scale: 0.0,
                    history: &self.history[k],
                    dt: 0.0,
                };
                self.kernel
                    .mean_cauchy_stress(&input, self.outs[k].pressure)
            })
            .collect()
    }

    fn owned(&self, k: usize) -> std::ops::Range<usize> {
        let s = self.first + k * self.unknowns_per_cell;
        s..s + self.unknowns_per_cell
    }
}

impl Contribution for SolidBody {
    fn name(&self) -> String {
        format!("body `{}`", self.name)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }

    fn unknowns(&self) -> usize {
        self.cells.len() * self.unknowns_per_cell
    }

    fn bind(&mut self, first: usize) {
        self.first = first;
    }

    fn couplings(&self, dim: usize) -> Vec<Vec<usize>> {
        (0..self.cells.len())
            .map(|k| {
                let mut v: Vec<usize> = self.nodes[k]
                    .iter()
                    .flat_map(|&n| (0..dim).map(move |c| n * dim + c))
                    .collect();
                v.extend(self.owned(k));
                v
            })
            .collect()
    }

    fn assemble(&mut self, ctx: &AssemblyContext, out: &mut Assembly) -> Result<(), FeError> {
        let dim = ctx.dofs.dim;
        let tangent = out.values.is_some();
        if let Some(r) = self.materials.iter().position(|m| m.is_none()) {
            return Err(FeError::InvalidConfig {
                field: format!("material of region `{}`", self.regions[r]),
                reason: "not set".into(),
            });
        }
        for (k, ns) in self.nodes.iter().enumerate() {
            for (a, &n) in ns.iter().enumerate() {
                self.u_local[k][a] = ctx.displacement(n);
            }
        }
        {
            let (kernel, xs, us, mats, region_of, size) = (
                &self.kernel,
                &self.x,
                &self.u_local,
                &self.materials,
                &self.region_of,
                &self.size,
            );
            let (cells, first, npc) = (&self.cells, self.first, self.unknowns_per_cell);
            let history = &self.history;
            // Cells in parallel into their own buffers; the reduction below
            // is serial in cell order, so results do not depend on the
            // thread count.
            self.outs
                .par_iter_mut()
                .enumerate()
                .try_for_each(|(k, o)| {
                    let m = mats[region_of[k]].as_ref().expect("checked above");
                    let s = first + k * npc;
                    let input = ElementInput {
                        element: cells[k],
                        x: &xs[k],
                        u: &us[k],
                        q: &ctx.u[s..s + npc],
                        material: &*m.material,
                        volumetric: m.volumetric,
                        scale: m.material.shear_modulus() / size[k],
                        history: &history[k],
                        dt: ctx.dt,
                    };
                    kernel.evaluate(&input, tangent, o)
                })?;
        }
        for (k, o) in self.outs.iter().enumerate() {
            for (a, &n) in self.nodes[k].iter().enumerate() {
                for c in 0..dim {
                    out.fint[n * dim + c] += o.residual[a * dim + c];
                }
            }
            let nu = self.nodes[k].len() * dim;
            for (m, s) in self.owned(k).enumerate() {
                out.fint[s] += o.residual[nu + m];
            }
            if tangent {
                out.add_group(k, &o.tangent);
            }
        }
        Ok(())
    }

    /// The trial history of the last assembly (at the converged state)
    /// becomes the committed history.
    fn commit(&mut self, _ctx: &AssemblyContext) {
        for (h, o) in self.history.iter_mut().zip(&self.outs) {
            h.clone_from(&o.history);
        }
    }

    /// Nothing to restore: every assembly recomputes the trial history
    /// from the committed one.
    fn rollback(&mut self) {}

    fn history(&self) -> Vec<f64> {
        self.history.concat()
    }

    fn set_history(&mut self, h: &[f64]) {
        let mut at = 0;
        for v in self.history.iter_mut() {
            let n = v.len();
            v.copy_from_slice(&h[at..at + n]);
            at += n;
        }
    }

    /// Zero history for the materials set now.
    fn reset(&mut self, _x0: &[[f64; 3]]) {
        let nq = self.kernel.quadrature_points();
        for (k, h) in self.history.iter_mut().enumerate() {
            let hl = self.materials[self.region_of[k]]
                .as_ref()
                .map_or(0, |m| m.material.history_len());
            h.clear();
            h.resize(nq * hl, 0.0);
        }
    }
}
