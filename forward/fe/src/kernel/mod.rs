//! Element kernels behind one trait: the residual (internal force) and
//! tangent of one cell from its reference coordinates, displacements and
//! element unknowns (pressure multipliers), for a given pointwise material.
//!
//! * [`pressure`] — the element pressure spaces (none, P0, discontinuous P1).
//! * [`solid`] — the one kernel pattern (`SolidKernel<N, D>`, fixed-size
//!   algebra over the node count) that serves the 4-node mixed quadrilateral
//!   (Q1/P0), the 9-node quadrilateral with a linear discontinuous pressure
//!   (Q2/P1), the 8-node mixed hexahedron (Q1/P0) and the plane-stress
//!   quadrilaterals without a pressure field, in every kinematics.
//!
//! Local degrees of freedom are ordered node by node (`a * dim + c` for
//! component `c` of node `a`), then the element's pressure unknowns.

pub mod pressure;
pub mod solid;

use palpate_material::Volumetric;

use crate::kinematics::Kinematics;
use crate::material::PointMaterial;
use crate::mesh::CellType;
use crate::FeError;

pub use pressure::PressureSpace;
pub use solid::SolidKernel;

/// What a kernel reads for one cell.
pub struct ElementInput<'a> {
    /// Index of the cell (for error messages).
    pub element: usize,
    /// Reference node coordinates (mm), `[x, y, z]`, one per node.
    pub x: &'a [[f64; 3]],
    /// Node displacements (mm), one per node (unused components zero).
    pub u: &'a [[f64; 3]],
    /// Element unknowns (pressure multipliers of the exact constraint).
    pub q: &'a [f64],
    /// The material at this cell's quadrature points.
    pub material: &'a dyn PointMaterial,
    /// How the law treats volume change: `Incompressible` makes the
    /// pressure a Lagrange multiplier, `D1` a condensed penalty.
    pub volumetric: Volumetric,
    /// Multiplier scale `s` (MPa per unit multiplier, typically `mu / h_e`)
    /// so that the constraint rows have the magnitude of the force rows.
    pub scale: f64,
    /// Committed material history, `material.history_len()` values per
    /// quadrature point in rule order (empty for elastic materials).
    pub history: &'a [f64],
    /// Time step of the increment (s; 0 for rate-independent histories).
    pub dt: f64,
}

/// Residual and tangent of one cell, local dof order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ElementOutput {
    pub residual: Vec<f64>,
    /// Row-major `n x n`, `n = residual.len()`.
    pub tangent: Vec<f64>,
    /// Current volume `v_e` (mm^3).
    pub volume: f64,
    /// Reference volume `V_e` (mm^3).
    pub ref_volume: f64,
    /// Pressure (mean stress, MPa, tension positive) at the cell centre.
    pub pressure: f64,
    /// Trial material history at the quadrature points (same layout as
    /// [`ElementInput::history`]).
    pub history: Vec<f64>,
    /// Work space of the kernel, kept between calls.
    pub(crate) scratch: Scratch,
}

/// Work space of a kernel evaluation: the volume gradients of the pressure
/// modes, their psi-weighted second derivatives, and the pressure functions
/// and weights at the quadrature points.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Scratch {
    pub gv: Vec<[f64; 4]>,
    pub d2v: Vec<f64>,
    pub points: Vec<([f64; 4], f64)>,
}

impl Scratch {
    /// Zeroed for `nu` displacement dofs and `np` pressure modes (second
    /// derivatives only when `np > 0`).
    pub fn reset(&mut self, nu: usize, np: usize) {
        self.gv.clear();
        self.gv.resize(nu, [0.0; 4]);
        self.d2v.clear();
        self.d2v.resize(np * nu * nu, 0.0);
        self.points.clear();
    }
}

impl ElementOutput {
    /// Zeroed buffers for `n` local dofs (the tangent only when asked).
    pub fn reset(&mut self, n: usize, tangent: bool) {
        self.residual.clear();
        self.residual.resize(n, 0.0);
        if tangent {
            self.tangent.clear();
            self.tangent.resize(n * n, 0.0);
        }
        self.volume = 0.0;
        self.ref_volume = 0.0;
        self.pressure = 0.0;
    }
}

/// An element formulation for one cell type in one kinematics.
pub trait ElementKernel: Send + Sync {
    /// The cell type it integrates.
    fn cell_type(&self) -> CellType;
    /// The kinematic idealisation.
    fn kinematics(&self) -> Kinematics;
    /// Displacement components per node.
    fn dim(&self) -> usize {
        self.kinematics().dim()
    }
    /// Element unknowns beyond the displacements for this volumetric
    /// treatment (pressure multipliers of the exact constraint; none for a
    /// penalty, which is condensed in the element).
    fn element_unknowns(&self, volumetric: Volumetric) -> usize;
    /// Residual and, when `tangent`, tangent of one cell into `out`.
    fn evaluate(
        &self,
        input: &ElementInput,
        tangent: bool,
        out: &mut ElementOutput,
    ) -> Result<(), FeError>;
    /// Number of quadrature points of a cell.
    fn quadrature_points(&self) -> usize;
    /// Reference volume of a cell (mm^3; per radian x 2 pi in axisymmetry).
    fn reference_volume(&self, x: &[[f64; 3]]) -> Result<f64, FeError>;
    /// Volume-average Cauchy stress of a cell (MPa, components xx, yy, zz,
    /// xy, yz, zx; in axisymmetry rr, zz, tt, rz, 0, 0) given its pressure.
    fn mean_cauchy_stress(&self, input: &ElementInput, pressure: f64) -> [f64; 6];
}

/// The kernel for a cell type, kinematics and pressure space, or an error
/// naming the combination that does not exist.
pub fn kernel_for(
    cell: CellType,
    kinematics: Kinematics,
    pressure: PressureSpace,
) -> Result<Box<dyn ElementKernel>, FeError> {
    let bad = |reason: String| FeError::InvalidConfig {
        field: "element".into(),
        reason,
    };
    kinematics.check().map_err(bad)?;
    if !kinematics.needs_pressure() && pressure != PressureSpace::None {
        return Err(bad(format!(
            "{kinematics:?} has no pressure field (the plane-stress condition removes it); got {pressure:?}"
        )));
    }
    if kinematics.needs_pressure() && pressure == PressureSpace::None {
        return Err(bad(format!(
            "{kinematics:?} needs a pressure field (P0 or P1) to be locking-free"
        )));
    }
    match (cell, kinematics) {
        (CellType::Quad4, k) if k.dim() == 2 => Ok(Box::new(SolidKernel::<4, 2>::new(
            cell,
            crate::shape::quad4,
            k,
            pressure,
        )?)),
        (CellType::Quad9, k) if k.dim() == 2 => Ok(Box::new(SolidKernel::<9, 2>::new(
            cell,
            crate::shape::quad9,
            k,
            pressure,
        )?)),
        (CellType::Hex8, Kinematics::ThreeD) => Ok(Box::new(SolidKernel::<8, 3>::new(
            cell,
            crate::shape::hex8,
            kinematics,
            pressure,
        )?)),
        (CellType::Hex27, Kinematics::ThreeD) => Ok(Box::new(SolidKernel::<27, 3>::new(
            cell,
            crate::shape::hex27,
            kinematics,
            pressure,
        )?)),
        _ => Err(bad(format!(
            "no element for {cell:?} cells in {kinematics:?} kinematics"
        ))),
    }
}
