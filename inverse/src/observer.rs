//! Progress reporting without `println!` (STYLE.md 14): a callback the CLI
//! can turn into a progress bar, bridged to argmin's observers.

use crate::{Objective, ParamMap};
use argmin::core::observers::Observe;
use argmin::core::{Error, State, KV};
use std::sync::{Arc, Mutex};

/// One iteration of one start of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Start index (0 = the given starting point) and number of starts.
    pub start: usize,
    pub starts: usize,
    /// Iteration within this start.
    pub iteration: u64,
    /// SSE at the current point and the best SSE of this start.
    pub sse: f64,
    pub best_sse: f64,
    /// The full physical parameter vector at the current point.
    pub theta: Vec<f64>,
}

/// Receives progress events.
pub trait FitObserver: Send {
    fn observe(&mut self, progress: &Progress);
}

impl<F: FnMut(&Progress) + Send> FitObserver for F {
    fn observe(&mut self, progress: &Progress) {
        self(progress)
    }
}

/// An observer shared with the solver (argmin observers must be `'static`).
pub type SharedObserver = Arc<Mutex<dyn FitObserver>>;

/// Wraps a callback as a [`SharedObserver`].
pub fn shared_observer(observer: impl FitObserver + 'static) -> SharedObserver {
    Arc::new(Mutex::new(observer))
}

/// The argmin observer that converts the unbounded state to a [`Progress`].
pub(crate) struct ArgminBridge {
    observer: SharedObserver,
    start: usize,
    starts: usize,
    map: ParamMap,
}

impl ArgminBridge {
    pub(crate) fn new(
        observer: SharedObserver,
        objective: &Objective,
        start: usize,
        starts: usize,
    ) -> Self {
        ArgminBridge {
            observer,
            start,
            starts,
            map: objective.clone_param_map(),
        }
    }
}

impl<I> Observe<I> for ArgminBridge
where
    I: State<Param = Vec<f64>, Float = f64>,
{
    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), Error> {
        let theta = state
            .get_param()
            .map(|z| self.map.theta_from_unbounded(z))
            .unwrap_or_default();
        let progress = Progress {
            start: self.start,
            starts: self.starts,
            iteration: state.get_iter(),
            sse: state.get_cost(),
            best_sse: state.get_best_cost(),
            theta,
        };
        if let Ok(mut obs) = self.observer.lock() {
            obs.observe(&progress);
        }
        Ok(())
    }
}
