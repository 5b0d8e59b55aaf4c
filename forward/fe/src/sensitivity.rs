//! Exact parameter sensitivities of an FE run by direct differentiation
//! through its converged increments.
//!
//! Increment `n` solves `R(u_n, h_{n-1}, p) = 0`, where `h_{n-1}` is the
//! committed history of every contribution ([`crate::contribution::Contribution::history`]:
//! viscoelastic internal variables, contact multipliers, stick points and
//! the positions at the last commit) and `p` the parameters; it commits
//! `h_n = H(u_n, h_{n-1}, p)` and observes `F_n = Phi(u_n, h_{n-1}, p)` (a
//! tool force, a reaction). Differentiating,
//!
//! ```text
//! K du_n/dp = -(dR/dp + dR/dh dh_{n-1}/dp)         (K: the tangent at u_n)
//! dh_n/dp   = dH/du du_n/dp + dH/dh dh_{n-1}/dp + dH/dp
//! dF_n/dp   = dPhi/du du_n/dp + dPhi/dh dh_{n-1}/dp + dPhi/dp
//! ```
//!
//! with `dh_0/dp = 0` (the reference state does not depend on the
//! parameters). After each converged increment the tangent at the
//! converged state is factorised once and each parameter costs one
//! back-substitution.
//!
//! The partial derivatives are taken semi-analytically: each bracket is
//! the derivative along one direction of `(u, h, p)`, computed by a
//! central difference of the assembly at the converged state (no solve):
//! the right-hand side from `R(u_n, h_{n-1} +- e dh_{n-1}/dp, p +- e)`, and
//! `dh_n/dp`, `dF_n/dp` from one assembly and commit at
//! `(u_n +- e du_n/dp, h_{n-1} +- e dh_{n-1}/dp, p +- e)`. Why this rather
//! than analytic derivatives of every law, Prony term, penalty and return
//! map: it is general (every law, the bulk ratio, Prony weights and times,
//! friction, penalties scaled by the shear modulus, any contribution that
//! exposes its history) with no code per law, and on a smooth piece of the
//! residual its error is `O(e^2)` plus round-off, far below the
//! accuracy of any finite difference of whole runs: with `e = 1e-4 |p|`
//! the tests find 1e-8 relative or better (a step of `1e-6 |p|` left
//! 2e-5 of round-off in a friction derivative, the stick slip being a
//! small difference of arc lengths). It costs, per increment, one more tangent assembly and factorisation
//! and, per parameter, four residual assemblies and one back-substitution,
//! against `2 P` more whole runs for central differences.
//!
//! What is differentiated is the discrete run with its increments held: the
//! same increments (the nominal run's step control), the Uzawa update of the
//! contact multipliers at each commit, and contact, stick and slip as the
//! nominal run found them: while it takes its differences, every
//! contribution holds the discrete state of the converged assembly
//! ([`crate::contribution::Contribution::hold_branches`]: a contact point
//! touching or clear, sticking or sliding), each piece's law extended
//! beyond its switch, so that the right-hand side, the new history and the
//! outputs are differentiated on the branch the tangent was assembled on.
//! A point within `e` of a switch would otherwise mix the two laws: on the
//! needle at friction 0.345, a point that stuck on one side of the
//! difference and slid on the other made the friction column 50 times too
//! large at one depth, and its stick point carried the error on
//! (`tests/integration/sensitivity_friction.rs`). At a switch the derivative
//! is one-sided, as the forces themselves are only piecewise smooth there,
//! and central differences of whole runs agree only with steps that fall
//! between the switches. Augmentations
//! within an increment (`SolverOptions::max_augmentations > 0` with a
//! penetration above tolerance) are treated as converged: their multipliers
//! are held, which is exact only once the augmentation has converged.

use crate::system::{System, Target};
use crate::FeError;

/// Relative size of the directional differences (`e = STEP |p_j|`, or
/// `STEP` for a parameter at zero; module documentation for the choice).
const STEP: f64 = 1e-4;

/// Sets the parameters of a run on a system (the model's materials and
/// contact options) without touching its history.
pub(crate) type SetParameters<'a> = dyn FnMut(&mut System, &[f64]) -> Result<(), FeError> + 'a;

/// The derivatives carried through a run: the history's and, after each
/// converged increment, the outputs'.
pub(crate) struct Differentiation {
    theta: Vec<f64>,
    /// Per parameter: the step `e` and the sides of its difference
    /// (`(1, -1)`, or `(1, 0)` when `theta - e` is not admissible).
    steps: Vec<(f64, f64, f64)>,
    /// `dh/dp_j` per contribution (empty until the first increment).
    dh: Vec<Vec<Vec<f64>>>,
    /// `d outputs / d p_j` of the last converged increment.
    pub(crate) outputs: Vec<Vec<f64>>,
    /// Drop the history's derivatives (`dh/dp = 0` at every increment): a
    /// switch for the tests that show they matter.
    pub(crate) drop_history: bool,
}

impl Differentiation {
    /// For a run at `theta` with `outputs` outputs; `set` sets parameters
    /// on `sys` (tried at `theta - e` for each parameter, then at `theta`).
    pub(crate) fn new(
        sys: &mut System,
        theta: &[f64],
        outputs: usize,
        set: &mut SetParameters,
    ) -> Result<Differentiation, FeError> {
        let mut steps = Vec::with_capacity(theta.len());
        for (j, &t) in theta.iter().enumerate() {
            let e = if t == 0.0 { STEP } else { STEP * t.abs() };
            let mut lower = theta.to_vec();
            lower[j] -= e;
            let minus = if set(sys, &lower).is_ok() { -1.0 } else { 0.0 };
            steps.push((e, 1.0, minus));
        }
        set(sys, theta)?;
        Ok(Differentiation {
            theta: theta.to_vec(),
            steps,
            dh: Vec::new(),
            outputs: vec![vec![0.0; outputs]; theta.len()],
            drop_history: false,
        })
    }

    /// The derivatives at the converged state of the increment to `target`,
    /// before its commit; leaves the system as it found it (state,
    /// parameters, committed history and the trial state of an assembly at
    /// the converged state). On an error (an element inverted at a
    /// perturbed state) the parameters, the committed history and the state
    /// are restored, so that the stepper can cut the increment and retry
    /// it; the history's derivatives are those of the increment's start.
    pub(crate) fn increment(
        &mut self,
        sys: &mut System,
        target: &Target,
        set: &mut SetParameters,
        observe: &dyn Fn(&System) -> Vec<f64>,
    ) -> Result<(), FeError> {
        let h0 = sys.histories();
        let u0 = sys.u.clone();
        let done = self.differentiate(sys, target, set, observe, &h0, &u0);
        sys.hold_branches(false);
        if done.is_err() {
            // the parameters were accepted at the run's start
            let _ = set(sys, &self.theta);
            sys.set_histories(&h0, &h0, 0.0);
            sys.set_state(&u0, &vec![0.0; sys.equations()], 0.0);
        }
        done
    }

    /// [`Differentiation::increment`] without the restoring on an error.
    fn differentiate(
        &mut self,
        sys: &mut System,
        target: &Target,
        set: &mut SetParameters,
        observe: &dyn Fn(&System) -> Vec<f64>,
        h0: &[Vec<f64>],
        u0: &[f64],
    ) -> Result<(), FeError> {
        if self.dh.is_empty() || self.drop_history {
            let zero: Vec<Vec<f64>> = h0.iter().map(|h| vec![0.0; h.len()]).collect();
            self.dh = vec![zero; self.theta.len()];
        }
        let zero = vec![0.0; sys.equations()];
        sys.assemble(target, true)?;
        sys.factorize_tangent()?;
        // every difference below on the branch this tangent was assembled on
        sys.hold_branches(true);
        let mut dh_new = Vec::with_capacity(self.theta.len());
        for j in 0..self.theta.len() {
            let (e, a, b) = self.steps[j];
            let dh = &self.dh[j];
            // the right-hand side: the residual along (h, p) at fixed u
            let mut sides = Vec::with_capacity(2);
            for s in [a, b] {
                self.at(sys, j, s, e, set)?;
                sys.set_histories(h0, dh, s * e);
                sys.set_state(u0, &zero, 0.0);
                sys.assemble(target, false)?;
                sides.push(sys.residual().to_vec());
            }
            let w = 1.0 / ((a - b) * e);
            let mut du: Vec<f64> = sides[0]
                .iter()
                .zip(&sides[1])
                .map(|(p, m)| -(p - m) * w)
                .collect();
            sys.solve_factored(&mut du)?;
            // the outputs and the new history along (u, h, p)
            let mut outs = Vec::with_capacity(2);
            let mut hists = Vec::with_capacity(2);
            for s in [a, b] {
                self.at(sys, j, s, e, set)?;
                sys.set_histories(h0, dh, s * e);
                sys.set_state(u0, &du, s * e);
                sys.assemble(target, false)?;
                outs.push(observe(sys));
                sys.commit_contributions(target);
                hists.push(sys.histories());
            }
            self.outputs[j] = outs[0]
                .iter()
                .zip(&outs[1])
                .map(|(p, m)| (p - m) * w)
                .collect();
            dh_new.push(
                hists[0]
                    .iter()
                    .zip(&hists[1])
                    .map(|(hp, hm)| hp.iter().zip(hm).map(|(p, m)| (p - m) * w).collect())
                    .collect(),
            );
        }
        self.dh = dh_new;
        sys.hold_branches(false);
        set(sys, &self.theta)?;
        sys.set_histories(h0, h0, 0.0);
        sys.set_state(u0, &zero, 0.0);
        sys.assemble(target, false)?;
        Ok(())
    }

    /// Sets the parameters `theta + s e` along parameter `j`.
    fn at(
        &self,
        sys: &mut System,
        j: usize,
        s: f64,
        e: f64,
        set: &mut SetParameters,
    ) -> Result<(), FeError> {
        let mut t = self.theta.clone();
        t[j] += s * e;
        set(sys, &t)
    }
}
