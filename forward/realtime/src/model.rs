//! The real-time model and its recursion: the force for an arbitrary depth
//! history, sample by sample.
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
//! Piola-Kirchhoff stress) differs from it, the more so where the contact
//! grows and shrinks (the rounded Q1 punch, the N1 needle).
//!
//! So a build with training histories (`RealTimeRequest::training_histories`)
//! replaces QLV's memory by a fitted one ([`crate::memory_kernel`]): the
//! memory read through the present depth, its coefficients from FE runs by
//! least squares, the same recursion. The held-out errors of both, build by
//! build, are in `docs/validation/realtime.md`.
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

// Negated comparisons (`!(x > 0.0)`) deliberately treat NaN as failure.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use serde::{Deserialize, Serialize};

use crate::memory_kernel::MemoryKernel;

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

/// A query the real-time model refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RangeError {
    #[error("depth {depth} mm is outside the real-time model's trained range [0, {max}] mm (it does not extrapolate; rebuild it with a larger --depth-max)")]
    Depth { depth: f64, max: f64 },
    #[error("time step {dt} s: must be finite and >= 0")]
    TimeStep { dt: f64 },
}

/// What the model was checked against: per held-out FE history, the
/// largest force error relative to the history's peak force (the measure
/// a build's `--target` is read by), and the RMS error over its stations
/// relative to the same peak.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryError {
    pub history: String,
    pub samples: usize,
    pub peak_force_n: f64,
    pub max_abs_error_n: f64,
    pub max_relative_error: f64,
    /// `sqrt(mean((F - F_FE)^2)) / peak` over the stations; none in files
    /// written before it was stored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_relative_error: Option<f64>,
    /// Where that error is: the station's `(time_s, depth_mm)`; none in
    /// older files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub worst_at: Option<(f64, f64)>,
}

/// One FE history of a build: its name (`training k` or `random k`), its
/// segment ends `(time_s, depth_mm)` and the FE force at its stations
/// `(time_s, force_n)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StoredRun {
    pub name: String,
    pub knots: Vec<(f64, f64)>,
    pub stations: Vec<(f64, f64)>,
}

/// The stored real-time model and its state (the state is not stored).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RealTimeModel {
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
    /// ([`crate::memory_kernel`]); built from FE training histories.
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
    /// The FE histories of the build (training first, then held out) with
    /// their FE forces, so the memory can be refitted without FE
    /// ([`RealTimeModel::refit`]); empty in files of older builds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub runs: Vec<StoredRun>,
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

impl RealTimeModel {
    /// A model from its elastic curve and relaxation terms; checks the
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
        let mut s = RealTimeModel {
            model,
            depth_max,
            elastic,
            prony,
            validation: Vec::new(),
            kernel: None,
            qlv_validation: Vec::new(),
            training_failures: Vec::new(),
            validation_failures: Vec::new(),
            runs: Vec::new(),
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

    /// JSON text of the stored model.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a real-time model serialises")
    }

    /// Reads a stored model, checked as [`RealTimeModel::new`].
    pub fn from_json(text: &str) -> Result<Self, String> {
        let s: RealTimeModel = serde_json::from_str(text).map_err(|e| e.to_string())?;
        let elastic = MonotoneCubic::new(s.elastic.x.clone(), s.elastic.y.clone())?;
        let mut out = RealTimeModel::new(s.model, elastic, s.prony)?;
        out.validation = s.validation;
        if let Some(k) = &s.kernel {
            k.check()?;
            if k.depth_max != out.depth_max {
                return Err(format!(
                    "memory kernel on [0, {}] mm for a model on [0, {}] mm",
                    k.depth_max, out.depth_max
                ));
            }
        }
        out.kernel = s.kernel;
        out.qlv_validation = s.qlv_validation;
        out.training_failures = s.training_failures;
        out.validation_failures = s.validation_failures;
        out.runs = s.runs;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::depth_history::random_history;

    fn linear_model(prony: Vec<(f64, f64)>) -> RealTimeModel {
        let x: Vec<f64> = (0..=10).map(|k| 0.1 * k as f64).collect();
        let y = x.iter().map(|d| 2.0 * d).collect();
        RealTimeModel::new("linear".into(), MonotoneCubic::new(x, y).unwrap(), prony).unwrap()
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
        let mut s = linear_model(vec![(0.3, 0.5), (0.2, 10.0)]);
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
        let mut s = linear_model(vec![(0.5, 1.0)]);
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
        let mut s = linear_model(vec![(0.3, 0.5)]);
        let a = s.force(0.5, 0.1).unwrap();
        let e = s.force(1.2, 0.1).unwrap_err();
        assert!(
            e.to_string()
                .contains("outside the real-time model's trained range [0, 1] mm"),
            "{e}"
        );
        assert!(s.force(-0.1, 0.1).is_err());
        assert!(s.force(f64::NAN, 0.1).is_err());
        let e = s.force(0.5, -0.1).unwrap_err();
        assert!(e.to_string().contains("time step -0.1 s"), "{e}");
        let mut t = linear_model(vec![(0.3, 0.5)]);
        t.force(0.5, 0.1).unwrap();
        assert_eq!(s.force(0.5, 0.1).unwrap(), t.force(0.5, 0.1).unwrap());
        assert!(a > 0.0);
        let bad = RealTimeModel::new(
            "x".into(),
            MonotoneCubic::new(vec![0.0, 1.0], vec![0.0, 1.0]).unwrap(),
            vec![(0.6, 1.0), (0.4, 2.0)],
        )
        .unwrap_err();
        assert!(bad.contains("sum to 1"), "{bad}");
        let json = t.to_json();
        assert!(RealTimeModel::from_json(&json).is_ok());
    }

    /// With a memory kernel (here QLV's own coefficients): the same answers
    /// as plain QLV, the same range checks, and the kernel survives the
    /// file; a kernel on another depth range is refused on reading.
    #[test]
    fn a_memory_kernel_answers_and_is_stored() {
        let prony = vec![(0.3, 0.5), (0.2, 10.0)];
        let mut plain = linear_model(prony.clone());
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
        let mut back = RealTimeModel::from_json(&with.to_json()).unwrap();
        assert!(back.kernel.is_some());
        assert_eq!(back.run(&h.time, &h.depth).unwrap(), b);
        let mut other = with.clone();
        other.kernel = Some(MemoryKernel::qlv(2.0, &at_knots, &prony, true));
        let e = RealTimeModel::from_json(&other.to_json()).unwrap_err();
        assert!(e.contains("memory kernel on [0, 2] mm"), "{e}");
    }
}
