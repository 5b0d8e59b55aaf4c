//! The global system of one step: the state, the numbering, the
//! contributions it sums, the sparse tangent with its symbolic
//! factorisation, and Newton-Raphson at fixed loading-channel values.
//! The increments (time stepping, cut-back) are [`crate::stepper`]'s.

use crate::contribution::{Assembly, AssemblyContext, Contribution};
use crate::dofs::{DofMap, DofValue};
use crate::line_search::{slope_search, LineSearch};
use crate::mesh::Mesh;
use crate::sparse::{Pattern, SparseLu, NONE};
use crate::FeError;

/// Newton and stepping controls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Largest increment of the path coordinate (mm of drive for
    /// displacement-driven histories).
    pub max_step: f64,
    /// First increment.
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
    /// The tangent is symmetric (hyperelastic bodies without owned
    /// pressure unknowns, frictionless contact): factorise it by sparse
    /// LDL^T (half the work of the LU), falling back to the LU on a zero
    /// pivot. Default `false`. A model must set it only when every
    /// contribution's tangent is symmetric: the upper triangle is not read.
    pub symmetric: bool,
    /// Solve each Newton system by GMRES preconditioned with the LDL^T
    /// factors of the tangent's symmetric part (owned pressures ordered
    /// after their displacements), falling back to the LU when a solve does
    /// not converge ([`crate::sparse::SparseLu::set_gmres`]). For 3D meshes
    /// with frictional contact (N3), whose LU fills many times more than the
    /// symmetric factorisation. Ignored when `symmetric` is set. Default
    /// `false`.
    pub gmres: bool,
    /// With `gmres`: solve a Newton system on the factors of an earlier
    /// tangent (kept across iterations and increments) when GMRES
    /// converges on them within this many iterations, and factorise only
    /// when it does not ([`crate::sparse::SparseLu::solve_reusing`]). The
    /// Newton steps are the same (to GMRES's tolerance); only the number of
    /// factorisations changes. 0 (default): factorise at every full Newton
    /// iteration.
    pub preconditioner_reuse: usize,
    /// For timed histories: the largest time increment (s). `None`: time
    /// does not limit increments (rate-independent materials: a hold at
    /// constant drive costs no increment, and `dt` still reaches the
    /// materials); `Some(dt)`: holds advance in increments of at most `dt`
    /// (rate-dependent materials).
    pub max_time_step: Option<f64>,
    /// The largest entry of a full Newton update (mm for displacements):
    /// a longer update is scaled down to it before the line search. A
    /// guard for contact whose active set jumps (a wheel moved sideways
    /// into the material, R2), where the first tangent can send the body
    /// millimetres through the tool. `None` (default): no limit.
    pub max_update: Option<f64>,
    /// How far along each full Newton update to step
    /// ([`crate::line_search`]). Default [`LineSearch::Residual`].
    pub line_search: LineSearch,
    /// Proximal stabilisation of an increment whose Newton fails: `beta >
    /// 0` solves instead a sequence of problems `R(u) + C (u - u_a) = 0`,
    /// `C = beta diag(K)` on the free displacements, each anchored at the
    /// last one's solution (proximal point iterations, Rockafellar 1976;
    /// the viscous stabilisation of Abaqus's `*STATIC, STABILIZE` with the
    /// viscous force driven to zero), trying plain Newton (8 iterations)
    /// after each; `C` is halved after a failed try and quadrupled from the
    /// same anchor when a proximal solve fails, for at most 40 steps. The
    /// accepted state is one plain Newton accepts (its tolerances, the
    /// stagnation one included), an equilibrium of `R` alone: the term only
    /// carries Newton across a local snap (a surface edge draped over a
    /// tool's rounded corner, Q1). 0 (default): off.
    pub stabilisation: f64,
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
            symmetric: false,
            gmres: false,
            preconditioner_reuse: 0,
            max_time_step: None,
            max_update: None,
            line_search: LineSearch::Residual,
            stabilisation: 0.0,
        }
    }
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
    /// Full Newton steps solved by GMRES on an earlier tangent's factors
    /// ([`SolverOptions::preconditioner_reuse`]), with no factorisation.
    pub reused_factors: usize,
    /// Increments accepted at the stagnation tolerance.
    pub loose: usize,
    /// Increments solved through proximal stabilisation
    /// ([`SolverOptions::stabilisation`]), and its proximal steps.
    pub stabilised: usize,
    pub proximal_steps: usize,
    /// Wall time in assembly and in factorise-and-solve (s).
    pub assembly_seconds: f64,
    pub solve_seconds: f64,
}

/// What one assembly measured.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Assembled {
    pub norm: f64,
    pub scale: f64,
}

/// The loading state an increment is solved at.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Target {
    pub channels: Vec<f64>,
    pub time: f64,
    pub dt: f64,
}

/// The contributions of a system being built, each added with a typed
/// handle that reaches it in the built [`System`] ([`System::from_parts`]):
/// a model keeps the handles instead of positions.
#[derive(Default)]
pub struct Parts {
    list: Vec<Box<dyn Contribution>>,
}

impl Parts {
    pub fn new() -> Self {
        Parts::default()
    }

    /// Adds `contribution` after those already added.
    pub fn add<T: Contribution + 'static>(&mut self, contribution: T) -> Part<T> {
        self.list.push(Box::new(contribution));
        Part {
            index: self.list.len() - 1,
            kind: std::marker::PhantomData,
        }
    }
}

/// A typed handle to a contribution of a [`System`] built from [`Parts`].
pub struct Part<T> {
    index: usize,
    kind: std::marker::PhantomData<fn() -> T>,
}

impl<T> Clone for Part<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Part<T> {}

impl<T> std::fmt::Debug for Part<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Part({}: {})", self.index, std::any::type_name::<T>())
    }
}

/// The global system.
pub struct System {
    pub mesh: Mesh,
    pub dofs: DofMap,
    pub contributions: Vec<Box<dyn Contribution>>,
    first_group: Vec<usize>,
    pattern: Pattern,
    lu: SparseLu,
    /// The state: node displacements (mm), then owned unknowns.
    pub u: Vec<f64>,
    fint: Vec<f64>,
    residual: Vec<f64>,
    values: Vec<f64>,
    /// Channel values and time at the last commit.
    pub(crate) committed: Target,
    length_scale: f64,
    /// Smallest force scale of the residual test (N), e.g. `1e-6 mu h^2`.
    pub force_floor: f64,
    pub stats: RunStats,
    /// A model's predictor of each increment's starting state
    /// ([`crate::predictor`]); `None` (default): the stepper's secant.
    pub predictor: Option<Box<dyn crate::predictor::Predictor>>,
    /// A test hook: every assembly fails once this many have passed, until
    /// it is cleared.
    #[doc(hidden)]
    pub fail_after: Option<usize>,
    /// The proximal term of a stabilised increment: per state entry the
    /// weight `c` (0 off the free displacements) and the anchor `u_a`.
    prox: Option<(Vec<f64>, Vec<f64>)>,
}

impl System {
    /// Binds the owned unknowns of `contributions` after the node
    /// displacements, numbers the equations from `bcs` (in `dofs`'s
    /// arguments), and builds the pattern and the symbolic LU. Every loading
    /// channel `0..channels` must be used by a condition or a contribution
    /// (an unused one is a mistake in the model, and its reaction would be
    /// silently zero); the error names the channel.
    pub fn new(
        mesh: Mesh,
        dim: usize,
        mut contributions: Vec<Box<dyn Contribution>>,
        bcs: &[crate::dofs::Dirichlet],
        channels: usize,
    ) -> Result<System, FeError> {
        mesh.validate()?;
        if dim != mesh.dim {
            return Err(FeError::InvalidConfig {
                field: "dim".into(),
                reason: format!("{dim} components per node on a {}D mesh", mesh.dim),
            });
        }
        let mut first = mesh.nodes.len() * dim;
        for c in contributions.iter_mut() {
            c.bind(first);
            first += c.unknowns();
        }
        let extra = first - mesh.nodes.len() * dim;
        let dofs = DofMap::new(&mesh, dim, extra, bcs, channels)?;
        let used: Vec<usize> = contributions.iter().flat_map(|c| c.channels()).collect();
        if let Some(c) = (0..channels).find(|&c| !dofs.uses_channel(c) && !used.contains(&c)) {
            return Err(FeError::InvalidConfig {
                field: "channels".into(),
                reason: format!(
                    "loading channel {c} is used by no boundary condition and no tool \
                     ({channels} channels)"
                ),
            });
        }
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut first_group = Vec::with_capacity(contributions.len());
        for c in &contributions {
            first_group.push(groups.len());
            groups.extend(
                c.couplings(dim)
                    .into_iter()
                    .map(|g| g.into_iter().map(|k| dofs.equation(k)).collect()),
            );
        }
        let pattern = Pattern::new(dofs.equations, &groups);
        let mut lu = SparseLu::new(&pattern)?;
        // node displacements are numbered first, owned unknowns after them
        lu.set_first_owned(dofs.equations - extra);
        let n = dofs.len();
        let length_scale = mesh.extent();
        let nnz = pattern.nnz();
        Ok(System {
            committed: Target {
                channels: vec![0.0; channels],
                time: 0.0,
                dt: 0.0,
            },
            u: vec![0.0; n],
            fint: vec![0.0; n],
            residual: vec![0.0; dofs.equations],
            values: vec![0.0; nnz],
            mesh,
            dofs,
            contributions,
            first_group,
            pattern,
            lu,
            length_scale,
            force_floor: 0.0,
            stats: RunStats::default(),
            predictor: None,
            fail_after: None,
            prox: None,
        })
    }

    /// [`System::new`] with the contributions of `parts`, whose handles
    /// ([`Part`]) reach them afterwards ([`System::get`], [`System::get_mut`]).
    pub fn from_parts(
        mesh: Mesh,
        dim: usize,
        parts: Parts,
        bcs: &[crate::dofs::Dirichlet],
        channels: usize,
    ) -> Result<System, FeError> {
        System::new(mesh, dim, parts.list, bcs, channels)
    }

    /// The contribution behind `part`, or an error naming what is there
    /// (a handle of another system).
    pub fn get_mut<T: Contribution + 'static>(&mut self, part: Part<T>) -> Result<&mut T, FeError> {
        self.part_mut(part.index)
    }

    /// The contribution behind `part`.
    pub fn get<T: Contribution + 'static>(&self, part: Part<T>) -> Option<&T> {
        self.part(part.index)
    }

    /// Contribution `index` as its concrete type, or an error naming it.
    pub fn part_mut<T: Contribution + 'static>(&mut self, index: usize) -> Result<&mut T, FeError> {
        let name = self
            .contributions
            .get(index)
            .map(|c| c.name())
            .unwrap_or_else(|| "nothing".into());
        self.contributions
            .get_mut(index)
            .and_then(|c| c.as_any_mut().downcast_mut::<T>())
            .ok_or_else(|| FeError::InvalidConfig {
                field: format!("contribution {index}"),
                reason: format!("is {name}, not a {}", std::any::type_name::<T>()),
            })
    }

    /// Contribution `index` as its concrete type.
    pub fn part<T: Contribution + 'static>(&self, index: usize) -> Option<&T> {
        self.contributions
            .get(index)
            .and_then(|c| c.as_any().downcast_ref::<T>())
    }

    /// The linear solver's counters: GMRES solves, their iterations and
    /// fallbacks to the LU, LDL^T fallbacks to the LU, and the stored
    /// entries of the LDL^T factor (when used).
    pub fn linear_solver_stats(&self) -> (usize, usize, usize, usize, Option<usize>) {
        (
            self.lu.gmres_solves,
            self.lu.gmres_iterations,
            self.lu.gmres_fallbacks,
            self.lu.ldlt_fallbacks,
            self.lu.ldlt_len(),
        )
    }

    /// Number of equations.
    pub fn equations(&self) -> usize {
        self.dofs.equations
    }

    /// Node displacements as `[f64; 3]` (unused components zero).
    pub fn displacements(&self) -> Vec<[f64; 3]> {
        let d = self.dofs.dim;
        (0..self.dofs.nodes)
            .map(|n| std::array::from_fn(|c| if c < d { self.u[n * d + c] } else { 0.0 }))
            .collect()
    }

    /// Internal forces of the last assembly (per state entry).
    pub fn internal_forces(&self) -> &[f64] {
        &self.fint
    }

    /// Reaction of the prescribed entries driven by `channel`:
    /// `sum scale * f_int` (N), from the last assembly.
    pub fn channel_reaction(&self, channel: usize) -> f64 {
        self.dofs
            .prescribed
            .iter()
            .filter_map(|&(k, v)| match v {
                DofValue::Channel { channel: c, scale } if c == channel => {
                    Some(self.fint[k] * scale)
                }
                _ => None,
            })
            .sum()
    }

    /// Starts a loading history afresh: zero state, fresh history.
    pub fn reset(&mut self) {
        self.u.iter_mut().for_each(|v| *v = 0.0);
        self.committed = Target {
            channels: vec![0.0; self.committed.channels.len()],
            time: 0.0,
            dt: 0.0,
        };
        for c in self.contributions.iter_mut() {
            c.reset(&self.mesh.nodes);
        }
        if let Some(p) = self.predictor.as_mut() {
            p.reset();
        }
        self.stats = RunStats::default();
    }

    /// Prescribed entries take their values for `target`.
    pub(crate) fn prescribe(&mut self, target: &Target) {
        for &(k, v) in &self.dofs.prescribed {
            self.u[k] = match v {
                DofValue::Fixed => 0.0,
                DofValue::Channel { channel, scale } => scale * target.channels[channel],
            };
        }
    }

    fn context<'a>(&'a self, target: &'a Target) -> AssemblyContext<'a> {
        AssemblyContext {
            u: &self.u,
            x0: &self.mesh.nodes,
            channels: &target.channels,
            channels_committed: &self.committed.channels,
            time: target.time,
            dt: target.dt,
            dofs: &self.dofs,
        }
    }

    /// Residual and (when `tangent`) tangent of every contribution at `target`.
    pub(crate) fn assemble(
        &mut self,
        target: &Target,
        tangent: bool,
    ) -> Result<Assembled, FeError> {
        let t0 = std::time::Instant::now();
        let r = self.assemble_inner(target, tangent);
        self.stats.assembly_seconds += t0.elapsed().as_secs_f64();
        r
    }

    fn assemble_inner(&mut self, target: &Target, tangent: bool) -> Result<Assembled, FeError> {
        if let Some(n) = self.fail_after.as_mut() {
            if *n == 0 {
                return Err(FeError::NonFiniteStress {
                    element: usize::MAX,
                });
            }
            *n -= 1;
        }
        self.fint.iter_mut().for_each(|v| *v = 0.0);
        if tangent {
            self.values.iter_mut().for_each(|v| *v = 0.0);
        }
        let mut force2 = 0.0;
        let mut contributions = std::mem::take(&mut self.contributions);
        let mut result = Ok(());
        let mut fint = std::mem::take(&mut self.fint);
        let mut values = std::mem::take(&mut self.values);
        {
            let ctx = self.context(target);
            for (c, first) in contributions.iter_mut().zip(&self.first_group) {
                let mut out = Assembly {
                    fint: &mut fint,
                    values: if tangent { Some(&mut values) } else { None },
                    pattern: &self.pattern,
                    first_group: *first,
                    dofs: &self.dofs,
                    force_scale2: 0.0,
                };
                if let Err(e) = c.assemble(&ctx, &mut out) {
                    result = Err(e);
                    break;
                }
                force2 += out.force_scale2;
            }
        }
        if let (Some((c, anchor)), Ok(())) = (&self.prox, &result) {
            let mut out = Assembly {
                fint: &mut fint,
                values: if tangent { Some(&mut values) } else { None },
                pattern: &self.pattern,
                first_group: 0,
                dofs: &self.dofs,
                force_scale2: 0.0,
            };
            for (k, &ck) in c.iter().enumerate() {
                if ck != 0.0 {
                    out.fint[k] += ck * (self.u[k] - anchor[k]);
                    out.add_entry(k, k, ck);
                }
            }
        }
        self.fint = fint;
        self.values = values;
        self.contributions = contributions;
        result?;
        let mut scale2 = force2;
        for &(k, _) in &self.dofs.prescribed {
            scale2 += self.fint[k].powi(2);
        }
        for (k, f) in self.fint.iter().enumerate() {
            let e = self.dofs.equation(k);
            if e != NONE {
                self.residual[e] = *f;
            }
        }
        let norm = self.residual.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !norm.is_finite() {
            return Err(FeError::NonFiniteStress {
                element: usize::MAX,
            });
        }
        Ok(Assembled {
            norm,
            scale: scale2.sqrt().max(self.force_floor),
        })
    }

    fn apply(&mut self, du: &[f64], alpha: f64, u0: &[f64]) {
        for (k, u) in self.u.iter_mut().enumerate() {
            let e = self.dofs.equation(k);
            if e != NONE {
                *u = u0[k] + alpha * du[e];
            }
        }
    }

    /// Newton iterations at `target` (modified Newton with the factors
    /// reused while they contract the residual fast, and an Armijo
    /// backtracking line search).
    pub(crate) fn newton(&mut self, target: &Target, opts: &SolverOptions) -> Result<(), FeError> {
        self.prescribe(target);
        if opts.symmetric {
            self.lu.set_symmetric(true)?;
        } else {
            self.lu.set_gmres(opts.gmres)?;
        }
        let mut a = self.assemble(target, true)?;
        let mut du = vec![0.0; self.dofs.equations];
        let mut chord = false;
        // whether `values` holds the tangent at the current state (the
        // line search assembles residuals only after its first trial)
        let mut have_tangent = true;
        for it in 0..=opts.max_iterations {
            let small_step = it > 0
                && du.iter().fold(0.0f64, |m: f64, v: &f64| m.max(v.abs()))
                    < 1e-12 * self.length_scale;
            if a.norm <= opts.tolerance * a.scale || (small_step && a.norm <= 1e-6 * a.scale) {
                return Ok(());
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
                let u0 = self.u.clone();
                self.apply(&du, 1.0, &u0);
                // residual only: the tangent is needed only if the chord is rejected
                match self.assemble(target, false) {
                    Ok(t) if t.norm <= 0.25 * norm0 => {
                        a = t;
                        have_tangent = false;
                        self.stats.chord_steps += 1;
                        continue;
                    }
                    _ => {
                        self.u.clone_from(&u0);
                        a = self.assemble(target, true)?;
                        have_tangent = true;
                    }
                }
            }
            if !have_tangent {
                a = self.assemble(target, true)?;
            }
            du.iter_mut().zip(&self.residual).for_each(|(d, r)| *d = -r);
            let values = std::mem::take(&mut self.values);
            let t0 = std::time::Instant::now();
            let solved = if opts.gmres && !opts.symmetric && opts.preconditioner_reuse > 0 {
                self.lu
                    .solve_reusing(&values, &mut du, opts.preconditioner_reuse)
            } else {
                self.lu.solve(&values, &mut du).map(|()| true)
            };
            self.stats.solve_seconds += t0.elapsed().as_secs_f64();
            self.values = values;
            if solved? {
                self.stats.factorisations += 1;
            } else {
                self.stats.reused_factors += 1;
            }
            if let Some(cap) = opts.max_update {
                let big = du.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                if big > cap {
                    let f = cap / big;
                    du.iter_mut().for_each(|v| *v *= f);
                }
            }
            let u0 = self.u.clone();
            let g0: f64 = du.iter().zip(&self.residual).map(|(d, r)| d * r).sum();
            if opts.line_search == LineSearch::Slope && g0 < 0.0 {
                let alpha = slope_search(g0, |alpha| {
                    self.apply(&du, alpha, &u0);
                    let t = self.assemble(target, alpha == 1.0)?;
                    a = t;
                    Ok(du.iter().zip(&self.residual).map(|(d, r)| d * r).sum())
                })?;
                have_tangent = alpha == 1.0;
                chord = opts.reuse_factorisation && a.norm <= 0.1 * norm0;
                continue;
            }
            let mut alpha = 1.0;
            let mut last_err = None;
            let mut accepted = None;
            // Armijo backtracking by halves: alpha = 1, 1/2, ..., 1/16, where
            // the step is taken whatever the residual; 1/32 is tried only
            // when the assembly at 1/16 fails (an inverted element). The
            // full step is assembled with its tangent (it is usually
            // accepted); shorter ones with the residual only, the tangent
            // then assembled at the accepted state when the next iteration
            // needs it (the same iterates, fewer tangent assemblies).
            for _ in 0..6 {
                self.apply(&du, alpha, &u0);
                have_tangent = alpha == 1.0;
                match self.assemble(target, have_tangent) {
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
            return Ok(());
        }
        Err(FeError::NewtonFailed {
            iterations: opts.max_iterations,
            residual: a.norm,
            tolerance: opts.tolerance * a.scale,
        })
    }

    /// Newton plus augmentations of the contributions' multipliers at `target`.
    pub(crate) fn solve_increment(
        &mut self,
        target: &Target,
        opts: &SolverOptions,
    ) -> Result<(), FeError> {
        // the start is kept only when a failure may be stabilised
        let start = (opts.stabilisation > 0.0).then(|| self.u.clone());
        match (self.newton(target, opts), start) {
            (Ok(()), _) => {}
            (Err(e), Some(start)) if e.is_recoverable() => {
                self.u = start;
                self.stabilised_newton(target, opts, e)?;
            }
            (Err(e), _) => return Err(e),
        }
        for _ in 0..opts.max_augmentations {
            let mut changed = false;
            for c in self.contributions.iter_mut() {
                changed |= c.augment();
            }
            if !changed {
                break;
            }
            self.stats.augmentations += 1;
            self.newton(target, opts)?;
        }
        Ok(())
    }

    /// [`SolverOptions::stabilisation`]: proximal steps from the current
    /// state, each followed by a try of plain Newton; `failed` is the error
    /// returned when none converges.
    fn stabilised_newton(
        &mut self,
        target: &Target,
        opts: &SolverOptions,
        failed: FeError,
    ) -> Result<(), FeError> {
        const STEPS: usize = 40;
        self.prescribe(target);
        self.assemble(target, true)?;
        let nd = self.dofs.nodes * self.dofs.dim;
        let mut c = vec![0.0; self.u.len()];
        for (k, ck) in c.iter_mut().enumerate().take(nd) {
            let e = self.dofs.equation(k);
            if e != NONE {
                if let Some(slot) = self.pattern.slot(e, e) {
                    *ck = opts.stabilisation * self.values[slot].abs();
                }
            }
        }
        let plain = SolverOptions {
            max_iterations: 8,
            ..*opts
        };
        let mut last = failed;
        let mut weight = 1.0;
        for _ in 0..STEPS {
            let anchor = self.u.clone();
            self.prox = Some((c.iter().map(|v| v * weight).collect(), anchor.clone()));
            let r = self.newton(target, opts);
            self.prox = None;
            self.stats.proximal_steps += 1;
            if let Err(e) = r {
                // a firmer term from the same anchor
                self.u = anchor;
                weight *= 4.0;
                last = e;
                continue;
            }
            let save = self.u.clone();
            match self.newton(target, &plain) {
                Ok(()) => {
                    self.stats.stabilised += 1;
                    return Ok(());
                }
                Err(e) => {
                    last = e;
                    self.u = save;
                    // a weaker term: the steps lengthen towards Newton's
                    weight *= 0.5;
                }
            }
        }
        Err(last)
    }

    /// Accepts the state at `target` as converged.
    pub(crate) fn commit(&mut self, target: &Target) {
        let mut contributions = std::mem::take(&mut self.contributions);
        {
            let ctx = self.context(target);
            for c in contributions.iter_mut() {
                c.commit(&ctx);
            }
        }
        self.contributions = contributions;
        self.committed = target.clone();
    }

    /// The residual of the last assembly, per equation.
    pub(crate) fn residual(&self) -> &[f64] {
        &self.residual
    }

    /// Factorises the tangent of the last assembly (which must have
    /// assembled it) for [`System::solve_factored`].
    pub(crate) fn factorize_tangent(&mut self) -> Result<(), FeError> {
        let values = std::mem::take(&mut self.values);
        let t0 = std::time::Instant::now();
        let r = self.lu.factorize(&values);
        self.stats.solve_seconds += t0.elapsed().as_secs_f64();
        self.values = values;
        r
    }

    /// Overwrites `rhs` (per equation) with the solution for the last
    /// factorised tangent.
    pub(crate) fn solve_factored(&mut self, rhs: &mut [f64]) -> Result<(), FeError> {
        let t0 = std::time::Instant::now();
        let r = self.lu.solve_factored(rhs);
        self.stats.solve_seconds += t0.elapsed().as_secs_f64();
        r
    }

    /// The state `u0 + a du` on the unknowns (`du` per equation), `u0` on
    /// the prescribed entries.
    pub(crate) fn set_state(&mut self, u0: &[f64], du: &[f64], a: f64) {
        self.apply(du, a, u0);
    }

    /// Every contribution's committed history ([`Contribution::history`]).
    pub(crate) fn histories(&self) -> Vec<Vec<f64>> {
        self.contributions.iter().map(|c| c.history()).collect()
    }

    /// Replaces every contribution's committed history by `h[c] + a dh[c]`.
    pub(crate) fn set_histories(&mut self, h: &[Vec<f64>], dh: &[Vec<f64>], a: f64) {
        for ((c, h), dh) in self.contributions.iter_mut().zip(h).zip(dh) {
            if a == 0.0 {
                c.set_history(h);
            } else {
                let v: Vec<f64> = h.iter().zip(dh).map(|(h, d)| h + a * d).collect();
                c.set_history(&v);
            }
        }
    }

    /// The contributions accept the trial history of the last assembly
    /// (the system's committed loading state is left as it is).
    pub(crate) fn commit_contributions(&mut self, target: &Target) {
        let mut contributions = std::mem::take(&mut self.contributions);
        {
            let ctx = self.context(target);
            for c in contributions.iter_mut() {
                c.commit(&ctx);
            }
        }
        self.contributions = contributions;
    }

    /// Every contribution holds the discrete state of the last assembly, or
    /// lets it follow the state again ([`Contribution::hold_branches`]).
    pub(crate) fn hold_branches(&mut self, hold: bool) {
        for c in self.contributions.iter_mut() {
            c.hold_branches(hold);
        }
    }

    /// Restores the contributions' history of the last commit (the state
    /// vector is the stepper's to restore).
    pub(crate) fn rollback(&mut self) {
        for c in self.contributions.iter_mut() {
            c.rollback();
        }
    }
}

#[cfg(test)]
#[path = "system_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "system_q1_tests.rs"]
mod q1_tests;
