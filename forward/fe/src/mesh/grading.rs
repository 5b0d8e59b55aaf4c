//! Graded node spacings along one coordinate of a structured mesh.

use serde::{Deserialize, Serialize};

use crate::FeError;

/// Spacing of nodes along one side of a rectangle, measured from its fine end:
/// uniform steps `h_fine` over `fine_length`, then steps growing by the factor
/// `growth` up to the full length (the graded steps are scaled slightly so the
/// last node lands exactly on the end).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Grading {
    /// Element size in the fine zone (mm).
    pub h_fine: f64,
    /// Length of the uniformly fine zone (mm).
    pub fine_length: f64,
    /// Ratio of consecutive element sizes beyond the fine zone (>= 1).
    pub growth: f64,
}

impl Grading {
    /// A uniform spacing of `n` elements over `length`.
    pub fn uniform(length: f64, n: usize) -> Self {
        Grading {
            h_fine: length / n.max(1) as f64,
            fine_length: length,
            growth: 1.0,
        }
    }

    /// Node positions from 0 (fine end) to `length`.
    pub fn positions(&self, length: f64) -> Result<Vec<f64>, FeError> {
        let bad = |reason: &str| FeError::InvalidMesh {
            field: "grading".into(),
            reason: reason.into(),
        };
        if !(length > 0.0 && length.is_finite()) {
            return Err(bad("length must be positive"));
        }
        if !(self.h_fine > 0.0 && self.h_fine.is_finite())
            || !(self.growth >= 1.0)
            || !(self.fine_length >= 0.0)
        {
            return Err(bad("need h_fine > 0, growth >= 1, fine_length >= 0"));
        }
        let fine = self.fine_length.min(length);
        let n_fine = ((fine / self.h_fine) - 1e-9)
            .ceil()
            .max(if fine > 0.0 { 1.0 } else { 0.0 }) as usize;
        let mut pos: Vec<f64> = (0..=n_fine)
            .map(|i| fine * i as f64 / n_fine.max(1) as f64)
            .collect();
        if n_fine == 0 {
            pos = vec![0.0];
        }
        let rest = length - fine;
        if rest > 1e-12 * length {
            let h0 = if n_fine > 0 {
                fine / n_fine as f64
            } else {
                self.h_fine
            };
            let mut sizes = Vec::new();
            let mut h = h0 * self.growth;
            let mut sum = 0.0;
            while sum < rest * (1.0 - 1e-9) {
                sizes.push(h);
                sum += h;
                h *= self.growth;
                if sizes.len() > 100_000 {
                    return Err(bad("too many elements"));
                }
            }
            // Drop a tiny last step into its neighbour.
            if sizes.len() > 1 && sum - rest > 0.5 * sizes[sizes.len() - 1] {
                let last = sizes.pop().unwrap_or(0.0);
                sum -= last;
            }
            let scale = rest / sum;
            let mut x = fine;
            for s in sizes {
                x += s * scale;
                pos.push(x);
            }
            if let Some(last) = pos.last_mut() {
                *last = length;
            }
        }
        Ok(pos)
    }
}

/// The node positions `xs` (increasing) with each interval split into
/// equal parts no longer than the local size `h_min + slope * dist`,
/// `dist` the interval's distance from `centre` (0 for the interval that
/// holds it): a band graded towards `centre` (a punch edge), from `h_min`
/// there growing by about `1 + slope` per element until it meets the
/// spacing of `xs`, which it never coarsens.
pub fn refine_towards(xs: &[f64], centre: f64, h_min: f64, slope: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(xs.len());
    if let Some(&first) = xs.first() {
        out.push(first);
    }
    for w in xs.windows(2) {
        let (a, b) = (w[0], w[1]);
        let dist = if centre < a {
            a - centre
        } else if centre > b {
            centre - b
        } else {
            0.0
        };
        let h = h_min + slope * dist;
        let n = if h > 0.0 && h.is_finite() {
            (((b - a) / h) - 1e-9).ceil().max(1.0) as usize
        } else {
            1
        };
        for k in 1..n {
            out.push(a + (b - a) * k as f64 / n as f64);
        }
        out.push(b);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refinement_towards_a_point_is_fine_there_and_keeps_the_nodes() {
        let xs: Vec<f64> = (0..=20).map(|k| 0.1 * k as f64).collect();
        let r = refine_towards(&xs, 1.0, 0.01, 0.5);
        for x in &xs {
            assert!(r.iter().any(|y| (y - x).abs() < 1e-12), "{x} kept");
        }
        assert!(r.windows(2).all(|w| w[1] > w[0]));
        // elements of 0.01 on both sides of 1.0, coarser away from it
        let at = |x: f64| {
            r.windows(2)
                .find(|w| w[0] <= x && x < w[1])
                .map(|w| w[1] - w[0])
                .unwrap()
        };
        assert!((at(0.995) - 0.01).abs() < 1e-9, "{}", at(0.995));
        assert!((at(1.005) - 0.01).abs() < 1e-9, "{}", at(1.005));
        assert!(at(1.15) > 0.04 && at(1.15) <= 0.1, "{}", at(1.15));
        assert!((at(1.85) - 0.1).abs() < 1e-9);
        // a centre outside leaves the far intervals alone
        assert_eq!(refine_towards(&xs, 10.0, 0.01, 0.5), xs);
    }

    #[test]
    fn grading_covers_the_length_and_grows() {
        let g = Grading {
            h_fine: 0.25,
            fine_length: 5.0,
            growth: 1.2,
        };
        let p = g.positions(35.0).unwrap();
        assert_eq!(p[0], 0.0);
        assert_eq!(*p.last().unwrap(), 35.0);
        assert!((p[1] - 0.25).abs() < 1e-12);
        assert!((p[20] - 5.0).abs() < 1e-12);
        for w in p.windows(3).skip(20) {
            assert!(w[2] - w[1] >= w[1] - w[0] - 1e-12);
        }
        let u = Grading::uniform(9.0, 9).positions(9.0).unwrap();
        assert_eq!(u.len(), 10);
        assert!(Grading {
            h_fine: 0.0,
            fine_length: 1.0,
            growth: 1.0
        }
        .positions(1.0)
        .is_err());
    }
}
