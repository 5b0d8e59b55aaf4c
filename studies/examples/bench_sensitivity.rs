//! Benchmark of exact FE sensitivities in a calibration: N1 fits by
//! Levenberg-Marquardt on one synthetic record and one mesh, side by side
//! by the finite-difference route (central differences of whole runs) and
//! the exact route (direct differentiation through the converged
//! increments, `palpate_fe::sensitivity`, plugged in by
//! `DataSet::with_model_sensitivities`). Two fits:
//!
//! * `friction`: neo-Hookean C10 and the needle's Coulomb friction; the
//!   record is the model at C10 = 1.101295e-3 MPa, friction 0.3, with a
//!   deterministic 0.5 % ripple; start C10 = 0.8e-3, friction 0.5;
//! * `c10-c20`: the reduced polynomial law (N = 2), C10 and C20 with the
//!   friction held at 0.3; record at C10 = 1.1e-3, C20 = 2e-4 MPa with the
//!   same ripple; start C10 = 0.8e-3, C20 = 1e-4.
//!
//! Prints per route the iterations, the FE runs (plain, and with
//! sensitivities), the runs of each iteration (`plain+sensitivities`, the
//! start first, the statistics at the optimum last), the CPU seconds (user
//! and system time of this process), the FE-run equivalents (CPU over the CPU of
//! one plain run at the truth), the CPU of one run with sensitivities, and
//! the estimates with their standard errors and the difference between the
//! routes in standard errors of the exact route. The rows are Markdown
//! (docs/validation/sensitivity.md).
//!
//! ```text
//! cargo run -p palpate-studies --example bench_sensitivity -- [--case friction|c10-c20|both] [--level L] [--depth D]
//! ```
//!
//! `--level` (default 2, the default mesh of N1; 1 is the coarse one) and
//! `--depth` (default 5 mm, samples every 0.5 mm) choose the problem.

use std::sync::atomic::{AtomicUsize, Ordering::SeqCst};
use std::sync::{Arc, Mutex};

use palpate_core::{
    Drive, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output, ParamSpace,
    Sensitivities,
};
use palpate_fe::{MeshDensity, N1Needle};
use palpate_inverse::{
    fit, shared_observer, DataSet, FitOptions, FitReport, Method, Objective, Progress, ResidualKind,
};

#[path = "../../forward/fe/examples/common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn num(name: &str, default: f64) -> f64 {
    arg(name).map_or(default, |v| {
        v.parse()
            .unwrap_or_else(|_| panic!("{name} {v}: expected a number"))
    })
}

/// A model counting its runs: plain ones and those with sensitivities.
struct Counting {
    inner: Arc<dyn ForwardModel>,
    plain: AtomicUsize,
    exact: AtomicUsize,
}

impl Counting {
    fn runs(&self) -> (usize, usize) {
        (self.plain.load(SeqCst), self.exact.load(SeqCst))
    }
}

struct CountingEvaluator<'a> {
    inner: Box<dyn Evaluator + 'a>,
    count: &'a AtomicUsize,
}

impl Evaluator for CountingEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.count.fetch_add(1, SeqCst);
        self.inner.predict_into(theta, loading, out)
    }
}

impl ForwardModel for Counting {
    fn name(&self) -> String {
        self.inner.name()
    }
    fn space(&self) -> &ParamSpace {
        self.inner.space()
    }
    fn observable(&self) -> Observable {
        self.inner.observable()
    }
    fn outputs(&self) -> Vec<Output> {
        self.inner.outputs()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(CountingEvaluator {
            inner: self.inner.evaluator(),
            count: &self.plain,
        })
    }
    fn as_sensitivities(&self) -> Option<&dyn Sensitivities> {
        self.inner
            .as_sensitivities()
            .map(|_| self as &dyn Sensitivities)
    }
}

impl Sensitivities for Counting {
    fn predict_with_jacobian(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        self.exact.fetch_add(1, SeqCst);
        self.inner
            .as_sensitivities()
            .expect("the inner model offers sensitivities")
            .predict_with_jacobian(theta, loading)
    }
}

struct Case {
    name: &'static str,
    title: &'static str,
    model: N1Needle,
    truth: [f64; 2],
    start: [f64; 2],
}

fn cases(level: usize) -> Vec<Case> {
    let mut friction = N1Needle::new("neo-hookean".parse().expect("a law"));
    friction.mesh = MeshDensity { level };
    friction.friction = 0.3;
    friction.set_friction_parameter(true);
    let mut poly = N1Needle::new("reduced-polynomial:2".parse().expect("a law"));
    poly.mesh = MeshDensity { level };
    poly.friction = 0.3;
    vec![
        Case {
            name: "friction",
            title: "neo-Hookean C10 and friction",
            model: friction,
            truth: [1101.295e-6, 0.3],
            start: [0.8e-3, 0.5],
        },
        Case {
            name: "c10-c20",
            title: "reduced polynomial C10 and C20 (friction 0.3 held)",
            model: poly,
            truth: [1.1e-3, 2e-4],
            start: [0.8e-3, 1e-4],
        },
    ]
}

/// One fit: the report, CPU s, (plain, sensitivity) runs, and the runs of
/// each iteration as `plain+sensitivities`.
fn route(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    start: &[f64],
    exact: bool,
) -> (FitReport, f64, (usize, usize), String) {
    let counting = Arc::new(Counting {
        inner: Arc::clone(model),
        plain: AtomicUsize::new(0),
        exact: AtomicUsize::new(0),
    });
    let counted: Arc<dyn ForwardModel> = counting.clone();
    let mut set = DataSet::new("synthetic", counted, loading.clone(), observed.to_vec());
    if exact {
        set = set.with_model_sensitivities();
        assert!(set.sensitivities.is_some(), "N1 offers exact sensitivities");
    }
    let objective = Objective::new(vec![set], ResidualKind::Absolute, &[]).expect("an objective");
    // the runs counted at each iteration's report
    let marks = Arc::new(Mutex::new(Vec::<(usize, usize)>::new()));
    let seen = Arc::clone(&marks);
    let watched = Arc::clone(&counting);
    let options = FitOptions {
        start: Some(start.to_vec()),
        observer: Some(shared_observer(move |_: &Progress| {
            seen.lock().expect("marks").push(watched.runs())
        })),
        ..FitOptions::with_method(Method::LevenbergMarquardt(Default::default()))
    };
    let c0 = cpu_seconds(false);
    let report = fit(&objective, &options).expect("a fit");
    let cpu = cpu_seconds(false) - c0;
    let total = counting.runs();
    let mut marks = marks.lock().expect("marks").clone();
    marks.push(total);
    let mut last = (0, 0);
    let per_iteration: Vec<String> = marks
        .iter()
        .map(|&(p, e)| {
            let s = format!("{}+{}", p - last.0, e - last.1);
            last = (p, e);
            s
        })
        .collect();
    (report, cpu, total, per_iteration.join(" "))
}

fn main() {
    let level = num("--level", 2.0) as usize;
    let depth = num("--depth", 5.0);
    let which = arg("--case").unwrap_or_else(|| "both".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let n = (depth / 0.5).round() as usize;
    let drive: Vec<f64> = (1..=n).map(|k| 0.5 * k as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    println!(
        "N1 needle, mesh level {level}, {n} samples to {depth} mm, {cores} cores available, dev or release as built"
    );
    for case in cases(level) {
        if which != "both" && which != case.name {
            continue;
        }
        let model: Arc<dyn ForwardModel> = Arc::new(case.model);
        let c0 = cpu_seconds(false);
        let clean = model
            .predict(&case.truth, &loading)
            .expect("the synthetic record");
        let run_cpu = cpu_seconds(false) - c0;
        let c1 = cpu_seconds(false);
        model
            .as_sensitivities()
            .expect("sensitivities")
            .predict_with_jacobian(&case.truth, &loading)
            .expect("a run with sensitivities");
        let sens_cpu = cpu_seconds(false) - c1;
        let observed: Vec<f64> = clean
            .iter()
            .enumerate()
            .map(|(i, f)| f * (1.0 + 0.005 * (1.7 * i as f64).sin()))
            .collect();
        let names = model.space().names();
        println!(
            "\n### {} ({})\n\nOne plain run at the truth: {run_cpu:.2} s CPU; one run with sensitivities: {sens_cpu:.2} s ({:.2} plain runs).\n",
            case.title,
            case.name,
            sens_cpu / run_cpu
        );
        println!(
            "| route | iterations | FE runs (plain + with sensitivities) | runs per iteration (start, iterations, statistics) | CPU s | FE-run equivalents | {} | SE | {} | SE |\n|---|---|---|---|---|---|---|---|---|---|",
            names[0], names[1]
        );
        let mut estimates = Vec::new();
        for exact in [false, true] {
            let (report, cpu, (plain, sens), per_iteration) =
                route(&model, &loading, &observed, &case.start, exact);
            let p = &report.parameters;
            let runs = if exact {
                format!("{} ({plain} + {sens})", plain + sens)
            } else {
                format!("{} ({} evaluations)", plain, report.evaluations)
            };
            println!(
                "| {} | {} | {runs} | {} | {cpu:.1} | {:.1} | {:.6e} | {:.2e} | {:.6e} | {:.2e} |",
                if exact {
                    "exact sensitivities"
                } else {
                    "finite differences"
                },
                report.iterations,
                if exact { per_iteration.as_str() } else { "" },
                cpu / run_cpu,
                p[0].value,
                p[0].standard_error.unwrap_or(f64::NAN),
                p[1].value,
                p[1].standard_error.unwrap_or(f64::NAN),
            );
            estimates.push(report);
        }
        let (fd, ex) = (&estimates[0], &estimates[1]);
        let gaps: Vec<String> = (0..2)
            .map(|k| {
                let se = ex.parameters[k].standard_error.unwrap_or(f64::NAN);
                format!(
                    "{} {:.3} SE",
                    names[k],
                    (fd.parameters[k].value - ex.parameters[k].value).abs() / se
                )
            })
            .collect();
        println!(
            "\nEstimates of the two routes apart by {} (of the exact route's SE).",
            gaps.join(", ")
        );
    }
}
