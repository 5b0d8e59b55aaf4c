//! Depth histories for the real-time model: piecewise-linear
//! punch depth against time, sampled at a fixed step, with the FE stations
//! of each segment; and the seeded random histories (ramps, holds,
//! unloadings) its builds train on and are checked against.

/// A random depth history inside `[0, depth_max]`: from rest, segments of
/// ramps (up or down, to a uniform depth, at 0.2..4 mm/s), holds (0.2..3
/// s) and full unloadings, `segments` of them, sampled every `dt`; the
/// segment ends are returned too (the stations an FE run needs).
pub fn random_history(seed: u64, depth_max: f64, segments: usize, dt: f64) -> History {
    // splitmix64: reproducible without a dependency on a generator crate
    let mut state = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut u = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut knots = vec![(0.0, 0.0)];
    let (mut t, mut d) = (0.0, 0.0);
    for k in 0..segments {
        let r = u();
        let target = if k == 0 {
            depth_max * (0.5 + 0.5 * u())
        } else if r < 0.35 {
            d
        } else if r < 0.5 {
            0.0
        } else {
            depth_max * u()
        };
        let duration = if target == d {
            0.2 + 2.8 * u()
        } else {
            (target - d).abs() / (0.2 + 3.8 * u())
        };
        t += duration.max(dt);
        d = target;
        knots.push((t, d));
    }
    let mut h = History::from_knots(knots, dt);
    h.depth
        .iter_mut()
        .for_each(|d| *d = d.clamp(0.0, depth_max));
    h
}

/// A depth history: its segment ends `(time, depth)` and its samples.
#[derive(Debug, Clone, PartialEq)]
pub struct History {
    pub knots: Vec<(f64, f64)>,
    pub time: Vec<f64>,
    pub depth: Vec<f64>,
}

impl History {
    /// The piecewise-linear history through `knots` `(time_s, depth_mm)`
    /// (from `(0, 0)`, times increasing), sampled every `dt` from `dt`.
    pub fn from_knots(knots: Vec<(f64, f64)>, dt: f64) -> History {
        let t = knots.last().map_or(0.0, |k| k.0);
        let n = (t / dt).round() as usize;
        let time: Vec<f64> = (1..=n).map(|k| k as f64 * dt).collect();
        let depth = time
            .iter()
            .map(|&s| {
                let j = knots
                    .partition_point(|k| k.0 <= s)
                    .clamp(1, knots.len() - 1);
                let (a, b) = (knots[j - 1], knots[j]);
                a.1 + (b.1 - a.1) * ((s - a.0) / (b.0 - a.0)).clamp(0.0, 1.0)
            })
            .collect();
        History { knots, time, depth }
    }

    /// The FE stations of the history `(times, depths)`: each segment's end
    /// and `ramp` (`hold`) equally spaced points inside each ramp (hold).
    pub fn stations(&self, ramp: usize, hold: usize) -> (Vec<f64>, Vec<f64>) {
        let mut st = Vec::new();
        for w in self.knots.windows(2) {
            let ((ta, da), (tb, db)) = (w[0], w[1]);
            let inner = if da == db { hold } else { ramp };
            for j in 1..=inner + 1 {
                let s = j as f64 / (inner + 1) as f64;
                st.push((ta + s * (tb - ta), da + s * (db - da)));
            }
        }
        st.into_iter().unzip()
    }

    /// The index of the 1 kHz-style sample at time `t` (the nearest sample
    /// time `k dt`, at least the first).
    pub fn sample_at(&self, t: f64) -> usize {
        let dt = self.time.first().copied().unwrap_or(1.0);
        ((t / dt).round() as usize).clamp(1, self.time.len().max(1)) - 1
    }
}
