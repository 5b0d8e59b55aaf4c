//! What a step sums: solid bodies and rigid-tool contact sets, each adding
//! its residual and tangent to one global system, each with its own history
//! under a trial / commit / rollback protocol.
//!
//! A contribution only ever *reads* its committed history during
//! [`Contribution::assemble`] and writes trial history; [`Contribution::commit`]
//! accepts the trial state of a converged increment and
//! [`Contribution::rollback`] forgets everything since the last commit
//! (including the multipliers of augmentations), so that a cut increment
//! is retried from exactly the state a run that never failed would have.

use crate::dofs::DofMap;
use crate::sparse::{Pattern, NONE};
use crate::FeError;

/// The state a contribution is assembled at.
pub struct AssemblyContext<'a> {
    /// The global state (node displacements, then owned unknowns).
    pub u: &'a [f64],
    /// Reference node coordinates.
    pub x0: &'a [[f64; 3]],
    /// Values of the loading channels at the end of the increment.
    pub channels: &'a [f64],
    /// Values of the loading channels at the last commit.
    pub channels_committed: &'a [f64],
    /// Physical time at the end of the increment and its increment (s;
    /// zero for rate-independent histories).
    pub time: f64,
    pub dt: f64,
    pub dofs: &'a DofMap,
}

impl AssemblyContext<'_> {
    /// Current position of node `n`.
    #[inline]
    pub fn position(&self, n: usize) -> [f64; 3] {
        let d = self.dofs.dim;
        let mut x = self.x0[n];
        for c in 0..d {
            x[c] += self.u[n * d + c];
        }
        x
    }

    /// Displacement of node `n` (unused components zero).
    #[inline]
    pub fn displacement(&self, n: usize) -> [f64; 3] {
        let d = self.dofs.dim;
        let mut u = [0.0; 3];
        for c in 0..d {
            u[c] = self.u[n * d + c];
        }
        u
    }
}

/// Where contributions add their residual and tangent.
pub struct Assembly<'a> {
    /// Internal force per state entry (prescribed entries included: their
    /// sum is the reaction).
    pub fint: &'a mut [f64],
    /// Values of the global sparse tangent (when assembling it).
    pub values: Option<&'a mut [f64]>,
    /// The pattern and the first of this contribution's coupling groups.
    pub pattern: &'a Pattern,
    pub first_group: usize,
    pub dofs: &'a DofMap,
    /// Sum of squared forces that set the scale of the residual test
    /// (contact forces; the system adds reactions of prescribed entries).
    pub force_scale2: f64,
}

impl Assembly<'_> {
    /// Adds the dense row-major local tangent `k` of this contribution's
    /// coupling group `group` (its state entries as given by
    /// [`Contribution::couplings`]).
    #[inline]
    pub fn add_group(&mut self, group: usize, k: &[f64]) {
        let Some(values) = self.values.as_deref_mut() else {
            return;
        };
        let slots = &self.pattern.slots[self.first_group + group];
        for (s, v) in slots.iter().zip(k) {
            if *s != NONE {
                values[*s] += v;
            }
        }
    }

    /// Adds `v` at (state entry `r`, state entry `c`) if both are unknowns
    /// and the pattern has the pair (it does for entries of one group).
    #[inline]
    pub fn add_entry(&mut self, r: usize, c: usize, v: f64) {
        let (er, ec) = (self.dofs.equation(r), self.dofs.equation(c));
        if er == NONE || ec == NONE {
            return;
        }
        if let (Some(values), Some(s)) = (self.values.as_deref_mut(), self.pattern.slot(er, ec)) {
            values[s] += v;
        }
    }
}

/// One term of the global residual and tangent.
pub trait Contribution: Send + std::any::Any {
    /// A name for messages (`body`, `needle contact`).
    fn name(&self) -> String;
    /// For typed access by the model that built the system (materials,
    /// penalties set per run).
    fn as_any(&self) -> &dyn std::any::Any;
    /// Mutable typed access.
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any;
    /// Unknowns this contribution owns beyond the node displacements.
    fn unknowns(&self) -> usize {
        0
    }
    /// The state index of the first owned unknown (called once, before
    /// [`Contribution::couplings`]).
    fn bind(&mut self, _first: usize) {}
    /// The loading channels this contribution follows (a tool's motion);
    /// [`crate::system::System::new`] refuses a channel that no boundary
    /// condition and no contribution uses.
    fn channels(&self) -> Vec<usize> {
        Vec::new()
    }
    /// Groups of state entries that the tangent couples (one per element
    /// or contact facet) for a state with `dim` components per node, for
    /// the sparsity pattern; their order is the order of
    /// [`Assembly::add_group`].
    fn couplings(&self, dim: usize) -> Vec<Vec<usize>>;
    /// Adds the residual and (when `out.values` is set) the tangent.
    fn assemble(&mut self, ctx: &AssemblyContext, out: &mut Assembly) -> Result<(), FeError>;
    /// Between Newton solves of one increment: update multipliers
    /// (augmented Lagrangian); true when something changed and Newton must
    /// run again.
    fn augment(&mut self) -> bool {
        false
    }
    /// Accepts the trial history of a converged increment.
    fn commit(&mut self, ctx: &AssemblyContext);
    /// Restores the history of the last commit.
    fn rollback(&mut self);
    /// Forgets all history (a new loading history starts at the reference state).
    fn reset(&mut self, x0: &[[f64; 3]]);
    /// The committed history as numbers (material internal variables,
    /// stick points, multipliers), for the direct differentiation of a run
    /// ([`crate::sensitivity`]), which carries their derivatives from
    /// increment to increment. A discrete part (in contact or not) is
    /// stored as 0 or 1 and read back as `> 0.5`. Default: none (a
    /// contribution whose residual depends on nothing committed).
    fn history(&self) -> Vec<f64> {
        Vec::new()
    }
    /// Replaces the committed history by `h` (as [`Contribution::history`]
    /// returned it, possibly perturbed); the trial state follows at the
    /// next assembly.
    fn set_history(&mut self, _h: &[f64]) {}
    /// Holds (`true`) the discrete state the last assembly found (a contact
    /// point touching or clear, sticking or sliding) in every later
    /// assembly, each piece's law extended beyond its switch, until released
    /// (`false`): the direct differentiation of a run
    /// ([`crate::sensitivity`]) takes its differences about the converged
    /// state on the branch that state's tangent was assembled on. Default:
    /// nothing to hold.
    fn hold_branches(&mut self, _hold: bool) {}
    /// Force the tool exerts on the body along `axis` at the last assembly
    /// (N; minus the body's reaction on the tool): a tool pressed down
    /// reports its compression force on `axis = -y`, and a tool dragging the
    /// surface along `+x` a positive force on `+x`. `None` for
    /// contributions without a tool.
    fn tool_force(&self, _axis: [f64; 3]) -> Option<f64> {
        None
    }
}
