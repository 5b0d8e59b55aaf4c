//! Predictors of the state at the start of an increment, from the converged
//! state, that a model can install on its [`crate::System`]
//! ([`crate::System::predictor`]) in place of the stepper's own secant
//! extrapolation (the previous increment's change scaled to the new size).
//!
//! [`FollowTool`]: a tool sliding along a fixed direction over a body that
//! is (nearly) invariant along it (R2's frictionless wheel rolling along a
//! block) carries its deformation field with it. In the tool's frame the
//! field `w(xi; s) = u(xi + s e; s)` (tool travel `s` along `e`) changes
//! only through what is not invariant (nodules, block ends), so the field
//! at the new travel is predicted in that frame and mapped back:
//!
//! ```text
//! order 0:  u_new(X) = u_c(X - (s_new - s_c) e)
//! order 1:  u_new(X) = (1 + r) u_c(X - (s_new - s_c) e) - r u_p(X - (s_new - s_p) e),
//!           r = (s_new - s_c) / (s_c - s_p)
//! ```
//!
//! (`c` the last converged state, `p` the one before, at the same values
//! of the other channels; order 1 is the secant in the tool's frame). The
//! fields at the shifted points are interpolated through their cells
//! ([`crate::mesh::Locator`]; the weights are cached per shift, so a pass
//! of equal steps locates its points once). A node whose shifted point
//! falls outside the body keeps its converged displacement. The stepper's
//! secant is the same prediction to first order in the step with the
//! derivative taken in the body's frame, where a moving contact edge
//! makes the field change fastest; see docs/validation/fe.md (R2 speed).

use crate::mesh::{Interpolant, Locator, Mesh};

/// A predictor of the state of an increment.
pub trait Predictor: Send {
    /// Writes the predicted state for an increment from channel values
    /// `from` (the converged state `u_c`) to `to` into `u` (which holds
    /// the stepper's own prediction on entry: `u_c`, or its secant
    /// extrapolation; prescribed entries are set by the system afterwards).
    /// `false` when it does not apply to this increment (the stepper then
    /// uses its secant).
    fn predict(
        &mut self,
        mesh: &Mesh,
        dim: usize,
        from: &[f64],
        to: &[f64],
        u_c: &[f64],
        u: &mut [f64],
    ) -> bool;
    /// Forgets the history of a loading history (a new one starts).
    fn reset(&mut self) {}
}

/// The deformation field travels with a tool sliding along `direction` by
/// loading channel `channel` (see the [module docs](self)).
pub struct FollowTool {
    pub channel: usize,
    /// Unit direction of the travel (in the mesh's frame).
    pub direction: [f64; 3],
    /// 0: the converged field shifted; 1: the secant in the tool's frame.
    pub order: usize,
    /// Per node, the weight `w` of this prediction against the stepper's
    /// own (`u = w u_follow + (1 - w) u_stepper`): 0 where the body is not
    /// invariant along the travel (a stiff inclusion fixed in the body,
    /// whose near-rigid motion the shift would smear into the soft
    /// matrix). `None`: 1 everywhere.
    pub weights: Option<Vec<f64>>,
    /// The last two converged states seen: channel values and state.
    history: Vec<(Vec<f64>, Vec<f64>)>,
    /// Interpolants of every node's shifted point, per shift (bits of the
    /// shift), most recent last.
    cache: Vec<(u64, Vec<Option<Interpolant>>)>,
}

/// Shifts whose interpolants are kept.
const CACHED_SHIFTS: usize = 6;

impl FollowTool {
    pub fn new(channel: usize, direction: [f64; 3], order: usize) -> FollowTool {
        FollowTool {
            channel,
            direction,
            order,
            weights: None,
            history: Vec::new(),
            cache: Vec::new(),
        }
    }

    /// Makes the interpolants at every node's point shifted by `-shift *
    /// direction` the most recent cache entry (located on a miss); `false`
    /// when the mesh cannot be searched.
    fn ensure(&mut self, mesh: &Mesh, shift: f64) -> bool {
        let key = shift.to_bits();
        if let Some(k) = self.cache.iter().position(|(s, _)| *s == key) {
            let hit = self.cache.remove(k);
            self.cache.push(hit);
            return true;
        }
        let Ok(loc) = Locator::new(mesh) else {
            return false;
        };
        let e = self.direction;
        let w: Vec<Option<Interpolant>> = mesh
            .nodes
            .iter()
            .map(|x| loc.locate([x[0] - shift * e[0], x[1] - shift * e[1]], 1e-9))
            .collect();
        if self.cache.len() == CACHED_SHIFTS {
            self.cache.remove(0);
        }
        self.cache.push((key, w));
        true
    }

    /// The cached interpolants of `shift` (after [`FollowTool::ensure`]).
    fn cached(&self, shift: f64) -> Option<&[Option<Interpolant>]> {
        let key = shift.to_bits();
        self.cache
            .iter()
            .find(|(s, _)| *s == key)
            .map(|(_, w)| w.as_slice())
    }

    /// Whether `a` and `b` agree on every channel but the tool's.
    fn same_other_channels(&self, a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .enumerate()
                .all(|(c, (x, y))| c == self.channel || x == y)
    }
}

impl Predictor for FollowTool {
    fn predict(
        &mut self,
        mesh: &Mesh,
        dim: usize,
        from: &[f64],
        to: &[f64],
        u_c: &[f64],
        u: &mut [f64],
    ) -> bool {
        // remember the converged states (a retried increment starts from
        // the same one)
        if self
            .history
            .last()
            .is_none_or(|(ch, _)| ch.as_slice() != from)
        {
            if self.history.len() == 2 {
                self.history.remove(0);
            }
            self.history.push((from.to_vec(), u_c.to_vec()));
        }
        let c = self.channel;
        if mesh.dim != 2
            || dim != 2
            || c >= from.len()
            || !self.same_other_channels(from, to)
            || !(to[c] > from[c])
        {
            return false;
        }
        let d1 = to[c] - from[c];
        // the state before, along the same travel
        let previous = match (self.order, self.history.len()) {
            (1, 2) => {
                let (ch, up) = &self.history[0];
                (self.same_other_channels(ch, from) && ch[c] < from[c]).then(|| {
                    (
                        to[c] - ch[c],
                        (to[c] - from[c]) / (from[c] - ch[c]),
                        up.clone(),
                    )
                })
            }
            _ => None,
        };
        if !self.ensure(mesh, d1) {
            return false;
        }
        // (ensuring d2 after d1 cannot evict d1, the most recent entry)
        let previous = previous.filter(|(d2, _, _)| self.ensure(mesh, *d2));
        let Some(w1) = self.cached(d1) else {
            return false;
        };
        let second = previous
            .as_ref()
            .and_then(|(d2, r, up)| self.cached(*d2).map(|w2| (w2, *r, up)));
        for n in 0..mesh.nodes.len() {
            let Some(i1) = &w1[n] else { continue };
            let wn = self.weights.as_ref().map_or(1.0, |w| w[n]);
            if wn == 0.0 {
                continue;
            }
            for comp in 0..dim {
                let a = i1.apply(mesh, |m| u_c[m * dim + comp]);
                let follow = match &second {
                    Some((w2, r, up)) => match &w2[n] {
                        Some(i2) => {
                            let b = i2.apply(mesh, |m| up[m * dim + comp]);
                            (1.0 + r) * a - r * b
                        }
                        None => a,
                    },
                    None => a,
                };
                let k = n * dim + comp;
                u[k] = wn * follow + (1.0 - wn) * u[k];
            }
        }
        true
    }

    fn reset(&mut self) {
        self.history.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rectangular 9-node cells (non-uniform columns, so a shift never maps
    /// nodes onto nodes): a quadratic field is in the element space and is
    /// interpolated exactly anywhere.
    fn mesh() -> Mesh {
        let xs: Vec<f64> = (0..=12)
            .map(|i| 2.0 * i as f64 + 0.1 * (i % 3) as f64)
            .collect();
        let ys = [0.0, 2.0, 3.5, 5.0, 6.0];
        Mesh::tensor(&xs, &ys).to_quadratic().unwrap()
    }

    /// A translating field with a part that changes linearly with the
    /// travel in the tool's frame: `u(X; s) = g(X - s e) + s h(X - s e)`,
    /// `g`, `h` quadratic.
    fn field(mesh: &Mesh, s: f64) -> Vec<f64> {
        let mut u = vec![0.0; 2 * mesh.nodes.len()];
        for (n, x) in mesh.nodes.iter().enumerate() {
            let (a, b) = (x[0] - s, x[1]);
            u[2 * n] = 0.01 * a * a - 0.02 * a * b + 0.1 + s * (0.003 * a - 0.001 * b * b);
            u[2 * n + 1] = -0.005 * b * b + 0.01 * a + s * 0.002 * a * b;
        }
        u
    }

    /// Order 0 carries the converged field along exactly where there is no
    /// change in the tool's frame; order 1 (after two converged states of
    /// unequal steps) also follows the frame's linear change; nodes whose
    /// shifted point lies outside keep their converged value; an increment
    /// that changes another channel is left to the stepper.
    #[test]
    fn follow_tool_predicts_a_translating_field() {
        let m = mesh();
        let inside = |x: &[f64; 3], d: f64| x[0] - d >= 0.0;
        for order in [0, 1] {
            let mut p = FollowTool::new(1, [1.0, 0.0, 0.0], order);
            let states = [1.0, 1.5, 2.3];
            let mut u = Vec::new();
            for k in 0..states.len() - 1 {
                let (s_c, s_new) = (states[k], states[k + 1]);
                let u_c = field(&m, s_c);
                u = u_c.clone();
                assert!(p.predict(&m, 2, &[3.0, s_c], &[3.0, s_new], &u_c, &mut u));
                let exact = field(&m, s_new);
                let shifted: Vec<f64> = (0..u.len())
                    .map(|i| {
                        let (n, c) = (i / 2, i % 2);
                        let x = m.nodes[n];
                        // g and h at the point the field comes from
                        let (a, b) = (x[0] - s_new, x[1]);
                        let frame = if c == 0 {
                            0.003 * a - 0.001 * b * b
                        } else {
                            0.002 * a * b
                        };
                        exact[i] - (s_new - s_c) * frame
                    })
                    .collect();
                // order 1 is exact from the second increment on
                let want = if order == 1 && k == 1 {
                    &exact
                } else {
                    &shifted
                };
                for (n, x) in m.nodes.iter().enumerate() {
                    for c in 0..2 {
                        let i = 2 * n + c;
                        let d = s_new - s_c;
                        if inside(x, d)
                            && (order == 0 || k == 0 || inside(x, s_new - states[k - 1]))
                        {
                            assert!(
                                (u[i] - want[i]).abs() < 1e-9,
                                "order {order} k {k} node {n}: {} vs {}",
                                u[i],
                                want[i]
                            );
                        } else if !inside(x, d) {
                            assert_eq!(u[i], u_c[i]);
                        }
                    }
                }
            }
            assert!(!u.is_empty());
            // another channel moves: not applicable
            let u_c = field(&m, 2.3);
            let mut v = u_c.clone();
            assert!(!p.predict(&m, 2, &[3.0, 2.3], &[3.5, 2.8], &u_c, &mut v));
            assert_eq!(v, u_c);
        }
    }
}
