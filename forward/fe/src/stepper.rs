//! Increments along a loading path: loading channels are piecewise-linear
//! functions of a path coordinate `tau` sampled at the output stations;
//! increments advance `tau` (so a hold at constant drive still advances
//! time, and rate-dependent contributions receive `dt`), grow after easy
//! convergence, and are cut back and retried from the last converged state
//! (state vector and every contribution's history) on failure. When the
//! cuts are exhausted the run stops with an error naming the sample and the
//! outputs of the samples that did converge.

use crate::system::{RunStats, SolverOptions, System, Target};
use crate::FeError;

/// A loading history as the stepper sees it: at each output station `k`,
/// the path coordinate `tau[k]` (non-decreasing, starting after `tau = 0`,
/// the reference state where every channel is zero), the channel values
/// and the physical time.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadPath {
    pub tau: Vec<f64>,
    /// `values[k][c]`: channel `c` at station `k`.
    pub values: Vec<Vec<f64>>,
    /// Physical time at each station (s); zero for rate-independent paths.
    pub time: Vec<f64>,
}

impl LoadPath {
    /// One channel driven through `drive` (rate-independent): `tau` is the
    /// accumulated absolute drive change, so increments are measured in the
    /// drive's unit.
    pub fn from_drive(drive: &[f64]) -> LoadPath {
        let mut tau = Vec::with_capacity(drive.len());
        let (mut t, mut prev) = (0.0, 0.0);
        for &d in drive {
            t += (d - prev).abs();
            prev = d;
            tau.push(t);
        }
        LoadPath {
            tau,
            values: drive.iter().map(|&d| vec![d]).collect(),
            time: vec![0.0; drive.len()],
        }
    }

    /// The path of a [`palpate_core::Loading`] with one drive channel: by
    /// drive change alone when it has no time or `max_time_step` is `None`
    /// (the stations keep their times, so `dt` reaches the materials), and
    /// with time as a second measure of progress otherwise
    /// ([`LoadPath::timed`] with `max_step` of path per `max_time_step`
    /// seconds).
    pub fn from_loading(
        drive: &[f64],
        time: Option<&[f64]>,
        max_step: f64,
        max_time_step: Option<f64>,
    ) -> LoadPath {
        match (time, max_time_step) {
            (Some(t), Some(dt)) => LoadPath::timed(
                t,
                drive.iter().map(|&d| vec![d]).collect(),
                &[1.0],
                dt / max_step,
            ),
            (Some(t), None) => LoadPath {
                time: t.to_vec(),
                ..LoadPath::from_drive(drive)
            },
            (None, _) => LoadPath::from_drive(drive),
        }
    }

    /// Channels given at times `time` (s): `tau` accumulates
    /// `max(|change of channel c| / unit[c], dt / time_unit)` over each
    /// segment, so that an increment of 1 in `tau` moves no channel by more
    /// than its unit and no more than `time_unit` seconds pass.
    pub fn timed(time: &[f64], values: Vec<Vec<f64>>, units: &[f64], time_unit: f64) -> LoadPath {
        let mut tau = Vec::with_capacity(time.len());
        let (mut t, mut t_prev) = (0.0, 0.0);
        let mut prev = vec![0.0; units.len()];
        for (k, v) in values.iter().enumerate() {
            let mut d = (time[k] - t_prev) / time_unit;
            for c in 0..units.len() {
                d = d.max((v[c] - prev[c]).abs() / units[c]);
            }
            t += d;
            tau.push(t);
            prev.clone_from(v);
            t_prev = time[k];
        }
        LoadPath {
            tau,
            values,
            time: time.to_vec(),
        }
    }

    /// Number of stations.
    pub fn len(&self) -> usize {
        self.tau.len()
    }

    /// True when there are no stations.
    pub fn is_empty(&self) -> bool {
        self.tau.is_empty()
    }

    /// Checks lengths and that `tau` and time never decrease.
    pub fn validate(&self, channels: usize) -> Result<(), FeError> {
        let bad = |reason: String| FeError::InvalidConfig {
            field: "loading".into(),
            reason,
        };
        if self.values.len() != self.tau.len() || self.time.len() != self.tau.len() {
            return Err(bad("tau, values and time differ in length".into()));
        }
        for k in 0..self.len() {
            if self.values[k].len() != channels {
                return Err(bad(format!(
                    "station {k} has {} channel values, the model has {channels} channels",
                    self.values[k].len()
                )));
            }
            if self.values[k].iter().any(|v| !v.is_finite()) || !self.tau[k].is_finite() {
                return Err(bad(format!("station {k} is not finite")));
            }
            let (t0, s0) = if k == 0 {
                (0.0, 0.0)
            } else {
                (self.tau[k - 1], self.time[k - 1])
            };
            if self.tau[k] < t0 || self.time[k] < s0 {
                return Err(bad(format!("station {k} goes back in time")));
            }
        }
        Ok(())
    }

    /// The loading state at `tau` within segment `k` (from station `k - 1`,
    /// or the reference state, to station `k`).
    fn at(&self, k: usize, tau: f64, channels: usize) -> (Vec<f64>, f64) {
        let (t0, v0, s0) = if k == 0 {
            (0.0, vec![0.0; channels], 0.0)
        } else {
            (
                self.tau[k - 1],
                self.values[k - 1].clone(),
                self.time[k - 1],
            )
        };
        let t1 = self.tau[k];
        if tau >= t1 {
            return (self.values[k].clone(), self.time[k]);
        }
        let w = (tau - t0) / (t1 - t0);
        let v = v0
            .iter()
            .zip(&self.values[k])
            .map(|(a, b)| a + (b - a) * w)
            .collect();
        (v, s0 + (self.time[k] - s0) * w)
    }

    /// Sign pattern of the channel rates in segment `k` (the predictor
    /// extrapolates only within one pattern).
    fn direction(&self, k: usize, channels: usize) -> Vec<i8> {
        let prev = if k == 0 {
            vec![0.0; channels]
        } else {
            self.values[k - 1].clone()
        };
        self.values[k]
            .iter()
            .zip(&prev)
            .map(|(b, a)| {
                if b > a {
                    1
                } else if b < a {
                    -1
                } else {
                    0
                }
            })
            .collect()
    }
}

/// What a model reads off the system after each station.
pub type Observer<'a> = dyn FnMut(&System) -> Vec<f64> + 'a;

/// Reported after every station.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    pub sample: usize,
    pub samples: usize,
    /// Value of the first channel at the station.
    pub drive: f64,
    /// The station's outputs.
    pub outputs: Vec<f64>,
    pub increments: usize,
    pub iterations: usize,
}

/// A failed run: where it stopped, and the outputs of the stations that did converge.
#[derive(Debug, Clone, PartialEq)]
pub struct RunFailure {
    pub sample: usize,
    /// Value of the first channel at the last converged state.
    pub drive: f64,
    pub cuts: usize,
    pub error: FeError,
    pub completed: Vec<Vec<f64>>,
}

/// Runs `path` from the reference state; `observe` reads each station's
/// outputs (reactions, tool forces) off the converged system.
pub fn run(
    sys: &mut System,
    path: &LoadPath,
    opts: &SolverOptions,
    observe: &mut Observer,
    progress: Option<&mut dyn FnMut(&Progress)>,
) -> Result<Vec<Vec<f64>>, RunFailure> {
    run_with_hook(sys, path, opts, observe, progress, None)
}

/// What runs after every converged increment, before its commit, with the
/// system at the converged state and the committed history of the
/// increment's start ([`crate::sensitivity`]); it must leave the system as
/// it found it, trial state included. An error fails the increment as
/// Newton's would: a recoverable one ([`FeError::is_recoverable`]) cuts
/// it and retries (the stepper restores the state vector and rolls the
/// contributions back, so the hook must leave the parameters and the
/// committed history as it found them on an error too), any other or one
/// after the last cut stops the run.
pub(crate) type IncrementHook<'a> = dyn FnMut(&mut System, &Target) -> Result<(), FeError> + 'a;

/// [`run`] with a hook after every converged increment.
pub(crate) fn run_with_hook(
    sys: &mut System,
    path: &LoadPath,
    opts: &SolverOptions,
    observe: &mut Observer,
    mut progress: Option<&mut dyn FnMut(&Progress)>,
    mut hook: Option<&mut IncrementHook>,
) -> Result<Vec<Vec<f64>>, RunFailure> {
    let channels = sys.committed.channels.len();
    let fail =
        |sample: usize, drive: f64, cuts: usize, error: FeError, done: &[Vec<f64>]| RunFailure {
            sample,
            drive,
            cuts,
            error,
            completed: done.to_vec(),
        };
    if let Err(e) = path.validate(channels) {
        return Err(fail(0, 0.0, 0, e, &[]));
    }
    sys.reset();
    let mut outputs = Vec::with_capacity(path.len());
    let mut tau_c = 0.0;
    let mut step = opts.first_step.min(opts.max_step);
    let mut u_c = sys.u.clone();
    // previous increment: (size, change of the state, direction pattern)
    let mut last: Option<(f64, Vec<f64>, Vec<i8>)> = None;
    let reference = sys.committed.clone();
    if let Err(e) = sys.assemble(&reference, false) {
        return Err(fail(0, 0.0, 0, e, &[]));
    }
    let mut current = observe(sys);
    for k in 0..path.len() {
        let target_tau = path.tau[k];
        let dir = path.direction(k, channels);
        let mut cuts = 0;
        while target_tau - tau_c > 1e-12 * (1.0 + target_tau.abs()) {
            let remaining = target_tau - tau_c;
            let size = step.min(remaining);
            let tau_new = if size >= remaining {
                target_tau
            } else {
                tau_c + size
            };
            let (values, time) = path.at(k, tau_new, channels);
            let target = Target {
                channels: values,
                time,
                dt: time - sys.committed.time,
            };
            // predictor: extrapolate the previous increment, then the
            // model's predictor (where it applies)
            if let Some((prev, du, pdir)) = &last {
                if *pdir == dir {
                    let f = size / prev;
                    for (u, d) in sys.u.iter_mut().zip(du) {
                        *u += f * d;
                    }
                }
            }
            if let Some(mut p) = sys.predictor.take() {
                let from = sys.committed.channels.clone();
                p.predict(
                    &sys.mesh,
                    sys.dofs.dim,
                    &from,
                    &target.channels,
                    &u_c,
                    &mut sys.u,
                );
                sys.predictor = Some(p);
            }
            let it0 = sys.stats.iterations;
            // the hook's failure is the increment's: a recoverable one (an
            // element inverted at a perturbed state) is cut like Newton's
            let solved = sys
                .solve_increment(&target, opts)
                .and_then(|()| hook.as_deref_mut().map_or(Ok(()), |h| h(sys, &target)));
            match solved {
                Ok(()) => {
                    sys.commit(&target);
                    let du: Vec<f64> = sys.u.iter().zip(&u_c).map(|(a, b)| a - b).collect();
                    last = Some((tau_new - tau_c, du, dir.clone()));
                    u_c.clone_from(&sys.u);
                    tau_c = tau_new;
                    sys.stats.increments += 1;
                    if sys.stats.iterations - it0 <= 6 {
                        step = (step * 1.5).min(opts.max_step);
                    }
                    current = observe(sys);
                }
                Err(e) if e.is_recoverable() && cuts < opts.max_cuts => {
                    cuts += 1;
                    sys.stats.cuts += 1;
                    sys.u.clone_from(&u_c);
                    sys.rollback();
                    last = None;
                    step = size * 0.5;
                }
                Err(e) => {
                    let drive = sys.committed.channels.first().copied().unwrap_or(0.0);
                    return Err(fail(k, drive, cuts, e, &outputs));
                }
            }
        }
        outputs.push(current.clone());
        if let Some(cb) = progress.as_deref_mut() {
            cb(&Progress {
                sample: k,
                samples: path.len(),
                drive: path.values[k].first().copied().unwrap_or(0.0),
                outputs: current.clone(),
                increments: sys.stats.increments,
                iterations: sys.stats.iterations,
            });
        }
    }
    Ok(outputs)
}

/// The counters of the last run.
pub fn stats(sys: &System) -> RunStats {
    sys.stats
}
