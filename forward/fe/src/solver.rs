//! The nonlinear quasi-static solver: assembly of element and contact
//! contributions into one residual and tangent, Newton-Raphson with a
//! backtracking line search, and automatic load increments that cut back on
//! failure and grow on easy convergence. A failed increment restores the last
//! converged state (displacements, multipliers and contact history).

use palpate_material::Volumetric;
use rayon::prelude::*;

use crate::contact::{ContactSet, NodeContact};
use crate::element::{quad4, reference_volume, ElementOutput, VolumeConstraint};
use crate::kinematics::Kinematics;
use crate::material::PointMaterial;
use crate::mesh2d::Mesh;
use crate::sparse::{Pattern, SparseLu, NONE};
use crate::FeError;

/// Displacement boundary conditions: fixed components and components driven
/// as `u = scale * drive`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Constraints {
    /// (node, component) held at zero.
    pub fixed: Vec<(usize, usize)>,
    /// (node, component, scale): `u = scale * drive`.
    pub driven: Vec<(usize, usize, f64)>,
}

/// How incompressibility is enforced (chosen when the solver is built,
/// because it decides the unknowns).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Incompressibility {
    /// Mean-dilatation penalty with the law's `D1` (finite bulk modulus).
    Penalty,
    /// Exact constraint with one Lagrange multiplier per element.
    Exact,
}

/// Newton and stepping controls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Largest drive increment (mm).
    pub max_step: f64,
    /// First drive increment (mm).
    pub first_step: f64,
    /// Halvings of the increment allowed at one sample before giving up.
    pub max_cuts: usize,
    /// Newton iterations per attempt.
    pub max_iterations: usize,
    /// Relative residual tolerance.
    pub tolerance: f64,
    /// Augmentations of the contact multipliers per increment.
    pub max_augmentations: usize,
    /// Relative residual accepted when Newton stagnates at the iteration
    /// limit (contact kinks can stall quadratic convergence); such
    /// increments are counted in [`RunStats::loose`].
    pub stagnation_tolerance: f64,
    /// Modified Newton: after an iteration that cut the residual tenfold,
    /// try the next step with the same factorisation and keep it when it
    /// cuts the residual fourfold (otherwise refactorise).
    pub reuse_factorisation: bool,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            max_step: 0.25,
            first_step: 0.05,
            max_cuts: 12,
            max_iterations: 25,
            tolerance: 1e-9,
            max_augmentations: 20,
            stagnation_tolerance: 1e-4,
            reuse_factorisation: true,
        }
    }
}

/// Reported after every sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    pub sample: usize,
    pub samples: usize,
    pub drive: f64,
    pub force: f64,
    pub increments: usize,
    pub iterations: usize,
}

/// Counters of one run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunStats {
    pub increments: usize,
    pub iterations: usize,
    pub cuts: usize,
    pub augmentations: usize,
    pub factorisations: usize,
    /// Newton iterations that reused an earlier factorisation (chord steps).
    pub chord_steps: usize,
    /// Increments accepted at the stagnation tolerance.
    pub loose: usize,
    /// Wall time in assembly and in factorise-and-solve (s).
    pub assembly_seconds: f64,
    pub solve_seconds: f64,
}

/// A failed run: where it stopped, and the forces of the samples that did converge.
#[derive(Debug, Clone, PartialEq)]
pub struct RunFailure {
    pub sample: usize,
    pub drive: f64,
    pub cuts: usize,
    pub error: FeError,
    pub completed: Vec<f64>,
}

struct Assembled {
    norm: f64,
    scale: f64,
    reaction: f64,
}

/// Solver for one mesh, boundary conditions and (optional) rigid tool. It
/// keeps the pattern, the symbolic factorisation and all scratch between runs.
pub struct Solver {
    pub mesh: Mesh,
    pub kinematics: Kinematics,
    pub incompressibility: Incompressibility,
    pub contact: Option<ContactSet>,
    constraints: Constraints,
    /// Equation number of dof `2 n + c`, or [`NONE`].
    eq: Vec<usize>,
    n_eq: usize,
    element_eqs: Vec<Vec<usize>>,
    element_x: Vec<[[f64; 2]; 4]>,
    element_h: Vec<f64>,
    pattern: Pattern,
    lu: SparseLu,
    length_scale: f64,
    h_min: f64,
    /// Current displacements (mm) and element multipliers.
    pub u: Vec<[f64; 2]>,
    pub q: Vec<f64>,
    outs: Vec<ElementOutput>,
    values: Vec<f64>,
    fint: Vec<f64>,
    residual: Vec<f64>,
    contacts: Vec<NodeContact>,
    x: Vec<[f64; 2]>,
    pub stats: RunStats,
}

impl Solver {
    /// Builds the dof numbering, the sparsity pattern and the symbolic LU.
    pub fn new(
        mesh: Mesh,
        kinematics: Kinematics,
        constraints: Constraints,
        contact: Option<ContactSet>,
        incompressibility: Incompressibility,
    ) -> Result<Solver, FeError> {
        let nn = mesh.nodes.len();
        let mut eq = vec![0usize; 2 * nn];
        for (n, c) in constraints
            .fixed
            .iter()
            .copied()
            .chain(constraints.driven.iter().map(|&(n, c, _)| (n, c)))
        {
            if n >= nn || c > 1 {
                return Err(FeError::InvalidConfig {
                    field: "constraints".into(),
                    reason: format!("node {n} component {c} does not exist"),
                });
            }
            eq[2 * n + c] = NONE;
        }
        let mut n_u = 0;
        for e in eq.iter_mut() {
            if *e != NONE {
                *e = n_u;
                n_u += 1;
            }
        }
        let ne = mesh.elements.len();
        let exact = incompressibility == Incompressibility::Exact;
        let element_eqs: Vec<Vec<usize>> = mesh
            .elements
            .iter()
            .enumerate()
            .map(|(e, nodes)| {
                let mut v: Vec<usize> = nodes
                    .iter()
                    .flat_map(|&n| [eq[2 * n], eq[2 * n + 1]])
                    .collect();
                if exact {
                    v.push(n_u + e);
                }
                v
            })
            .collect();
        let n_eq = n_u + if exact { ne } else { 0 };
        let pattern = Pattern::new(n_eq, &element_eqs);
        let lu = SparseLu::new(&pattern)?;
        let element_x: Vec<[[f64; 2]; 4]> = mesh
            .elements
            .iter()
            .map(|el| el.map(|n| mesh.nodes[n]))
            .collect();
        for (e, x) in element_x.iter().enumerate() {
            let area2: f64 = (0..4)
                .map(|k| x[k][0] * x[(k + 1) % 4][1] - x[(k + 1) % 4][0] * x[k][1])
                .sum();
            if !(area2 > 0.0) || !(reference_volume(kinematics, x) > 0.0) {
                return Err(FeError::InvalidMesh {
                    field: format!("element {e}"),
                    reason: "zero or negative area (corners must be counter-clockwise)".into(),
                });
            }
        }
        let element_h = element_x
            .iter()
            .map(|x| {
                let area2: f64 = (0..4)
                    .map(|k| x[k][0] * x[(k + 1) % 4][1] - x[(k + 1) % 4][0] * x[k][1])
                    .sum();
                (0.5 * area2).sqrt()
            })
            .collect();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &mesh.nodes {
            for i in 0..2 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        let length_scale = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let h_min = mesh.min_edge();
        let nnz = pattern.nnz();
        Ok(Solver {
            kinematics,
            incompressibility,
            contact,
            constraints,
            eq,
            n_eq,
            element_eqs,
            element_x,
            element_h,
            pattern,
            lu,
            length_scale,
            h_min,
            u: vec![[0.0; 2]; nn],
            q: vec![0.0; ne],
            outs: vec![ElementOutput::default(); ne],
            values: vec![0.0; nnz],
            fint: vec![0.0; 2 * nn],
            residual: vec![0.0; n_eq],
            contacts: Vec::new(),
            x: mesh.nodes.clone(),
            mesh,
            stats: RunStats::default(),
        })
    }

    /// Number of unknowns of the global system.
    pub fn equations(&self) -> usize {
        self.n_eq
    }

    /// Element pressures (mean stress, MPa, tension positive) of the last assembly.
    pub fn pressures(&self) -> Vec<f64> {
        self.outs.iter().map(|o| o.pressure).collect()
    }

    fn constraint_for(&self, vol: Volumetric, mu: f64, e: usize) -> VolumeConstraint {
        match vol {
            Volumetric::D1(d1) => VolumeConstraint::Penalty { d1 },
            Volumetric::Incompressible => VolumeConstraint::Exact {
                scale: mu / self.element_h[e],
            },
        }
    }

    fn assemble(
        &mut self,
        mat: &dyn PointMaterial,
        vol: Volumetric,
        drive: f64,
        tangent: bool,
    ) -> Result<Assembled, FeError> {
        let t0 = std::time::Instant::now();
        let r = self.assemble_inner(mat, vol, drive, tangent);
        self.stats.assembly_seconds += t0.elapsed().as_secs_f64();
        r
    }

    fn assemble_inner(
        &mut self,
        mat: &dyn PointMaterial,
        vol: Volumetric,
        drive: f64,
        tangent: bool,
    ) -> Result<Assembled, FeError> {
        let mu = mat.shear_modulus();
        let kin = self.kinematics;
        let constraints: Vec<VolumeConstraint> = (0..self.outs.len())
            .map(|e| self.constraint_for(vol, mu, e))
            .collect();
        {
            let (u, q, xs, els) = (&self.u, &self.q, &self.element_x, &self.mesh.elements);
            // Elements in parallel into their own buffers; the reduction below is
            // serial in element order, so results do not depend on the thread count.
            self.outs
                .par_iter_mut()
                .enumerate()
                .try_for_each(|(e, out)| {
                    let ue = els[e].map(|n| u[n]);
                    quad4(kin, &xs[e], &ue, q[e], mat, constraints[e], tangent, e, out)
                })?;
        }
        self.fint.iter_mut().for_each(|v| *v = 0.0);
        self.residual.iter_mut().for_each(|v| *v = 0.0);
        if tangent {
            self.values.iter_mut().for_each(|v| *v = 0.0);
        }
        for (e, out) in self.outs.iter().enumerate() {
            let nodes = self.mesh.elements[e];
            for a in 0..4 {
                for c in 0..2 {
                    self.fint[2 * nodes[a] + c] += out.residual[2 * a + c];
                }
            }
            let eqs = &self.element_eqs[e];
            let nl = eqs.len();
            if nl == 9 {
                self.residual[eqs[8]] = out.residual[8];
            }
            if tangent {
                let slots = &self.pattern.slots[e];
                for i in 0..nl {
                    for j in 0..nl {
                        let s = slots[i * nl + j];
                        if s != NONE {
                            self.values[s] += out.tangent[i][j];
                        }
                    }
                }
            }
        }
        let mut scale2 = 0.0;
        let mut reaction = 0.0;
        for &(n, c, s) in &self.constraints.driven {
            reaction += self.fint[2 * n + c] * s;
        }
        for &(n, c) in &self.constraints.fixed {
            scale2 += self.fint[2 * n + c].powi(2);
        }
        for &(n, c, _) in &self.constraints.driven {
            scale2 += self.fint[2 * n + c].powi(2);
        }
        if let Some(cs) = self.contact.as_mut() {
            for (x, (x0, u)) in self.x.iter_mut().zip(self.mesh.nodes.iter().zip(&self.u)) {
                *x = [x0[0] + u[0], x0[1] + u[1]];
            }
            cs.evaluate(&self.x, drive, &mut self.contacts);
            reaction = ContactSet::reaction(&self.contacts, cs.tool.direction);
            for nc in &self.contacts {
                scale2 += nc.force[0].powi(2) + nc.force[1].powi(2);
                for (a, &na) in nc.nodes.iter().enumerate() {
                    let wa = nc.weights[a];
                    if wa == 0.0 {
                        continue;
                    }
                    for i in 0..2 {
                        self.fint[2 * na + i] -= wa * nc.force[i];
                    }
                    if !tangent {
                        continue;
                    }
                    // the two nodes of a contact point share an element, so
                    // their blocks are in the pattern
                    for (b, &nb) in nc.nodes.iter().enumerate() {
                        let wab = wa * nc.weights[b];
                        if wab == 0.0 {
                            continue;
                        }
                        for i in 0..2 {
                            for j in 0..2 {
                                let (ri, cj) = (self.eq[2 * na + i], self.eq[2 * nb + j]);
                                if ri != NONE && cj != NONE {
                                    if let Some(s) = self.pattern.slot(ri, cj) {
                                        self.values[s] -= wab * nc.stiffness[i][j];
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        for (dof, &r) in self.eq.iter().enumerate() {
            if r != NONE {
                self.residual[r] = self.fint[dof];
            }
        }
        let norm = self.residual.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !norm.is_finite() {
            return Err(FeError::NonFiniteStress {
                element: usize::MAX,
            });
        }
        let floor = 1e-6 * mu * self.h_min * self.h_min;
        Ok(Assembled {
            norm,
            scale: scale2.sqrt().max(floor),
            reaction,
        })
    }

    fn set_drive(&mut self, drive: f64) {
        for &(n, c, s) in &self.constraints.driven {
            self.u[n][c] = s * drive;
        }
        for &(n, c) in &self.constraints.fixed {
            self.u[n][c] = 0.0;
        }
    }

    fn apply(&mut self, du: &[f64], alpha: f64, u0: &[[f64; 2]], q0: &[f64]) {
        for (dof, &r) in self.eq.iter().enumerate() {
            if r != NONE {
                self.u[dof / 2][dof % 2] = u0[dof / 2][dof % 2] + alpha * du[r];
            }
        }
        let n_u = self.n_eq
            - if self.incompressibility == Incompressibility::Exact {
                self.q.len()
            } else {
                0
            };
        if self.incompressibility == Incompressibility::Exact {
            for (e, q) in self.q.iter_mut().enumerate() {
                *q = q0[e] + alpha * du[n_u + e];
            }
        }
    }

    /// Newton iterations at a fixed drive; returns the reaction.
    fn newton(
        &mut self,
        mat: &dyn PointMaterial,
        vol: Volumetric,
        drive: f64,
        opts: &SolverOptions,
    ) -> Result<f64, FeError> {
        self.set_drive(drive);
        let mut a = self.assemble(mat, vol, drive, true)?;
        let mut du = vec![0.0; self.n_eq];
        let mut chord = false;
        for it in 0..=opts.max_iterations {
            let small_step = it > 0
                && du.iter().fold(0.0f64, |m: f64, v: &f64| m.max(v.abs()))
                    < 1e-12 * self.length_scale;
            if a.norm <= opts.tolerance * a.scale || (small_step && a.norm <= 1e-6 * a.scale) {
                return Ok(a.reaction);
            }
            if it == opts.max_iterations {
                break;
            }
            self.stats.iterations += 1;
            let norm0 = a.norm;
            if chord {
                // Modified Newton: reuse the factors of an earlier tangent of
                // this increment while they still contract the residual fast.
                du.iter_mut().zip(&self.residual).for_each(|(d, r)| *d = -r);
                let t0 = std::time::Instant::now();
                let solved = self.lu.solve_factored(&mut du);
                self.stats.solve_seconds += t0.elapsed().as_secs_f64();
                solved?;
                let (u0, q0) = (self.u.clone(), self.q.clone());
                self.apply(&du, 1.0, &u0, &q0);
                // residual only: the tangent is needed only if the chord is rejected
                match self.assemble(mat, vol, drive, false) {
                    Ok(t) if t.norm <= 0.25 * norm0 => {
                        a = t;
                        self.stats.chord_steps += 1;
                        continue;
                    }
                    _ => {
                        self.u.clone_from(&u0);
                        self.q.clone_from(&q0);
                        a = self.assemble(mat, vol, drive, true)?;
                    }
                }
            }
            du.iter_mut().zip(&self.residual).for_each(|(d, r)| *d = -r);
            let values = std::mem::take(&mut self.values);
            let t0 = std::time::Instant::now();
            let solved = self.lu.solve(&values, &mut du);
            self.stats.solve_seconds += t0.elapsed().as_secs_f64();
            self.values = values;
            solved?;
            self.stats.factorisations += 1;
            let (u0, q0) = (self.u.clone(), self.q.clone());
            let mut alpha = 1.0;
            let mut last_err = None;
            let mut accepted = None;
            // Armijo backtracking by halves: alpha = 1, 1/2, ..., 1/16, where
            // the step is taken whatever the residual; 1/32 is tried only
            // when the assembly at 1/16 fails (an inverted element).
            for _ in 0..6 {
                self.apply(&du, alpha, &u0, &q0);
                match self.assemble(mat, vol, drive, true) {
                    Ok(t) if t.norm <= (1.0 - 1e-4 * alpha) * a.norm || alpha <= 1.0 / 16.0 => {
                        accepted = Some(t);
                        break;
                    }
                    Ok(t) => accepted = Some(t),
                    Err(e) => {
                        accepted = None;
                        last_err = Some(e);
                    }
                }
                alpha *= 0.5;
            }
            match accepted {
                Some(t) => {
                    chord = opts.reuse_factorisation && t.norm <= 0.1 * norm0;
                    a = t;
                }
                None => {
                    return Err(last_err.unwrap_or(FeError::NewtonFailed {
                        iterations: it,
                        residual: a.norm,
                        tolerance: opts.tolerance * a.scale,
                    }))
                }
            }
        }
        if a.norm <= opts.stagnation_tolerance * a.scale {
            self.stats.loose += 1;
            return Ok(a.reaction);
        }
        Err(FeError::NewtonFailed {
            iterations: opts.max_iterations,
            residual: a.norm,
            tolerance: opts.tolerance * a.scale,
        })
    }

    /// Newton plus contact augmentations at one drive value.
    fn solve_increment(
        &mut self,
        mat: &dyn PointMaterial,
        vol: Volumetric,
        drive: f64,
        opts: &SolverOptions,
    ) -> Result<f64, FeError> {
        let mut reaction = self.newton(mat, vol, drive, opts)?;
        for _ in 0..opts.max_augmentations {
            let Some(cs) = self.contact.as_mut() else {
                break;
            };
            if cs.max_penetration() <= cs.options.penetration_tol {
                break;
            }
            cs.augment();
            self.stats.augmentations += 1;
            reaction = self.newton(mat, vol, drive, opts)?;
        }
        Ok(reaction)
    }

    /// Runs the loading history `drives` from the undeformed state and
    /// returns the reaction force at each sample.
    pub fn run(
        &mut self,
        mat: &dyn PointMaterial,
        vol: Volumetric,
        drives: &[f64],
        opts: &SolverOptions,
        progress: Option<&dyn Fn(&Progress)>,
    ) -> Result<Vec<f64>, RunFailure> {
        let fail = |sample: usize, drive: f64, cuts: usize, error: FeError, completed: &[f64]| {
            RunFailure {
                sample,
                drive,
                cuts,
                error,
                completed: completed.to_vec(),
            }
        };
        let wants_exact = matches!(vol, Volumetric::Incompressible);
        if wants_exact != (self.incompressibility == Incompressibility::Exact) {
            let e = FeError::InvalidConfig {
                field: "volumetric".into(),
                reason: format!(
                    "solver built for {:?} incompressibility, law given {vol:?}",
                    self.incompressibility
                ),
            };
            return Err(fail(0, drives.first().copied().unwrap_or(0.0), 0, e, &[]));
        }
        self.stats = RunStats::default();
        self.u.iter_mut().for_each(|v| *v = [0.0; 2]);
        self.q.iter_mut().for_each(|v| *v = 0.0);
        if let Some(cs) = self.contact.as_mut() {
            cs.reset(&self.mesh);
        }
        let mut forces = Vec::with_capacity(drives.len());
        let mut d_c = 0.0;
        let mut step = opts.first_step.min(opts.max_step);
        let (mut u_c, mut q_c) = (self.u.clone(), self.q.clone());
        let mut last: Option<(f64, Vec<[f64; 2]>, Vec<f64>)> = None; // previous increment (size, du, dq)
        let mut reaction = match self.assemble(mat, vol, 0.0, false) {
            Ok(a) => a.reaction,
            Err(e) => return Err(fail(0, 0.0, 0, e, &[])),
        };
        for (k, &target) in drives.iter().enumerate() {
            let mut cuts = 0;
            while (target - d_c).abs() > 1e-12 * (1.0 + target.abs()) {
                let dir = (target - d_c).signum();
                let size = step.min((target - d_c).abs());
                let d_new = if size >= (target - d_c).abs() {
                    target
                } else {
                    d_c + dir * size
                };
                // predictor: extrapolate the previous increment
                if let Some((prev, du, dq)) = &last {
                    if prev.signum() == dir {
                        let f = size / prev.abs();
                        for (u, d) in self.u.iter_mut().zip(du) {
                            u[0] += f * d[0];
                            u[1] += f * d[1];
                        }
                        for (q, d) in self.q.iter_mut().zip(dq) {
                            *q += f * d;
                        }
                    }
                }
                let it0 = self.stats.iterations;
                match self.solve_increment(mat, vol, d_new, opts) {
                    Ok(r) => {
                        reaction = r;
                        if let Some(cs) = self.contact.as_mut() {
                            for (x, (x0, u)) in
                                self.x.iter_mut().zip(self.mesh.nodes.iter().zip(&self.u))
                            {
                                *x = [x0[0] + u[0], x0[1] + u[1]];
                            }
                            cs.commit(&self.x, d_new);
                        }
                        let du: Vec<[f64; 2]> = self
                            .u
                            .iter()
                            .zip(&u_c)
                            .map(|(a, b)| [a[0] - b[0], a[1] - b[1]])
                            .collect();
                        let dq: Vec<f64> = self.q.iter().zip(&q_c).map(|(a, b)| a - b).collect();
                        last = Some((d_new - d_c, du, dq));
                        u_c.clone_from(&self.u);
                        q_c.clone_from(&self.q);
                        d_c = d_new;
                        self.stats.increments += 1;
                        if self.stats.iterations - it0 <= 6 {
                            step = (step * 1.5).min(opts.max_step);
                        }
                    }
                    Err(e) if e.is_recoverable() && cuts < opts.max_cuts => {
                        cuts += 1;
                        self.stats.cuts += 1;
                        self.u.clone_from(&u_c);
                        self.q.clone_from(&q_c);
                        last = None;
                        step = size * 0.5;
                    }
                    Err(e) => return Err(fail(k, d_c, cuts, e, &forces)),
                }
            }
            forces.push(reaction);
            if let Some(cb) = progress {
                cb(&Progress {
                    sample: k,
                    samples: drives.len(),
                    drive: target,
                    force: reaction,
                    increments: self.stats.increments,
                    iterations: self.stats.iterations,
                });
            }
        }
        Ok(forces)
    }
}
