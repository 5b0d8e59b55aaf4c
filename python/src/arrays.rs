//! The functions of `palpate._native` that call palpate's typed library
//! API ([`palpate_studies::api`]) with numpy arrays in memory: `simulate`
//! ([`palpate_studies::api::simulate::simulate`], the force curve out),
//! `calibrate` ([`palpate_studies::api::calibrate`] and
//! [`palpate_studies::api::calibrate_experiment`], the data in), `diagnose`
//! ([`palpate_studies::api::diagnose`], the record in), and `sample`
//! ([`palpate_studies::api::sample::sample`], the data in, the draws out).
//! The GIL is released while they run.
//!
//! The options are typed keywords; the texts among them (law, residual,
//! estimator, a record's `TEST[key=value]` form) are read by the same
//! functions the command line uses, so the messages are the same.
//!
//! No copy at the boundary:
//! * in: a record's columns are read as borrowed slices of the numpy
//!   arrays (`PyReadonlyArray1::as_slice`; a non-contiguous array, e.g. a
//!   strided view, is copied once into a Vec instead) and named in the
//!   record's text as `TEST=<array:K>` ([`palpate_studies::records::arrays`]);
//! * out: a Vec palpate filled is moved into numpy (`PyArray1::from_vec`:
//!   the array's memory is the Vec's, owned by a Rust container object that
//!   is the array's `base`).

use crate::{to_py, PalpateError};
use numpy::{PyArray1, PyReadonlyArray1};
use palpate_studies::api::{self, sample::SampleOptions, simulate::SimulateOptions};
use palpate_studies::api::{Observer, Silent, Stderr};
use palpate_studies::records::arrays::ArrayRecord;
use palpate_studies::records::data_option::{read_data_with, read_force_records};
use palpate_studies::records::ReadOptions;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::borrow::Cow;

/// A record from Python: its column names and the columns.
type PyRecord<'py> = (Vec<String>, Vec<PyReadonlyArray1<'py, f64>>);

/// A record's names and its columns as slices (borrowed, or copied when
/// the array was not contiguous).
type Columns<'a> = (Vec<String>, Vec<Cow<'a, [f64]>>);

/// The columns of the records as slices: borrowed when contiguous, else
/// copied once (returned in the Cow).
fn columns<'a>(records: &'a [PyRecord<'_>]) -> Vec<Columns<'a>> {
    records
        .iter()
        .map(|(names, cols)| {
            let cols = cols
                .iter()
                .map(|a| match a.as_slice() {
                    Ok(s) => Cow::Borrowed(s),
                    Err(_) => Cow::Owned(a.as_array().iter().copied().collect()),
                })
                .collect();
            (names.clone(), cols)
        })
        .collect()
}

fn array_records<'a>(cols: &'a [Columns<'a>]) -> Vec<ArrayRecord<'a>> {
    cols.iter()
        .map(|(names, c)| ArrayRecord {
            names: names.clone(),
            columns: c.iter().map(|c| c.as_ref()).collect(),
        })
        .collect()
}

/// Lines and bars on standard error when `verbose`, else nothing.
fn observer(verbose: bool) -> &'static (dyn Observer + Sync) {
    if verbose {
        &Stderr
    } else {
        &Silent
    }
}

/// A JSON value as Python data (dicts keep the serialiser's order).
fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use pyo3::types::{PyBool, PyList, PyString};
    use serde_json::Value as V;
    Ok(match v {
        V::Null => py.None().into_bound(py),
        V::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        V::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        V::String(s) => PyString::new(py, s).into_any(),
        V::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(json_to_py(py, x)?)?;
            }
            l.into_any()
        }
        V::Object(m) => {
            let d = PyDict::new(py);
            for (k, x) in m {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// An FE benchmark's (N1, N3, C1, Q1) or an experiment's force curve
/// ([`palpate_studies::api::simulate::simulate`]) with the arrays moved
/// out of palpate's Vecs: a dict of `displacement_mm`, `force_N` and, when
/// present, `time_s`, `error_estimate_N`, with `comments` (the CSV's
/// comment lines) and `title`. R2: the scan
/// ([`palpate_studies::api::simulate::r2::scan`]), `position_mm`,
/// `force_N`, `force_x_N`, `error_estimate_N` and the pressing phase
/// (`press_displacement_mm`, `press_force_N`, `press_force_x_N`).
#[pyfunction]
#[pyo3(signature = (
    benchmark=None, experiment=None, law=None, params=Vec::new(), *, friction=None, rd=None,
    nodules=None, nodule_law=None, nodule_params=Vec::new(), bonded=false, sliding_base=false,
    tool=None, element=None, edge_radius=None, depth=None, step=None, mesh=None, accuracy=None,
    bulk=None, error_estimate="on", order=None, prony=None, ramp=None, hold=None, verbose=false
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    benchmark: Option<String>,
    experiment: Option<String>,
    law: Option<String>,
    params: Vec<(String, f64)>,
    friction: Option<f64>,
    rd: Option<f64>,
    nodules: Option<String>,
    nodule_law: Option<String>,
    nodule_params: Vec<(String, f64)>,
    bonded: bool,
    sliding_base: bool,
    tool: Option<String>,
    element: Option<String>,
    edge_radius: Option<f64>,
    depth: Option<f64>,
    step: Option<f64>,
    mesh: Option<String>,
    accuracy: Option<f64>,
    bulk: Option<String>,
    error_estimate: &str,
    order: Option<f64>,
    prony: Option<String>,
    ramp: Option<f64>,
    hold: Option<f64>,
    verbose: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let error_estimate = match error_estimate {
        "on" => true,
        "off" => false,
        other => {
            return Err(PalpateError::new_err(format!(
                "--error-estimate {other}: expected on or off"
            )))
        }
    };
    let options = SimulateOptions {
        benchmark,
        experiment,
        law,
        params,
        friction,
        rd,
        nodules,
        nodule_law,
        nodule_params,
        bonded,
        sliding_base,
        tool,
        element,
        edge_radius,
        depth,
        step,
        mesh,
        accuracy,
        bulk,
        error_estimate,
        order,
        prony,
        ramp,
        hold,
    };
    let show = observer(verbose);
    if options.benchmark().eq_ignore_ascii_case("r2") {
        let s = py
            .detach(|| api::simulate::r2::scan(&options, show))
            .map_err(to_py)?
            .scan;
        let d = PyDict::new(py);
        d.set_item("position_mm", PyArray1::from_vec(py, s.position_mm))?;
        d.set_item("force_N", PyArray1::from_vec(py, s.force_n))?;
        d.set_item("force_x_N", PyArray1::from_vec(py, s.force_x_n))?;
        if let Some(e) = s.error_estimate_n {
            d.set_item("error_estimate_N", PyArray1::from_vec(py, e))?;
        }
        d.set_item(
            "press_displacement_mm",
            PyArray1::from_vec(py, s.press_depth_mm),
        )?;
        d.set_item("press_force_N", PyArray1::from_vec(py, s.press_force_n))?;
        d.set_item("press_force_x_N", PyArray1::from_vec(py, s.press_force_x_n))?;
        d.set_item("comments", s.comments)?;
        d.set_item("title", s.title)?;
        return Ok(d);
    }
    let c = py
        .detach(|| api::simulate::simulate(&options, show).map(|s| s.curve))
        .map_err(to_py)?;
    let d = PyDict::new(py);
    if let Some(t) = c.time_s {
        d.set_item("time_s", PyArray1::from_vec(py, t))?;
    }
    d.set_item("displacement_mm", PyArray1::from_vec(py, c.displacement_mm))?;
    d.set_item("force_N", PyArray1::from_vec(py, c.force_n))?;
    if let Some(e) = c.error_estimate_n {
        d.set_item("error_estimate_N", PyArray1::from_vec(py, e))?;
    }
    d.set_item("comments", c.comments)?;
    d.set_item("title", c.title)?;
    Ok(d)
}

/// A fit ([`palpate_studies::api::calibrate`], or
/// [`palpate_studies::api::calibrate_experiment`] for an experiment
/// description or a preset benchmark such as N1) of the records `data`
/// (`TEST=FILE`, `TEST[key=value,...]=FILE`, a C1 or force record's
/// `FILE`, with `<array:K>` for the K-th of `records`). Returns the
/// calibration as Python data (the report of `palpate calibrate --json`);
/// `verbose` prints its table as the command line does.
#[pyfunction]
#[pyo3(signature = (
    law, data, records, *, experiment=None, benchmark=None, residual="absolute", estimator="lm",
    fix=Vec::new(), viscoelastic=None, verbose=false
))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate<'py>(
    py: Python<'py>,
    law: Option<String>,
    data: Vec<String>,
    records: Vec<PyRecord<'_>>,
    experiment: Option<String>,
    benchmark: Option<String>,
    residual: &str,
    estimator: &str,
    fix: Vec<(String, f64)>,
    viscoelastic: Option<String>,
    verbose: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let cols = columns(&records);
    let recs = array_records(&cols);
    let fit = py
        .detach(|| {
            let spec = api::experiment_spec(
                experiment.as_deref(),
                benchmark.as_deref(),
                law.as_deref(),
            )?;
            if let Some(spec) = spec {
                anyhow::ensure!(
                    viscoelastic.is_none(),
                    "--viscoelastic: not an option of an experiment's calibration (its description holds the model)"
                );
                let options = api::ExperimentFitOptions::parse(residual, estimator, fix)?;
                let data = read_force_records(&data, &recs, &ReadOptions::default())?;
                return api::calibrate_experiment(spec, &data, &options);
            }
            let law = law.as_deref().ok_or_else(|| {
                anyhow::anyhow!("--law: give the material law (e.g. --law neo-hookean)")
            })?;
            let options = api::CalibrateOptions::parse(
                law,
                residual,
                estimator,
                fix,
                viscoelastic.as_deref(),
            )?;
            let data = read_data_with(&data, benchmark.as_deref(), &recs)?;
            api::calibrate(&data, &options)
        })
        .map_err(to_py)?;
    if verbose {
        print!("{}", palpate_studies::report::calibration_table(&fit));
    }
    let value = serde_json::to_value(&fit).map_err(|e| to_py(e.into()))?;
    json_to_py(py, &value)
}

/// The gap diagnosis of one record ([`palpate_studies::api::diagnose`]):
/// `data` is `TEST=FILE` (a homogeneous record), a force record's `FILE`
/// with `benchmark` C1 or N1, with `<array:K>` for the K-th of `records`.
/// Returns the report (the `--json` of `palpate diagnose`) as Python data;
/// `verbose` prints the command line's summary.
#[pyfunction]
#[pyo3(signature = (
    data, records, *, benchmark=None, base=None, effects=Vec::new(), alpha=None, folds=None,
    verbose=false
))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose<'py>(
    py: Python<'py>,
    data: String,
    records: Vec<PyRecord<'_>>,
    benchmark: Option<String>,
    base: Option<String>,
    effects: Vec<String>,
    alpha: Option<f64>,
    folds: Option<usize>,
    verbose: bool,
) -> PyResult<Bound<'py, PyAny>> {
    use palpate_studies::api::diagnose::{diagnose, explanation_summary, gap_options, read_record};
    let cols = columns(&records);
    let recs = array_records(&cols);
    let report = py
        .detach(|| {
            let options = gap_options(alpha, folds, &effects)?;
            let record = read_record(benchmark.as_deref(), &data, &recs)?;
            diagnose(&record, None, base.as_deref(), &options)
        })
        .map_err(to_py)?;
    if verbose {
        println!("{}", palpate_studies::report::gap_summary(&report));
        println!("{}", explanation_summary(&report));
    }
    let value = serde_json::to_value(&report).map_err(|e| to_py(e.into()))?;
    json_to_py(py, &value)
}

/// The posterior of `law`'s (or `experiment`'s) parameters
/// ([`palpate_studies::api::sample::sample`]) on the records `data`
/// (`TEST=FILE`, a benchmark's or experiment's `FILE`, with `<array:K>`
/// for the K-th of `records`). Returns (names, draws, n_chains, n_draws,
/// report, table, warnings): the draws a flat float64 array moved out of
/// palpate's Vec, chain-major (reshape to (n_chains, n_draws, len(names))
/// for a view), the report the `--json` of `palpate sample` as Python
/// data, the table and warnings the command line prints.
#[pyfunction]
#[pyo3(signature = (
    law, data, records, *, experiment=None, benchmark=None, sampler="nuts", draws=None,
    max_draws=None, tune=None, parallel=None, seed=0, sigma=None, ar1=false, prior=Vec::new(),
    boxes=Vec::new(), mesh=None, bulk=None, friction=None, prony=None, edge_radius=None,
    design=None, holdout=None, cache=None, evidence=false, verbose=false
))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn sample<'py>(
    py: Python<'py>,
    law: Option<String>,
    data: Vec<String>,
    records: Vec<PyRecord<'py>>,
    experiment: Option<String>,
    benchmark: Option<String>,
    sampler: &str,
    draws: Option<usize>,
    max_draws: Option<usize>,
    tune: Option<usize>,
    parallel: Option<usize>,
    seed: u64,
    sigma: Option<f64>,
    ar1: bool,
    prior: Vec<String>,
    boxes: Vec<String>,
    mesh: Option<String>,
    bulk: Option<String>,
    friction: Option<f64>,
    prony: Option<String>,
    edge_radius: Option<f64>,
    design: Option<usize>,
    holdout: Option<usize>,
    cache: Option<std::path::PathBuf>,
    evidence: bool,
    verbose: bool,
) -> PyResult<(
    Vec<String>,
    Bound<'py, PyArray1<f64>>,
    usize,
    usize,
    Bound<'py, PyAny>,
    String,
    Vec<String>,
)> {
    let cols = columns(&records);
    let recs = array_records(&cols);
    let show = observer(verbose);
    let s = py
        .detach(|| {
            let options = SampleOptions {
                law,
                experiment,
                benchmark,
                data,
                reading: ReadOptions::default(),
                boxes,
                mesh,
                bulk,
                friction,
                prony,
                edge_radius,
                design,
                holdout,
                cache,
                sampler: sampler.parse()?,
                draws,
                max_draws,
                tune,
                parallel,
                seed,
                sigma,
                ar1,
                priors: prior,
                evidence,
            };
            api::sample::sample(&options, &recs, show)
        })
        .map_err(to_py)?;
    let report = json_to_py(py, &s.report)?;
    let (n_chains, n_draws) = (s.chains.n_chains, s.chains.n_draws);
    Ok((
        s.names,
        PyArray1::from_vec(py, s.chains.values),
        n_chains,
        n_draws,
        report,
        s.table,
        s.warnings,
    ))
}

/// The staged identification of one Q1 ramp-and-hold record
/// ([`palpate_studies::api::identify::identify_q1`]): `data` is `FILE`,
/// `Q1=FILE` or `<array:K>` for the K-th of `records`. Returns (report,
/// text): the result as Python data (the `--json` of `palpate calibrate
/// --benchmark Q1`) and the report the command line prints.
#[pyfunction]
#[pyo3(signature = (
    law, data, records, *, stages=None, prony_terms=None, fit_mesh=None, correct_mesh=None,
    time_step=None, edge_radius=None, fit_edge_radius=None, mesh_check=None, compare=false,
    profile=false, verbose=false
))]
#[allow(clippy::too_many_arguments)]
pub fn identify_q1<'py>(
    py: Python<'py>,
    law: String,
    data: String,
    records: Vec<PyRecord<'_>>,
    stages: Option<String>,
    prony_terms: Option<usize>,
    fit_mesh: Option<f64>,
    correct_mesh: Option<f64>,
    time_step: Option<f64>,
    edge_radius: Option<f64>,
    fit_edge_radius: Option<f64>,
    mesh_check: Option<f64>,
    compare: bool,
    profile: bool,
    verbose: bool,
) -> PyResult<(Bound<'py, PyAny>, String)> {
    use palpate_studies::api::identify::{identify_q1, q1_record, Q1Options};
    let cols = columns(&records);
    let recs = array_records(&cols);
    let show = observer(verbose);
    let result = py
        .detach(|| {
            let options = Q1Options {
                stages,
                prony_terms,
                fit_mesh,
                correct_mesh,
                time_step,
                edge_radius,
                fit_edge_radius,
                mesh_check,
                compare,
                profile,
            }
            .for_law(&law)?;
            let record = q1_record(&data, &recs)?;
            identify_q1(&record, &options, show)
        })
        .map_err(to_py)?;
    let text = palpate_studies::apps::two_stage::report(&result, None);
    let value = serde_json::to_value(&result).map_err(|e| to_py(e.into()))?;
    Ok((json_to_py(py, &value)?, text))
}
