//! The real-time model's fitted memory: a nonlinear
//! single-integral force model whose memory is read through the present
//! depth, fitted to FE histories by linear least squares.
//!
//! # Why
//!
//! QLV on the force ([`crate::model`]'s default) assumes the force
//! stored at an earlier depth relaxes as the elastic force does, whatever
//! the depth is now: exact for a flat punch in the linear range, off by
//! several per cent of the peak for the rounded Q1 punch and the N1 needle,
//! whose contact grows and shrinks (docs/validation/realtime.md). The FE material's Prony
//! series acts on the isochoric second Piola-Kirchhoff stress; the force of
//! a stress stored at depth `b` and read at depth `a` is `K(a, b)`, not
//! `F_e(b)`. This model keeps the recursion (O(modes x knots) a sample) and
//! lets the data give `K`.
//!
//! # Model
//!
//! A single-integral nonlinear viscoelastic law (the modified superposition
//! of Findley, Lai & Onaran 1976, *Creep and relaxation of nonlinear
//! viscoelastic materials*, ch. 7, with a separable kernel), in the depth
//! `e(t)` of the tissue surface (the punch depth `d(t)` while in contact):
//!
//! ```text
//! F(t) = sum_k a_k phi_k(e(t))
//!      + sum_i sum_k (c_ik0 chi_0(e(t)) + c_ik1 chi_1(e(t))) m_ik(t),
//! m_ik(t) = int_0^t exp(-(t - s) / tau_i) d phi_k(e(s)),
//! ```
//!
//! `phi_k` hat functions on `knots` equal depth intervals of
//! `[0, depth_max]` (`phi_k(0) = 0`), `chi_0 = 1 - e / depth_max` and
//! `chi_1 = e / depth_max` (the present depth, linearly), `tau_i` the
//! material's time constants. The memory update is exact for `phi_k(e)`
//! linear in time over a step (Taylor, Pister & Goudreau 1970):
//! `m(n+1) = exp(-dt/tau) m(n) + (1 - exp(-dt/tau)) / (dt/tau) (phi(n+1) - phi(n))`.
//! QLV with the material's terms is the special case
//! `a_k = g_inf F_e(x_k)`, `c_ik0 = c_ik1 = g_i F_e(x_k)`.
//!
//! Loss of contact (with `lift_off`, as QLV's): when the trial force at
//! `e = d` is negative, the surface is free; its depth `e > d` solves
//! `F(e) = 0` (bisection: `F` is piecewise quadratic in `e`), the memory
//! follows `e`, and the answer is 0. Without `lift_off` the memory follows
//! the punch and the force is clamped at 0.
//!
//! A compliant contact (`soft_contact = [g0, A]`, with `lift_off`): the
//! contact does not end at once, as neither the needle's (a shrinking
//! contact patch) nor the rounded punch's does (the tissue lets go of the
//! face and the edge at different times). The surface's depth `e` lags
//! the punch by a gap `g = e - d` at which the punch presses with
//! `H(g) = A (g0 / g - 1)` (`g < g0`; 0 beyond): `e` solves `F(e) = H(e - d)`
//! (bisection: `F(e) - H` rises from minus infinity at `e = d`), the memory
//! follows `e`, and the answer is `F(e)`. Deep in contact the gap is small
//! (`g ~ A g0 / F`); as the force falls the gap opens and the force fades to
//! 0 over `g0` instead of stopping; beyond `g0` it is the hard rule's free
//! surface. `g0 -> 0` is the hard contact. The gap is at most `d` (`g0` is
//! `min(g0, d)`): a punch at the surface presses nothing on a surface at
//! rest (without it, the press across the gap would hold a force at
//! `d = 0`). `H` is an empirical law, not a
//! contact solution: its two constants are chosen with the rest.
//!
//! Which one holds (the punch, the hard contact or one of four compliant
//! ones, [`COMPLIANT`]) is chosen by cross-validation on the training
//! histories ([`MemoryKernel::fit`]): the free surface is physics for a
//! flat punch, whose contact is all or nothing in the linear range, and
//! less so for a needle or a rounded edge at depth.
//!
//! Stop operators (`stops`): a rate-independent hysteresis
//! beside the memory,
//!
//! ```text
//! F += sum_j (b_j0 chi_0(e) + b_j1 chi_1(e)) s_j(t),
//! s_j(t) = clamp(s_j(t - dt) + e(t) - e(t - dt), -r_j, r_j),
//! ```
//!
//! the stretch of an elastic-perfectly-plastic element of yield
//! displacement `r_j` (the stop operator of Prandtl-Ishlinskii hysteresis
//! models; Visintin 1994, *Differential Models of Hysteresis*, ch. III;
//! Iwan 1966, J. Appl. Mech. 33:893, for the parallel elements), with
//! thresholds [`STOPS`] times `depth_max`. A reversal of the depth changes
//! the force by up to `2 b_j r_j` over `2 r_j` of depth, whatever the rate:
//! what the memory alone lacks where the FE force falls faster on
//! unloading than it rose (a needle's shaft sliding back, a contact patch
//! letting go) and comes back earlier on reloading. Linear in `b`, so
//! fitted with the rest; the cross-validation chooses each contact form
//! without and with them.
//!
//! # Fit
//!
//! The force is linear in `a` and `c` once the path `e(t)` is known, so the
//! coefficients are linear least squares over the FE stations of the
//! training histories (stations with an FE force below 1 % of the peak
//! are out of contact and left out), with second differences along the
//! knots as a small smoothing penalty; with `lift_off` the path comes from
//! the previous fit (three fixed-point passes from `e = d`). The solver is
//! nalgebra's SVD (a dense problem of ~1,000 x 56; the crate is already a
//! dependency here, faer is not).

use serde::{Deserialize, Serialize};

use crate::depth_history::History;

/// Present-depth functions `chi_j`.
const PRESENT: usize = 2;
/// Fixed-point passes of the lift-off path in a fit.
const LIFT_PASSES: usize = 3;
/// Bisections of a surface depth (to `depth_max / 2^40`).
const BISECTIONS: usize = 40;
/// The compliant contacts the cross-validation tries besides the hard one:
/// `[g0 / depth_max, A / peak force]`. What the choice among them gives on
/// the builds measured: docs/validation/realtime.md.
pub const COMPLIANT: [[f64; 2]; 4] = [[0.05, 0.03], [0.1, 0.03], [0.1, 0.1], [0.2, 0.03]];
/// Thresholds of the stop operators, over `depth_max` (module doc); the
/// cross-validation chooses whether a build uses them
/// (docs/validation/realtime.md).
pub const STOPS: [f64; 3] = [0.03, 0.1, 0.3];
/// Folds of the cross-validation that chooses `lift_off`.
const FOLDS: usize = 4;
/// Stations whose FE force is below this fraction of the run's peak are
/// taken as out of contact and not fitted.
const CONTACT_FLOOR: f64 = 0.01;

/// One FE training run: the history (sampled at its time step) and the FE
/// force at its stations `(time_s, force_n)`.
#[derive(Debug, Clone)]
pub struct TrainingRun<'a> {
    pub history: &'a History,
    pub stations: &'a [(f64, f64)],
}

/// How the fit went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KernelTraining {
    /// FE training histories and their stations in contact.
    pub histories: usize,
    pub stations: usize,
    /// RMS of the fit at those stations (N).
    pub rms_n: f64,
    /// Cross-validated station error over the run's peak (the mean over
    /// the held-out runs of each one's largest), without and with loss of
    /// contact (the smaller one chose `lift_off`); none if not fitted.
    pub cv_max_relative_error: Option<[f64; 2]>,
    /// Each loss-of-contact form the cross-validation tried after the
    /// punch-following one: `[g0 / depth_max, A / peak force]` (`[0, 0]`
    /// the hard contact) and its score as above.
    #[serde(default)]
    pub cv_contacts: Vec<([f64; 2], f64)>,
    /// The same scores with the stop operators ([`STOPS`]): following the
    /// punch, then each form of `cv_contacts` in its order (empty in files
    /// written before them).
    #[serde(default)]
    pub cv_stops: Vec<f64>,
}

/// The fitted memory and its state (the state is not stored).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MemoryKernel {
    /// Depth range (mm) of the hat functions.
    pub depth_max: f64,
    /// Number of hat functions `phi_k` (knots at `k depth_max / knots`).
    pub knots: usize,
    /// `tau_i` (s).
    pub taus: Vec<f64>,
    /// `a_k` (N).
    pub equilibrium: Vec<f64>,
    /// `c_ikj` at `(i knots + k) 2 + j` (N).
    pub memory: Vec<f64>,
    /// Loss of contact (see the module doc).
    pub lift_off: bool,
    /// A compliant contact with `lift_off`: `[g0 (mm), A (N)]` of the
    /// press `H(g) = A (g0 / g - 1)` at a gap `g = e - d < g0` (module
    /// doc); `g0 = 0` is the hard contact (files written before it).
    #[serde(default)]
    pub soft_contact: [f64; 2],
    /// Thresholds `r_j` (mm) of the stop operators (rate-independent
    /// hysteresis; module doc); empty: none.
    #[serde(default)]
    pub stops: Vec<f64>,
    /// `b_jp` at `j PRESENT + p` (N/mm).
    #[serde(default)]
    pub stop_coefficients: Vec<f64>,
    pub training: KernelTraining,
    #[serde(skip)]
    state: KernelState,
}

#[derive(Debug, Clone, Default)]
struct KernelState {
    m: Vec<f64>,
    trial: Vec<f64>,
    phi: Vec<f64>,
    e: f64,
    dt: f64,
    decay: Vec<(f64, f64)>,
    stop: Vec<f64>,
    stop_trial: Vec<f64>,
}

/// The two hats that are non-zero at `depth`: `(k, weight)` pairs (a `k`
/// of `usize::MAX` stands for the hat at 0, which is not a function).
fn hats(depth_max: f64, knots: usize, depth: f64) -> [(usize, f64); 2] {
    let x = (depth / depth_max * knots as f64).clamp(0.0, knots as f64);
    let j = (x.floor() as usize).min(knots - 1);
    let w = x - j as f64;
    let lower = if j >= 1 { j - 1 } else { usize::MAX };
    [(lower, 1.0 - w), (j, w)]
}

impl MemoryKernel {
    fn shape(depth_max: f64, knots: usize, taus: &[f64], lift_off: bool) -> Self {
        MemoryKernel {
            depth_max,
            knots,
            taus: taus.to_vec(),
            equilibrium: vec![0.0; knots],
            memory: vec![0.0; taus.len() * knots * PRESENT],
            lift_off,
            soft_contact: [0.0; 2],
            stops: Vec::new(),
            stop_coefficients: Vec::new(),
            training: KernelTraining {
                histories: 0,
                stations: 0,
                rms_n: 0.0,
                cv_max_relative_error: None,
                cv_contacts: Vec::new(),
                cv_stops: Vec::new(),
            },
            state: KernelState::default(),
        }
    }

    /// QLV on the force as a kernel: `a_k = g_inf F_k`, `c_ik0 = c_ik1 =
    /// g_i F_k`, with `F_k` the elastic force at knot `k` (`knots` values,
    /// at `k depth_max / knots`, k = 1..knots) and the Prony terms
    /// `(g_i, tau_i)`; it answers as [`crate::RealTimeModel`]'s QLV
    /// wherever the elastic curve is linear between the knots.
    pub fn qlv(
        depth_max: f64,
        elastic_at_knots: &[f64],
        prony: &[(f64, f64)],
        lift_off: bool,
    ) -> MemoryKernel {
        let knots = elastic_at_knots.len();
        let taus: Vec<f64> = prony.iter().map(|p| p.1).collect();
        let mut k = MemoryKernel::shape(depth_max, knots, &taus, lift_off);
        let g_inf = 1.0 - prony.iter().map(|p| p.0).sum::<f64>();
        for (j, &f) in elastic_at_knots.iter().enumerate() {
            k.equilibrium[j] = g_inf * f;
            for (i, &(g, _)) in prony.iter().enumerate() {
                let base = (i * knots + j) * PRESENT;
                k.memory[base] = g * f;
                k.memory[base + 1] = g * f;
            }
        }
        k.reset();
        k
    }

    fn columns(&self) -> usize {
        self.knots + self.memory.len() + self.stop_coefficients.len()
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        let n = self.taus.len() * self.knots;
        self.state = KernelState {
            m: vec![0.0; n],
            trial: vec![0.0; n],
            phi: vec![0.0; self.knots],
            e: 0.0,
            dt: f64::NAN,
            decay: vec![(1.0, 1.0); self.taus.len()],
            stop: vec![0.0; self.stops.len()],
            stop_trial: vec![0.0; self.stops.len()],
        };
    }

    fn set_step(&mut self, dt: f64) {
        if self.state.m.len() != self.taus.len() * self.knots {
            self.reset();
        }
        if dt != self.state.dt {
            for (i, &tau) in self.taus.iter().enumerate() {
                let x = dt / tau;
                let e = (-x).exp();
                let p = if x > 0.0 { -(-x).exp_m1() / x } else { 1.0 };
                self.state.decay[i] = (e, p);
            }
            self.state.dt = dt;
        }
    }

    /// The row of the linear model at surface depth `e` after the step set
    /// by [`Self::set_step`]: writes the trial memory into the state and,
    /// if `row` is given, the column values into it; returns the force with
    /// the current coefficients.
    fn trial(&mut self, e: f64, mut row: Option<&mut [f64]>) -> f64 {
        let nk = self.knots;
        let st = &mut self.state;
        let h = hats(self.depth_max, nk, e);
        let r = e.min(self.depth_max) / self.depth_max;
        let chi = [1.0 - r, r];
        let mut f = 0.0;
        if let Some(r) = row.as_deref_mut() {
            r.iter_mut().for_each(|v| *v = 0.0);
        }
        for &(k, w) in &h {
            if k != usize::MAX {
                f += self.equilibrium[k] * w;
                if let Some(r) = row.as_deref_mut() {
                    r[k] += w;
                }
            }
        }
        // phi(e) - phi(previous) without a dense phi(e): subtract the
        // previous, add the two new hats
        for (i, &(ed, p)) in st.decay.iter().enumerate() {
            for k in 0..nk {
                let mut dphi = -st.phi[k];
                for &(kk, w) in &h {
                    if kk == k {
                        dphi += w;
                    }
                }
                let c = i * nk + k;
                let m = ed * st.m[c] + p * dphi;
                st.trial[c] = m;
                let base = c * PRESENT;
                f += m * (self.memory[base] * chi[0] + self.memory[base + 1] * chi[1]);
                if let Some(r) = row.as_deref_mut() {
                    r[nk + base] = m * chi[0];
                    r[nk + base + 1] = m * chi[1];
                }
            }
        }
        let first = nk + self.memory.len();
        for (j, &r0) in self.stops.iter().enumerate() {
            let s = (st.stop[j] + (e - st.e)).clamp(-r0, r0);
            st.stop_trial[j] = s;
            let b = &self.stop_coefficients[j * PRESENT..(j + 1) * PRESENT];
            f += s * (b[0] * chi[0] + b[1] * chi[1]);
            if let Some(r) = row.as_deref_mut() {
                r[first + j * PRESENT] = s * chi[0];
                r[first + j * PRESENT + 1] = s * chi[1];
            }
        }
        f
    }

    fn commit(&mut self, e: f64) {
        let st = &mut self.state;
        std::mem::swap(&mut st.m, &mut st.trial);
        std::mem::swap(&mut st.stop, &mut st.stop_trial);
        st.phi.iter_mut().for_each(|v| *v = 0.0);
        for (k, w) in hats(self.depth_max, self.knots, e) {
            if k != usize::MAX {
                st.phi[k] = w;
            }
        }
        st.e = e;
    }

    /// One step to punch depth `depth` (mm, in range) after `dt` (s, >= 0):
    /// the force and the surface depth. The caller checks the range.
    pub(crate) fn step(&mut self, depth: f64, dt: f64) -> (f64, f64) {
        self.set_step(dt);
        if self.lift_off && self.soft_contact[0] > 0.0 && depth > 0.0 {
            return self.step_compliant(depth);
        }
        let f = self.trial(depth, None);
        if f >= 0.0 {
            self.commit(depth);
            return (f, depth);
        }
        if !self.lift_off {
            self.commit(depth);
            return (0.0, depth);
        }
        // the free surface: F(e) = 0 for e in (depth, depth_max]
        let e = self.surface_depth(depth, self.depth_max, |_| 0.0);
        self.trial(e, None);
        self.commit(e);
        (0.0, e)
    }

    /// The surface depth `e` in `(lo, hi]` where the force `F(e)` meets the
    /// punch's `press(e)` (`F - press` rising in `e`, negative at `lo`), by
    /// bisection; `hi` if `F` stays below. Leaves the trial state at some
    /// depth: the caller sets it at `e`.
    fn surface_depth(&mut self, mut lo: f64, mut hi: f64, press: impl Fn(f64) -> f64) -> f64 {
        if self.trial(hi, None) < press(hi) {
            return hi;
        }
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if self.trial(mid, None) < press(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// A step with the compliant contact: the surface depth `e` in
    /// `(d, depth_max + g0]` where `F(e) = H(e - d)`, by bisection (`F(e) -
    /// H` rises from minus infinity at `e = d`); beyond `g0` it is the free
    /// surface's `F(e) = 0`. The force is `max(F(e), 0)`. (The depth
    /// functions are constant beyond `depth_max`, so a punch at the range's
    /// end keeps its gap.) The gap is at most the punch depth `d`
    /// (`g0` becomes `min(g0, d)`), so the force goes to 0 with `d`, and a
    /// punch at the surface (`d = 0`) follows the hard rule: at rest, no
    /// force.
    fn step_compliant(&mut self, depth: f64) -> (f64, f64) {
        let [g0, a] = self.soft_contact;
        let g0 = g0.min(depth);
        let press = |e: f64| {
            let g = e - depth;
            if g < g0 {
                a * (g0 / g - 1.0)
            } else {
                0.0
            }
        };
        let e = self.surface_depth(depth, self.depth_max + g0, press);
        let f = self.trial(e, None).max(0.0);
        self.commit(e);
        (f, e)
    }

    /// The forces and surface depths of a whole history from rest.
    fn run(&mut self, history: &History) -> (Vec<f64>, Vec<f64>) {
        self.reset();
        let mut prev = 0.0;
        let mut out = (
            Vec::with_capacity(history.time.len()),
            Vec::with_capacity(history.time.len()),
        );
        for (&t, &d) in history.time.iter().zip(&history.depth) {
            let (f, e) = self.step(d.clamp(0.0, self.depth_max), t - prev);
            prev = t;
            out.0.push(f);
            out.1.push(e);
        }
        out
    }

    /// Least squares on `runs` along the surface paths `paths`; returns the
    /// RMS at the fitted stations and their number.
    fn solve(
        &mut self,
        runs: &[TrainingRun<'_>],
        paths: &[Vec<f64>],
        smoothing: f64,
    ) -> Result<(f64, usize), String> {
        let ncol = self.columns();
        let mut rows: Vec<f64> = Vec::new();
        let mut rhs: Vec<f64> = Vec::new();
        let mut row = vec![0.0; ncol];
        for (run, path) in runs.iter().zip(paths) {
            let peak = run.stations.iter().map(|s| s.1).fold(0.0, f64::max);
            let mut want = run
                .stations
                .iter()
                .filter(|s| s.1 > CONTACT_FLOOR * peak)
                .map(|&(t, f)| (run.history.sample_at(t), f))
                .peekable();
            self.reset();
            let mut prev = 0.0;
            for (j, (&t, &e)) in run.history.time.iter().zip(path).enumerate() {
                self.set_step(t - prev);
                prev = t;
                let at = want.peek().map(|w| w.0);
                if at == Some(j) {
                    self.trial(e, Some(&mut row));
                    while want.peek().map(|w| w.0) == Some(j) {
                        let (_, f) = want.next().expect("peeked");
                        rows.extend_from_slice(&row);
                        rhs.push(f);
                    }
                } else {
                    self.trial(e, None);
                }
                self.commit(e);
            }
        }
        let n = rhs.len();
        if n < ncol {
            return Err(format!(
                "{n} FE stations in contact for {ncol} coefficients: train on more histories"
            ));
        }
        // second differences along the knots: the equilibrium, then each
        // (mode, present function)
        let mut penalty = |first: usize, stride: usize| {
            for k in 1..self.knots - 1 {
                let mut r = vec![0.0; ncol];
                r[first + (k - 1) * stride] = smoothing;
                r[first + k * stride] = -2.0 * smoothing;
                r[first + (k + 1) * stride] = smoothing;
                rows.extend(r);
                rhs.push(0.0);
            }
        };
        penalty(0, 1);
        for i in 0..self.taus.len() {
            for j in 0..PRESENT {
                penalty(self.knots + i * self.knots * PRESENT + j, PRESENT);
            }
        }
        let a = nalgebra::DMatrix::from_row_slice(rhs.len(), ncol, &rows);
        let b = nalgebra::DVector::from_vec(rhs);
        let svd = a.clone().svd(true, true);
        let c = svd
            .solve(&b, 1e-12 * svd.singular_values.max())
            .map_err(|e| format!("least squares of the memory kernel: {e}"))?;
        let res = a.rows(0, n) * &c - b.rows(0, n);
        self.equilibrium
            .copy_from_slice(&c.as_slice()[..self.knots]);
        let nm = self.memory.len();
        self.memory
            .copy_from_slice(&c.as_slice()[self.knots..self.knots + nm]);
        self.stop_coefficients
            .copy_from_slice(&c.as_slice()[self.knots + nm..]);
        Ok(((res.norm_squared() / n as f64).sqrt(), n))
    }

    /// Fits with the surface following the punch (`contact` none) or with
    /// loss of contact, hard (`[0, 0]`) or compliant (`[g0 (mm), A (N)]`)
    /// (module doc).
    fn fit_with(
        depth_max: f64,
        knots: usize,
        taus: &[f64],
        runs: &[TrainingRun<'_>],
        contact: Option<[f64; 2]>,
        with_stops: bool,
        smoothing: f64,
    ) -> Result<(MemoryKernel, f64, usize), String> {
        let lift_off = contact.is_some();
        let mut k = MemoryKernel::shape(depth_max, knots, taus, lift_off);
        k.soft_contact = contact.unwrap_or([0.0; 2]);
        if with_stops {
            k.stops = STOPS.iter().map(|r| r * depth_max).collect();
            k.stop_coefficients = vec![0.0; k.stops.len() * PRESENT];
        }
        let mut paths: Vec<Vec<f64>> = runs.iter().map(|r| r.history.depth.clone()).collect();
        let (mut rms, mut n) = k.solve(runs, &paths, smoothing)?;
        if lift_off {
            for _ in 0..LIFT_PASSES {
                paths = runs.iter().map(|r| k.run(r.history).1).collect();
                (rms, n) = k.solve(runs, &paths, smoothing)?;
            }
        }
        k.reset();
        Ok((k, rms, n))
    }

    /// The largest station error over the run's peak force.
    fn max_relative_error(&mut self, run: &TrainingRun<'_>) -> f64 {
        let (f, _) = self.run(run.history);
        let peak = run.stations.iter().map(|s| s.1).fold(0.0, f64::max);
        let worst = run
            .stations
            .iter()
            .map(|&(t, v)| (f[run.history.sample_at(t)] - v).abs())
            .fold(0.0, f64::max);
        worst / peak.max(f64::MIN_POSITIVE)
    }

    /// Fits the kernel to FE training runs (at least `FOLDS + 1` = 5; the first
    /// should reach `depth_max`): `knots` hat functions on `[0, depth_max]`,
    /// the material's time constants `taus`. How the memory meets the punch
    /// (following it, a hard loss of contact, or one of the compliant ones
    /// of [`COMPLIANT`]), each without and with the stop operators
    /// ([`STOPS`]), is chosen by a 4-fold cross-validation over the runs
    /// after the first (which stays in every fold): the smallest mean of the
    /// held-out runs' largest errors, the simpler form on a tie (without
    /// stops first). Then the chosen form is fitted to all of them.
    pub fn fit(
        depth_max: f64,
        knots: usize,
        taus: &[f64],
        runs: &[TrainingRun<'_>],
    ) -> Result<MemoryKernel, String> {
        if !(depth_max > 0.0 && depth_max.is_finite()) || knots < 3 || taus.is_empty() {
            return Err(format!(
                "memory kernel on [0, {depth_max}] mm with {knots} knots and {} time constants: need a depth > 0, at least 3 knots and 1 time constant",
                taus.len()
            ));
        }
        if let Some(t) = taus.iter().find(|t| !(**t > 0.0 && t.is_finite())) {
            return Err(format!("time constant {t} s: must be > 0"));
        }
        if runs.len() < FOLDS + 1 {
            return Err(format!(
                "{} FE training histories: the memory kernel needs at least {}",
                runs.len(),
                FOLDS + 1
            ));
        }
        let peak = runs
            .iter()
            .flat_map(|r| r.stations.iter().map(|s| s.1))
            .fold(0.0, f64::max);
        if !(peak > 0.0 && peak.is_finite()) {
            return Err("the FE training histories carry no force".into());
        }
        let smoothing = 0.01 * peak;
        // run 0 (the ramp and hold to depth_max) stays in every fold: it
        // alone reaches the range's end and holds long
        let contacts: Vec<Option<[f64; 2]>> = [None, Some([0.0; 2])]
            .into_iter()
            .chain(
                COMPLIANT
                    .iter()
                    .map(|c| Some([c[0] * depth_max, c[1] * peak])),
            )
            .collect();
        // each contact without, then with, the stop operators
        let forms: Vec<(Option<[f64; 2]>, bool)> = [false, true]
            .into_iter()
            .flat_map(|with_stops| contacts.iter().map(move |&c| (c, with_stops)))
            .collect();
        let mut cv = vec![0.0f64; forms.len()];
        for (slot, &(contact, with_stops)) in forms.iter().enumerate() {
            let mut scored = 0usize;
            for fold in 0..FOLDS {
                let held = |r: usize| r > 0 && (r - 1) % FOLDS == fold;
                let train: Vec<TrainingRun<'_>> = runs
                    .iter()
                    .enumerate()
                    .filter(|(r, _)| !held(*r))
                    .map(|(_, r)| r.clone())
                    .collect();
                let (mut k, _, _) = Self::fit_with(
                    depth_max, knots, taus, &train, contact, with_stops, smoothing,
                )?;
                for (_, run) in runs.iter().enumerate().filter(|(r, _)| held(*r)) {
                    cv[slot] += k.max_relative_error(run);
                    scored += 1;
                }
            }
            cv[slot] /= scored.max(1) as f64;
        }
        // the first smallest score: the simpler form on a tie
        let best = (0..cv.len()).fold(0, |b, j| if cv[j] < cv[b] { j } else { b });
        let (contact, with_stops) = forms[best];
        let (mut k, rms, n) =
            Self::fit_with(depth_max, knots, taus, runs, contact, with_stops, smoothing)?;
        let nc = contacts.len();
        let lifted = cv[1..nc].iter().copied().fold(f64::INFINITY, f64::min);
        k.training = KernelTraining {
            histories: runs.len(),
            stations: n,
            rms_n: rms,
            cv_max_relative_error: Some([cv[0], lifted]),
            cv_contacts: std::iter::once([0.0; 2])
                .chain(COMPLIANT)
                .zip(cv[1..nc].iter().copied())
                .collect(),
            cv_stops: cv[nc..].to_vec(),
        };
        Ok(k)
    }

    /// The stored kernel's shape is consistent (a file read from disk).
    pub fn check(&self) -> Result<(), String> {
        if !(self.depth_max > 0.0 && self.depth_max.is_finite()) || self.knots < 3 {
            return Err(format!(
                "memory kernel: depth range {} mm, {} knots",
                self.depth_max, self.knots
            ));
        }
        if self.equilibrium.len() != self.knots
            || self.memory.len() != self.taus.len() * self.knots * PRESENT
        {
            return Err(format!(
                "memory kernel: {} equilibrium and {} memory coefficients for {} knots and {} time constants",
                self.equilibrium.len(),
                self.memory.len(),
                self.knots,
                self.taus.len()
            ));
        }
        if let Some(v) = self
            .equilibrium
            .iter()
            .chain(&self.memory)
            .chain(&self.taus)
            .find(|v| !v.is_finite())
        {
            return Err(format!("memory kernel: coefficient {v} is not finite"));
        }
        if let Some(t) = self.taus.iter().find(|t| **t <= 0.0) {
            return Err(format!("memory kernel: time constant {t} s"));
        }
        if self.stop_coefficients.len() != self.stops.len() * PRESENT
            || self
                .stops
                .iter()
                .chain(&self.stop_coefficients)
                .any(|v| !v.is_finite())
            || self.stops.iter().any(|r| *r <= 0.0)
        {
            return Err(format!(
                "memory kernel: {} stop operators with thresholds {:?} mm and {} coefficients: need thresholds > 0 and {} finite coefficients",
                self.stops.len(),
                self.stops,
                self.stop_coefficients.len(),
                self.stops.len() * PRESENT
            ));
        }
        if self
            .soft_contact
            .iter()
            .any(|v| !(*v >= 0.0 && v.is_finite()))
        {
            return Err(format!(
                "memory kernel: compliant contact {:?} (gap mm, force N): need values >= 0",
                self.soft_contact
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "memory_kernel_tests.rs"]
mod tests;
