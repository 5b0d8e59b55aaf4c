//! A real-time surrogate of an indentation force response (BENCHMARKS.md
// Negated comparisons (`!(x > 0.0)`) deliberately treat NaN as failure.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
//! Q1, N1 with `--prony`): the force for an arbitrary depth history, sample
//! by sample, fast enough for haptic rendering at 1 kHz and more (issue 13).
//!
//! Why here: this module family (`palpate_uq::surrogate`) is where reduced
//! models of FE responses live; like the parametric surrogate of
//! [`super::model`], it is built from runs of any
//! [`palpate_core::ForwardModel`] (the FE models behind the trait) and needs
//! no FE code, so it sits beside it rather than in `palpate-fe`. The two
//! answer different questions: [`super::Surrogate`] maps parameters to the
//! force on one fixed history (for posteriors), [`RealTimeSurrogate`] maps a
//! depth history to the force at fixed parameters (for rendering).
//!
//! # Model
//!
//! Quasi-linear viscoelasticity on the force (Fung 1993, ch. 7), with the
//! elastic force curve `F_e(d)` of the FE model (a monotone cubic through an
//! elastic FE ramp, [`MonotoneCubic`]) and the relaxation function
//! `G(t) = g_inf + sum_i g_i exp(-t / tau_i)`:
//!
//! ```text
//! F(t) = g_inf F_e(d(t)) + sum_i g_i h_i(t),
//! h_i(n+1) = e_i h_i(n) + phi_i (F_e(n+1) - F_e(n)),  e_i = exp(-dt / tau_i),
//! phi_i = (1 - e_i) / (dt / tau_i),
//! ```
//!
//! the recursive update exact for `F_e` linear in time over a step (Taylor,
//! Pister & Goudreau 1970; `palpate_enrich::qlv_convolve`), O(terms) per
//! sample. For the flat punch under displacement control it is exact in the
//! linear range (correspondence principle: `F = 8 a int G(t - s) dG d`);
//! at finite depth the FE material (Prony series on the isochoric second
//! Piola-Kirchhoff stress) differs from it: within 2 % of the peak for Q1
//! to 0.8 mm, 5-12 % for the rounded Q1 punch to 4 mm and 4-14 % for the
//! N1 needle to 10 mm (docs/guide.md).
//!
//! So a build with training histories (`RealTimeRequest::training_histories`)
//! replaces QLV's memory by a fitted one ([`super::memory_kernel`]): the
//! memory read through the present depth, its coefficients from FE runs by
//! least squares, the same recursion. Held-out errors (docs/guide.md): Q1
//! within 1.1 % to 4 mm (the 1 mm edge), N1 within 1.6 % to 4 mm and up to
//! 3.5 % (frictionless) or 4.5 % (friction 0.8, to 7 mm) deeper.
//!
//! Loss of contact: a punch withdrawn faster than the tissue recovers
//! leaves it; the force cannot pull (`F >= 0`). When the trial force of a
//! step is negative, the tissue surface is free: its elastic force
//! `F_s` solves `F = 0`,
//! `F_s = sum_i g_i (phi_i F_e(n) - e_i h_i(n)) / (g_inf + sum_i g_i phi_i)`,
//! the history advances with `F_s` instead of `F_e(d)` and the answer is 0;
//! contact resumes at the first step whose trial force is >= 0 (the punch
//! has caught up with the recovering surface).
//!
//! Range: depths in `[0, depth_max]` of the elastic FE ramp, `dt >= 0`;
//! anything else is refused ([`RangeError`]), never extrapolated.

use serde::{Deserialize, Serialize};

use super::memory_kernel::{MemoryKernel, TrainingRun};

/// A monotone piecewise-cubic Hermite interpolant (Fritsch & Carlson 1980,
/// SIAM J. Numer. Anal. 17, 238; the slopes of Fritsch & Butland 1984, as
/// scipy's `PchipInterpolator`): no overshoot between the FE samples, so
/// the elastic force stays monotone in depth and its inverse (loss of
/// contact) is defined. Hand-written (30 lines): the workspace has no
/// interpolation crate and the evaluation must not allocate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MonotoneCubic {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub slope: Vec<f64>,
}

impl MonotoneCubic {
    /// Through `(x_k, y_k)`, `x` strictly increasing, at least 2 points.
    pub fn new(x: Vec<f64>, y: Vec<f64>) -> Result<Self, String> {
        let n = x.len();
        if n < 2 || y.len() != n {
            return Err(format!(
                "{n} depths and {} forces: need at least 2 of each",
                y.len()
            ));
        }
        if let Some(k) = (1..n).find(|&k| !(x[k] > x[k - 1])) {
            return Err(format!("depth {} at sample {k} does not increase", x[k]));
        }
        let h: Vec<f64> = (0..n - 1).map(|k| x[k + 1] - x[k]).collect();
        let del: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / h[k]).collect();
        let mut m = vec![0.0; n];
        if n == 2 {
            m = vec![del[0]; 2];
        } else {
            for k in 1..n - 1 {
                if del[k - 1] * del[k] > 0.0 {
                    let (w1, w2) = (2.0 * h[k] + h[k - 1], h[k] + 2.0 * h[k - 1]);
                    m[k] = (w1 + w2) / (w1 / del[k - 1] + w2 / del[k]);
                }
            }
            let end = |h0: f64, h1: f64, d0: f64, d1: f64| {
                let s = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
                if s * d0 <= 0.0 {
                    0.0
                } else if d0 * d1 <= 0.0 && s.abs() > 3.0 * d0.abs() {
                    3.0 * d0
                } else {
                    s
                }
            };
            m[0] = end(h[0], h[1], del[0], del[1]);
            m[n - 1] = end(h[n - 2], h[n - 3], del[n - 2], del[n - 3]);
        }
        Ok(MonotoneCubic { x, y, slope: m })
    }

    /// The value at `t` in `[x_0, x_n]` (clamped to the ends outside).
    pub fn eval(&self, t: f64) -> f64 {
        let n = self.x.len();
        let k = self.x.partition_point(|&v| v <= t).clamp(1, n - 1) - 1;
        let h = self.x[k + 1] - self.x[k];
        let s = ((t - self.x[k]) / h).clamp(0.0, 1.0);
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * self.y[k]
            + (s3 - 2.0 * s2 + s) * h * self.slope[k]
            + (-2.0 * s3 + 3.0 * s2) * self.y[k + 1]
            + (s3 - s2) * h * self.slope[k + 1]
    }
}

/// A query the surrogate refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RangeError {
    #[error("depth {depth} mm is outside the surrogate's trained range [0, {max}] mm (it does not extrapolate; rebuild it with a larger --depth-max)")]
    Depth { depth: f64, max: f64 },
    #[error("time step {dt} s: must be finite and >= 0")]
    TimeStep { dt: f64 },
}

/// What the surrogate was checked against: per held-out FE history, the
/// largest force error relative to the history's peak force.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryError {
    pub history: String,
    pub samples: usize,
    pub peak_force_n: f64,
    pub max_abs_error_n: f64,
    pub max_relative_error: f64,
}

/// The stored surrogate and its state (the state is not stored).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RealTimeSurrogate {
    /// What it stands for (model name and parameters).
    pub model: String,
    /// Largest depth of the elastic curve (mm).
    pub depth_max: f64,
    /// The elastic force against depth.
    pub elastic: MonotoneCubic,
    /// `(g_i, tau_i)`.
    pub prony: Vec<(f64, f64)>,
    /// Held-out FE histories and the error on each.
    pub validation: Vec<HistoryError>,
    /// The fitted memory that replaces QLV's when present
    /// ([`super::memory_kernel`]); built from FE training histories.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kernel: Option<MemoryKernel>,
    /// With a kernel: plain QLV's errors on the same held-out histories.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub qlv_validation: Vec<HistoryError>,
    /// Training histories the FE model could not finish (left out of the
    /// fit), with the reason.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub training_failures: Vec<String>,
    /// Held-out histories the FE model could not finish (so not in
    /// `validation`), with the reason.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub validation_failures: Vec<String>,
    /// FE runs and wall time of the build.
    pub fe_runs: usize,
    pub build_time_s: f64,
    #[serde(skip)]
    state: State,
}

#[derive(Debug, Clone, Default)]
struct State {
    h: Vec<f64>,
    fe: f64,
    dt: f64,
    e: Vec<f64>,
    phi: Vec<f64>,
}

/// The name the issue gives it: `Surrogate::force(depth, dt)`.
pub type Surrogate = RealTimeSurrogate;

impl RealTimeSurrogate {
    /// A surrogate from its elastic curve and relaxation terms; checks the
    /// terms (`g_i >= 0`, `sum g_i < 1`, `tau_i > 0`) and the curve (depths
    /// from 0, forces not decreasing).
    pub fn new(
        model: String,
        elastic: MonotoneCubic,
        prony: Vec<(f64, f64)>,
    ) -> Result<Self, String> {
        check_prony(&prony)?;
        if elastic.x[0] != 0.0 {
            return Err(format!(
                "the elastic curve starts at {} mm, not 0",
                elastic.x[0]
            ));
        }
        if let Some(k) = (1..elastic.y.len()).find(|&k| elastic.y[k] < elastic.y[k - 1]) {
            return Err(format!(
                "the elastic force decreases at {} mm ({} N after {} N): not a loading curve",
                elastic.x[k],
                elastic.y[k],
                elastic.y[k - 1]
            ));
        }
        let depth_max = *elastic.x.last().expect("two points");
        let mut s = RealTimeSurrogate {
            model,
            depth_max,
            elastic,
            prony,
            validation: Vec::new(),
            kernel: None,
            qlv_validation: Vec::new(),
            training_failures: Vec::new(),
            validation_failures: Vec::new(),
            fe_runs: 0,
            build_time_s: 0.0,
            state: State::default(),
        };
        s.reset();
        Ok(s)
    }

    /// Back to rest (no history, the punch at the surface).
    pub fn reset(&mut self) {
        let n = self.prony.len();
        self.state = State {
            h: vec![0.0; n],
            fe: 0.0,
            dt: f64::NAN,
            e: vec![0.0; n],
            phi: vec![0.0; n],
        };
        if let Some(k) = self.kernel.as_mut() {
            k.reset();
        }
    }

    /// `g_inf = 1 - sum g_i`.
    pub fn g_inf(&self) -> f64 {
        1.0 - self.prony.iter().map(|p| p.0).sum::<f64>()
    }

    /// The force (N) at punch depth `depth` (mm) reached `dt` seconds after
    /// the previous call (the depth linear in time in between). Refuses a
    /// depth outside the trained range and a negative or non-finite `dt`;
    /// a refused call leaves the state unchanged.
    pub fn force(&mut self, depth: f64, dt: f64) -> Result<f64, RangeError> {
        if !(depth >= 0.0 && depth <= self.depth_max * (1.0 + 1e-12)) {
            return Err(RangeError::Depth {
                depth,
                max: self.depth_max,
            });
        }
        if !(dt >= 0.0 && dt.is_finite()) {
            return Err(RangeError::TimeStep { dt });
        }
        if let Some(k) = self.kernel.as_mut() {
            return Ok(k.step(depth.min(k.depth_max), dt).0);
        }
        if self.state.h.len() != self.prony.len() {
            self.reset();
        }
        let st = &mut self.state;
        if dt != st.dt {
            for (i, &(_, tau)) in self.prony.iter().enumerate() {
                let x = dt / tau;
                st.e[i] = (-x).exp();
                st.phi[i] = if x > 0.0 { -(-x).exp_m1() / x } else { 1.0 };
            }
            st.dt = dt;
        }
        let g_inf = 1.0 - self.prony.iter().map(|p| p.0).sum::<f64>();
        let fe = self.elastic.eval(depth);
        let (mut f, mut c, mut b) = (g_inf * fe, g_inf, 0.0);
        for (i, &(g, _)) in self.prony.iter().enumerate() {
            f += g * (st.e[i] * st.h[i] + st.phi[i] * (fe - st.fe));
            c += g * st.phi[i];
            b += g * (st.phi[i] * st.fe - st.e[i] * st.h[i]);
        }
        // in contact, or the free surface's elastic force making F = 0
        let (fe_new, out) = if f >= 0.0 {
            (fe, f)
        } else {
            ((b / c).max(fe), 0.0)
        };
        for i in 0..self.prony.len() {
            st.h[i] = st.e[i] * st.h[i] + st.phi[i] * (fe_new - st.fe);
        }
        st.fe = fe_new;
        Ok(out)
    }

    /// The forces of a whole history `(time_s, depth_mm)` from rest.
    pub fn run(&mut self, time: &[f64], depth: &[f64]) -> Result<Vec<f64>, (usize, RangeError)> {
        self.reset();
        let mut prev = 0.0;
        time.iter()
            .zip(depth)
            .enumerate()
            .map(|(k, (&t, &d))| {
                let dt = t - prev;
                prev = t;
                self.force(d, dt).map_err(|e| (k, e))
            })
            .collect()
    }

    /// JSON text of the stored surrogate.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a surrogate serialises")
    }

    /// Reads a stored surrogate, checked as [`RealTimeSurrogate::new`].
    pub fn from_json(text: &str) -> Result<Self, String> {
        let s: RealTimeSurrogate = serde_json::from_str(text).map_err(|e| e.to_string())?;
        let elastic = MonotoneCubic::new(s.elastic.x.clone(), s.elastic.y.clone())?;
        let mut out = RealTimeSurrogate::new(s.model, elastic, s.prony)?;
        out.validation = s.validation;
        if let Some(k) = &s.kernel {
            k.check()?;
            if k.depth_max != out.depth_max {
                return Err(format!(
                    "memory kernel on [0, {}] mm for a surrogate on [0, {}] mm",
                    k.depth_max, out.depth_max
                ));
            }
        }
        out.kernel = s.kernel;
        out.qlv_validation = s.qlv_validation;
        out.training_failures = s.training_failures;
        out.validation_failures = s.validation_failures;
        out.reset();
        out.fe_runs = s.fe_runs;
        out.build_time_s = s.build_time_s;
        Ok(out)
    }
}

fn check_prony(prony: &[(f64, f64)]) -> Result<(), String> {
    for (i, &(g, tau)) in prony.iter().enumerate() {
        if !(g >= 0.0 && g.is_finite()) {
            return Err(format!("g{} = {g}: must be >= 0", i + 1));
        }
        if !(tau > 0.0 && tau.is_finite()) {
            return Err(format!(
                "tau{} = {tau} s: must be positive and finite",
                i + 1
            ));
        }
    }
    let sum: f64 = prony.iter().map(|p| p.0).sum();
    if !(sum < 1.0) {
        return Err(format!(
            "the weights sum to {sum}; they must sum to less than 1"
        ));
    }
    Ok(())
}

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

/// What a build runs: the elastic and viscoelastic forms of one model (the
/// same FE model without and with its Prony series), their parameters, the
/// trained depth range and the held-out histories.
pub struct RealTimeRequest<'a> {
    pub elastic: &'a dyn palpate_core::ForwardModel,
    pub elastic_theta: &'a [f64],
    pub viscoelastic: &'a dyn palpate_core::ForwardModel,
    pub viscoelastic_theta: &'a [f64],
    /// The material's Prony terms (the surrogate's relaxation terms).
    pub prony: Vec<(f64, f64)>,
    pub depth_max: f64,
    /// Samples of the elastic ramp 0..depth_max.
    pub knots: usize,
    /// Held-out random histories ([`random_history`], seeds 1..=n) run by
    /// the FE model and compared.
    pub validation_histories: usize,
    /// Segments per held-out history.
    pub segments: usize,
    /// FE training histories for the memory kernel
    /// ([`super::memory_kernel`]): a ramp to `depth_max` in 1 s held 20 s,
    /// then random histories of seeds 1001.. (never a held-out seed); 0
    /// (or fewer than 5): QLV with the material's terms, nothing fitted.
    pub training_histories: usize,
    /// Hat functions of the kernel on `[0, depth_max]`.
    pub kernel_knots: usize,
}

impl RealTimeSurrogate {
    /// Builds the surrogate: one elastic FE ramp (the curve), then the
    /// held-out FE histories in parallel, each compared with the surrogate
    /// run at 1 kHz along the same piecewise-linear depth history (the
    /// error at the FE stations, relative to the history's peak FE force).
    /// `tick(done, total)` reports FE runs.
    pub fn build(
        req: &RealTimeRequest<'_>,
        tick: Option<&(dyn Fn(usize, usize) + Sync)>,
    ) -> Result<RealTimeSurrogate, String> {
        use palpate_core::{Drive, Loading};
        use rayon::prelude::*;
        let t0 = std::time::Instant::now();
        let total = 1
            + req.validation_histories
            + if req.training_histories >= 5 {
                req.training_histories
            } else {
                0
            };
        if !(req.depth_max > 0.0 && req.depth_max.is_finite()) || req.knots < 2 {
            return Err(format!(
                "depth range {} mm with {} samples: need a depth > 0 and at least 2 samples",
                req.depth_max, req.knots
            ));
        }
        let x: Vec<f64> = (0..=req.knots)
            .map(|k| req.depth_max * k as f64 / req.knots as f64)
            .collect();
        let f = req
            .elastic
            .predict(
                req.elastic_theta,
                &Loading::quasi_static(Drive::DisplacementMm, x[1..].to_vec()),
            )
            .map_err(|e| format!("the elastic FE ramp to {} mm: {e}", req.depth_max))?;
        if let Some(t) = tick {
            t(1, total);
        }
        let mut y = vec![0.0];
        y.extend(f);
        let elastic = MonotoneCubic::new(x, y)?;
        let mut s = RealTimeSurrogate::new(
            format!(
                "{} at {:?}",
                req.viscoelastic.name(),
                req.viscoelastic_theta
            ),
            elastic,
            req.prony.clone(),
        )?;
        // the FE histories, training and held-out, in one parallel batch
        let train = if req.training_histories >= 5 {
            req.training_histories
        } else {
            0
        };
        let mut jobs: Vec<(String, History, (usize, usize))> = (0..train)
            .map(|k| {
                let h = if k == 0 {
                    let d = req.depth_max;
                    History::from_knots(vec![(0.0, 0.0), (1.0, d), (21.0, d)], 1e-3)
                } else {
                    random_history(1000 + k as u64, req.depth_max, req.segments, 1e-3)
                };
                (format!("training {k}"), h, (8, 6))
            })
            .collect();
        jobs.extend((1..=req.validation_histories as u64).map(|seed| {
            (
                format!("random {seed}"),
                random_history(seed, req.depth_max, req.segments, 1e-3),
                (4, 3),
            )
        }));
        let done = std::sync::atomic::AtomicUsize::new(1);
        let fe: Vec<Result<Vec<(f64, f64)>, String>> = jobs
            .par_iter()
            .map(|(name, h, (ramp, hold))| {
                let r = fe_stations(req.viscoelastic, req.viscoelastic_theta, h, (*ramp, *hold))
                    .map_err(|e| format!("FE run of {name}: {e}"));
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if let Some(t) = tick {
                    t(n, total);
                }
                r
            })
            .collect();
        // a history the FE model cannot finish is left out and named: from
        // the fit (an error if too few are left) or from the error table (an
        // error if none is left)
        let mut failed: Vec<String> = Vec::new();
        let mut held_failed: Vec<String> = Vec::new();
        let mut fe_ok: Vec<Option<Vec<(f64, f64)>>> = Vec::with_capacity(fe.len());
        for (j, r) in fe.into_iter().enumerate() {
            match r {
                Ok(st) => fe_ok.push(Some(st)),
                Err(e) => {
                    if j < train {
                        failed.push(e);
                    } else {
                        held_failed.push(e);
                    }
                    fe_ok.push(None);
                }
            }
        }
        if req.validation_histories > 0 && held_failed.len() == req.validation_histories {
            return Err(format!(
                "no held-out FE history ran, so the surrogate cannot be checked; first: {}",
                held_failed[0]
            ));
        }
        s.validation_failures = held_failed;
        let held = (train..jobs.len())
            .filter_map(|j| fe_ok[j].as_ref().map(|st| (&jobs[j].0, &jobs[j].1, st)));
        if train > 0 {
            let runs: Vec<TrainingRun<'_>> = (0..train)
                .filter_map(|j| {
                    fe_ok[j].as_ref().map(|st| TrainingRun {
                        history: &jobs[j].1,
                        stations: st,
                    })
                })
                .collect();
            if fe_ok[0].is_none() || runs.len() < 5 {
                return Err(format!(
                    "{} of {train} FE training histories failed (the ramp and hold to {} mm {}); first: {}",
                    failed.len(),
                    req.depth_max,
                    if fe_ok[0].is_none() { "among them" } else { "ran" },
                    failed.first().map_or("", |s| s.as_str())
                ));
            }
            s.training_failures = failed;
            let taus: Vec<f64> = req.prony.iter().map(|p| p.1).collect();
            let mut qlv = s.clone();
            s.qlv_validation = held
                .clone()
                .map(|(name, h, st)| qlv.error_on(name, h, st))
                .collect::<Result<_, _>>()?;
            s.kernel = Some(MemoryKernel::fit(
                req.depth_max,
                req.kernel_knots,
                &taus,
                &runs,
            )?);
        }
        s.validation = held
            .map(|(name, h, st)| s.error_on(name, h, st))
            .collect::<Result<_, _>>()?;
        s.reset();
        s.fe_runs = total;
        s.build_time_s = t0.elapsed().as_secs_f64();
        Ok(s)
    }

    /// Runs `history` through the FE model (stations: the segment ends and
    /// 4 points inside each ramp, 3 inside each hold) and through the
    /// surrogate at its 1 kHz samples; the error at the stations.
    pub fn compare(
        &mut self,
        model: &dyn palpate_core::ForwardModel,
        theta: &[f64],
        history: &History,
        seed: u64,
    ) -> Result<HistoryError, String> {
        let st = fe_stations(model, theta, history, (4, 3))
            .map_err(|e| format!("FE run of random history {seed}: {e}"))?;
        self.error_on(&format!("random {seed}"), history, &st)
    }

    /// The surrogate's largest error at the FE `stations` `(time_s,
    /// force_n)` of `history`, run from rest at the history's samples.
    pub fn error_on(
        &mut self,
        name: &str,
        history: &History,
        stations: &[(f64, f64)],
    ) -> Result<HistoryError, String> {
        let forces = self
            .run(&history.time, &history.depth)
            .map_err(|(k, e)| format!("{name}, sample {k}: {e}"))?;
        let peak = stations.iter().map(|s| s.1).fold(0.0, f64::max);
        let worst = stations
            .iter()
            .map(|&(t, f)| (forces[history.sample_at(t)] - f).abs())
            .fold(0.0, f64::max);
        Ok(HistoryError {
            history: name.to_string(),
            samples: stations.len(),
            peak_force_n: peak,
            max_abs_error_n: worst,
            max_relative_error: worst / peak,
        })
    }
}

/// The FE force of `history` at its stations ([`History::stations`] with
/// `(ramp, hold)` inner points): `(time_s, force_n)`.
fn fe_stations(
    model: &dyn palpate_core::ForwardModel,
    theta: &[f64],
    history: &History,
    (ramp, hold): (usize, usize),
) -> Result<Vec<(f64, f64)>, String> {
    use palpate_core::{Drive, Loading};
    let (time, depth) = history.stations(ramp, hold);
    let f = model
        .predict(
            theta,
            &Loading::timed(Drive::DisplacementMm, time.clone(), depth),
        )
        .map_err(|e| e.to_string())?;
    Ok(time.into_iter().zip(f).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linear_surrogate(prony: Vec<(f64, f64)>) -> RealTimeSurrogate {
        let x: Vec<f64> = (0..=10).map(|k| 0.1 * k as f64).collect();
        let y = x.iter().map(|d| 2.0 * d).collect();
        RealTimeSurrogate::new("linear".into(), MonotoneCubic::new(x, y).unwrap(), prony).unwrap()
    }

    /// The monotone cubic interpolates, reproduces a line, and does not
    /// overshoot a step.
    #[test]
    fn monotone_cubic_interpolates_without_overshoot() {
        let x = vec![0.0, 1.0, 2.0, 3.0, 4.0];
        let line =
            MonotoneCubic::new(x.clone(), x.iter().map(|v| 3.0 * v + 1.0).collect()).unwrap();
        for t in [0.0, 0.3, 1.7, 4.0] {
            assert!((line.eval(t) - (3.0 * t + 1.0)).abs() < 1e-12);
        }
        let step = MonotoneCubic::new(x, vec![0.0, 0.0, 1.0, 1.0, 1.0]).unwrap();
        let mut prev = -1.0;
        for k in 0..=400 {
            let v = step.eval(0.01 * k as f64);
            assert!(
                (0.0..=1.0).contains(&v) && v >= prev,
                "{v} at {}",
                0.01 * k as f64
            );
            prev = v;
        }
        assert!(MonotoneCubic::new(vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
    }

    /// A step to depth d then hold: F = F_e(d) G(t) exactly.
    #[test]
    fn step_and_hold_follows_the_relaxation_function() {
        let mut s = linear_surrogate(vec![(0.3, 0.5), (0.2, 10.0)]);
        let f0 = s.force(0.5, 0.0).unwrap();
        assert!((f0 - 1.0).abs() < 1e-12);
        let mut t = 0.0;
        for _ in 0..1000 {
            let f = s.force(0.5, 0.01).unwrap();
            t += 0.01;
            let g = 0.5 + 0.3 * (-t / 0.5f64).exp() + 0.2 * (-t / 10.0f64).exp();
            assert!((f - g).abs() < 1e-10, "{f} vs {g} at {t}");
        }
    }

    /// A fast withdrawal after a long hold loses contact (force 0, never
    /// negative), and contact resumes deeper than the punch left it only
    /// after the surface has recovered towards it.
    #[test]
    fn unloading_loses_and_regains_contact() {
        let mut s = linear_surrogate(vec![(0.5, 1.0)]);
        s.force(1.0, 0.0).unwrap();
        for _ in 0..100 {
            s.force(1.0, 0.1).unwrap();
        }
        // relaxed: F = 0.5 * 2
        assert!((s.force(1.0, 0.0).unwrap() - 1.0).abs() < 1e-4);
        // instant withdrawal to 0.6 mm: QLV alone would give 1 - 0.8 < 0.2... here
        // 0.5 * 1.2 + 0.5 * (h - 0.8) with h ~ 2 e^-10 -> 0.6 - 0.4 = 0.2 >= 0
        let f = s.force(0.6, 0.0).unwrap();
        assert!((f - 0.2).abs() < 1e-3, "{f}");
        // to 0.2 mm: trial 0.2 - 0.4 - ... < 0: no contact
        assert_eq!(s.force(0.2, 0.0).unwrap(), 0.0);
        // held at 0.2 mm, the surface recovers and meets the punch again
        let mut regained = None;
        for k in 0..200 {
            let f = s.force(0.2, 0.05).unwrap();
            assert!(f >= 0.0);
            if f > 0.0 && regained.is_none() {
                regained = Some(k);
            }
        }
        assert!(regained.is_some_and(|k| k > 0));
        // relaxed at 0.2 mm again: g_inf F_e(0.2) = 0.2
        assert!((s.force(0.2, 100.0).unwrap() - 0.2).abs() < 1e-3);
    }

    /// Outside the range: refused, state untouched.
    #[test]
    fn refuses_outside_the_range() {
        let mut s = linear_surrogate(vec![(0.3, 0.5)]);
        let a = s.force(0.5, 0.1).unwrap();
        let e = s.force(1.2, 0.1).unwrap_err();
        assert!(
            e.to_string()
                .contains("outside the surrogate's trained range [0, 1] mm"),
            "{e}"
        );
        assert!(s.force(-0.1, 0.1).is_err());
        assert!(s.force(f64::NAN, 0.1).is_err());
        let e = s.force(0.5, -0.1).unwrap_err();
        assert!(e.to_string().contains("time step -0.1 s"), "{e}");
        let mut t = linear_surrogate(vec![(0.3, 0.5)]);
        t.force(0.5, 0.1).unwrap();
        assert_eq!(s.force(0.5, 0.1).unwrap(), t.force(0.5, 0.1).unwrap());
        assert!(a > 0.0);
        let bad = RealTimeSurrogate::new(
            "x".into(),
            MonotoneCubic::new(vec![0.0, 1.0], vec![0.0, 1.0]).unwrap(),
            vec![(0.6, 1.0), (0.4, 2.0)],
        )
        .unwrap_err();
        assert!(bad.contains("sum to 1"), "{bad}");
        let json = t.to_json();
        assert!(RealTimeSurrogate::from_json(&json).is_ok());
    }

    /// With a memory kernel (here QLV's own coefficients): the same answers
    /// as plain QLV, the same range checks, and the kernel survives the
    /// file; a kernel on another depth range is refused on reading.
    #[test]
    fn a_memory_kernel_answers_and_is_stored() {
        let prony = vec![(0.3, 0.5), (0.2, 10.0)];
        let mut plain = linear_surrogate(prony.clone());
        let mut with = plain.clone();
        let at_knots: Vec<f64> = (1..=10).map(|k| 0.2 * k as f64).collect();
        with.kernel = Some(MemoryKernel::qlv(1.0, &at_knots, &prony, true));
        let h = random_history(7, 1.0, 6, 1e-3);
        let a = plain.run(&h.time, &h.depth).unwrap();
        let b = with.run(&h.time, &h.depth).unwrap();
        let worst = a
            .iter()
            .zip(&b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst}");
        assert!(with.force(1.2, 0.1).is_err());
        assert!(with.force(0.5, -1.0).is_err());
        let mut back = RealTimeSurrogate::from_json(&with.to_json()).unwrap();
        assert!(back.kernel.is_some());
        assert_eq!(back.run(&h.time, &h.depth).unwrap(), b);
        let mut other = with.clone();
        other.kernel = Some(MemoryKernel::qlv(2.0, &at_knots, &prony, true));
        let e = RealTimeSurrogate::from_json(&other.to_json()).unwrap_err();
        assert!(e.contains("memory kernel on [0, 2] mm"), "{e}");
    }

    /// A tissue with a memory that QLV cannot represent, behind the forward
    /// trait: its force is a [`MemoryKernel`] (the stored stress reads 60 %
    /// stronger at the deepest present depth), run along the loading's
    /// stations joined linearly in 1 ms steps; without `viscous`, the instantaneous
    /// response (the elastic form).
    struct KernelTissue {
        truth: MemoryKernel,
        viscous: bool,
        space: palpate_core::ParamSpace,
        /// Histories whose first station is at one of these depths fail,
        /// as an FE run that stops.
        fails_on: Vec<f64>,
    }

    struct KernelTissueEval<'a>(&'a KernelTissue);

    impl palpate_core::Evaluator for KernelTissueEval<'_> {
        fn predict_into(
            &mut self,
            _theta: &[f64],
            loading: &palpate_core::Loading,
            out: &mut [f64],
        ) -> Result<(), palpate_core::ForwardError> {
            if let (Some(t), Some(d)) = (loading.time.as_ref(), loading.drive.first()) {
                if self.0.fails_on.iter().any(|f| (f - d).abs() < 1e-12) {
                    return Err(palpate_core::ForwardError::NotConverged {
                        sample: 0,
                        drive: loading.drive[0],
                        cuts: 0,
                        reason: format!(
                            "this test tissue fails on the history of {} stations",
                            t.len()
                        ),
                        completed: Vec::new(),
                    });
                }
            }
            let mut k = self.0.truth.clone();
            k.reset();
            let time = match (&loading.time, self.0.viscous) {
                (Some(t), true) => t.clone(),
                _ => vec![0.0; loading.drive.len()],
            };
            let mut knots = vec![(0.0, 0.0)];
            knots.extend(time.iter().copied().zip(loading.drive.iter().copied()));
            let mut prev = (0.0, 0.0);
            for (o, &(t, d)) in out.iter_mut().zip(&knots[1..]) {
                // 1 ms steps (as the surrogate's), the depth linear in time
                let n = ((t - prev.0) / 1e-3).round().max(1.0) as usize;
                let mut f = 0.0;
                for j in 1..=n {
                    let s = j as f64 / n as f64;
                    f = k.step(prev.1 + s * (d - prev.1), (t - prev.0) / n as f64).0;
                }
                *o = f;
                prev = (t, d);
            }
            Ok(())
        }
    }

    impl palpate_core::ForwardModel for KernelTissue {
        fn name(&self) -> String {
            "kernel tissue".into()
        }
        fn space(&self) -> &palpate_core::ParamSpace {
            &self.space
        }
        fn observable(&self) -> palpate_core::Observable {
            palpate_core::Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn palpate_core::Evaluator + '_> {
            Box::new(KernelTissueEval(self))
        }
    }

    /// A build request on the test tissue: 12 training (or `training`)
    /// and 3 held-out histories to 1 mm, 10 knots.
    fn tissue_request<'a>(
        elastic: &'a KernelTissue,
        viscoelastic: &'a KernelTissue,
        training: usize,
    ) -> RealTimeRequest<'a> {
        RealTimeRequest {
            elastic,
            elastic_theta: &[1.0],
            viscoelastic,
            viscoelastic_theta: &[1.0],
            prony: vec![(0.3, 0.5), (0.2, 10.0)],
            depth_max: 1.0,
            knots: 20,
            validation_histories: 3,
            segments: 6,
            training_histories: training,
            kernel_knots: 10,
        }
    }

    /// The test tissue: elastic (instantaneous) or viscoelastic, failing
    /// on the histories whose first station is at a depth in `fails_on`.
    fn tissue(viscous: bool, fails_on: Vec<f64>) -> KernelTissue {
        let prony = vec![(0.3, 0.5), (0.2, 10.0)];
        let knots = 10;
        let at_knots: Vec<f64> = (1..=knots)
            .map(|k| {
                let x = k as f64 / knots as f64;
                0.02 * x + 0.03 * x * x
            })
            .collect();
        let mut truth = MemoryKernel::qlv(1.0, &at_knots, &prony, true);
        truth.memory.chunks_mut(2).for_each(|c| c[1] *= 1.6);
        KernelTissue {
            truth,
            viscous,
            space: palpate_core::ParamSpace::new(vec![palpate_core::ParamSpec::new(
                "k", "-", 0.0, 2.0, 1.0,
            )]),
            fails_on,
        }
    }

    /// The whole build on that tissue: the training histories, the fit and
    /// the held-out table (12 training histories, as the CLI's default): the
    /// fitted memory is within 1 % of the peak on histories it was not
    /// built from (measured 0.23-0.48 %), where QLV with the same terms is
    /// off by more than 2 % (3.1-9.9 %).
    #[test]
    fn a_build_fits_a_memory_that_qlv_misses() {
        let elastic = tissue(false, Vec::new());
        let viscoelastic = tissue(true, Vec::new());
        let req = tissue_request(&elastic, &viscoelastic, 12);
        let ticks = std::sync::atomic::AtomicUsize::new(0);
        let tick = |_: usize, total: usize| {
            assert_eq!(total, 16);
            ticks.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        };
        let s = RealTimeSurrogate::build(&req, Some(&tick)).unwrap();
        assert_eq!(ticks.into_inner(), 16);
        assert_eq!(s.fe_runs, 16);
        let k = s.kernel.as_ref().expect("a fitted memory");
        assert_eq!(k.training.histories, 12);
        assert!(k.lift_off, "{:?}", k.training.cv_max_relative_error);
        assert_eq!(s.validation.len(), 3);
        assert!(s.training_failures.is_empty() && s.validation_failures.is_empty());
        for (v, q) in s.validation.iter().zip(&s.qlv_validation) {
            assert!(v.max_relative_error < 1e-2, "{v:?}");
            assert!(q.max_relative_error > 2e-2, "{q:?}");
        }
        // without training histories: plain QLV, as before
        let plain =
            RealTimeSurrogate::build(&tissue_request(&elastic, &viscoelastic, 0), None).unwrap();
        assert!(plain.kernel.is_none() && plain.qlv_validation.is_empty());
        for (p, q) in plain.validation.iter().zip(&s.qlv_validation) {
            assert_eq!(p.max_relative_error, q.max_relative_error);
        }
    }

    /// Histories the model cannot finish are left out and named, from the
    /// fit and from the error table, and the build still stores a
    /// surrogate; with none of the held-out histories run, it is an error.
    #[test]
    fn a_build_leaves_out_histories_the_model_cannot_run() {
        // the first station of training history k (k >= 1) and of held-out seed k
        let first = |h: History, inner: usize| h.stations(inner, inner).1[0];
        let train = |k: u64| first(random_history(1000 + k, 1.0, 6, 1e-3), 8);
        let held = |k: u64| first(random_history(k, 1.0, 6, 1e-3), 4);
        let elastic = tissue(false, Vec::new());
        let failing = tissue(true, vec![train(3), train(7), held(2)]);
        let s = RealTimeSurrogate::build(&tissue_request(&elastic, &failing, 12), None).unwrap();
        assert_eq!(s.training_failures.len(), 2);
        assert_eq!(s.validation_failures.len(), 1);
        assert!(
            s.validation_failures[0].contains("random 2")
                && s.validation_failures[0].contains("fails on"),
            "{:?}",
            s.validation_failures
        );
        assert_eq!(s.validation.len(), 2);
        assert_eq!(s.kernel.as_ref().unwrap().training.histories, 10);
        let back = RealTimeSurrogate::from_json(&s.to_json()).unwrap();
        assert_eq!(back.validation_failures, s.validation_failures);
        assert_eq!(back.training_failures, s.training_failures);
        let none = tissue(true, vec![held(1), held(2), held(3)]);
        let e = RealTimeSurrogate::build(&tissue_request(&elastic, &none, 0), None).unwrap_err();
        assert!(e.contains("no held-out FE history ran"), "{e}");
    }
}
