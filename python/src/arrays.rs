//! The functions of `palpate._native` that pass numpy arrays in memory
//! (rust-numpy) instead of through files: `simulate_arrays` (the force
//! curve out), `calibrate_arrays` (the data in), `sample_arrays` (the data
//! in, the draws out).
//!
//! They take the command line's options as `args` (parsed by the same clap
//! definitions as `run_cli`, so the options, defaults and messages are those
//! of `palpate --help`) and call palpate's library functions behind the
//! subcommands ([`palpate_studies::cli::simulate::curve`],
//! [`palpate_studies::cli::calibrate::fit`],
//! [`palpate_studies::cli::sample::draw`]), the GIL released while they run.
//!
//! No copy at the boundary:
//! * in: a record's columns are read as borrowed slices of the numpy
//!   arrays (`PyReadonlyArray1::as_slice`; a non-contiguous array, e.g. a
//!   strided view, is copied once into a Vec instead) and named in the
//!   options as `--data TEST=<array:K>` ([`palpate_studies::records::arrays`]);
//! * out: a Vec palpate filled is moved into numpy (`PyArray1::from_vec`:
//!   the array's memory is the Vec's, owned by a Rust container object that
//!   is the array's `base`).

use crate::{parse_cli, to_py};
use numpy::{PyArray1, PyReadonlyArray1};
use palpate_studies::cli::{calibrate, sample, simulate, Command};
use palpate_studies::records::arrays::ArrayRecord;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::borrow::Cow;

/// A record from Python: its column names and the columns.
type PyRecord<'py> = (Vec<String>, Vec<PyReadonlyArray1<'py, f64>>);

/// A record's names and its columns as slices (borrowed, or copied when
/// the array was not contiguous).
type Columns<'a> = (Vec<String>, Vec<Cow<'a, [f64]>>);

/// The command line `palpate NAME ARGS...` parsed.
fn parse(name: &str, args: Vec<String>) -> PyResult<Command> {
    Ok(parse_cli(std::iter::once(name.to_string()).chain(args).collect())?.command)
}

/// The error for a subcommand other than `expected` (not reachable from
/// the Python package, which names the subcommand itself).
fn other(expected: &str) -> PyErr {
    crate::PalpateError::new_err(format!("expected the options of `palpate {expected}`"))
}

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

/// `palpate simulate ARGS` (N1, N3, C1, Q1) with the curve returned as
/// arrays moved out of palpate's Vecs: a dict of `displacement_mm`,
/// `force_N` and, when present, `time_s`, `error_estimate_N`, with
/// `comments` (the CSV's comment lines) and `title`.
#[pyfunction]
pub fn simulate_arrays<'py>(py: Python<'py>, args: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
    let Command::Simulate(a) = parse("simulate", args)? else {
        return Err(other("simulate"));
    };
    let c = py.detach(|| simulate::curve(&a)).map_err(to_py)?;
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

/// `palpate calibrate ARGS` with `--data TEST=<array:K>` taking the K-th of
/// `records` (column names, float64 columns). Returns the JSON of `--json`
/// as text.
#[pyfunction]
pub fn calibrate_arrays(
    py: Python<'_>,
    args: Vec<String>,
    records: Vec<PyRecord<'_>>,
) -> PyResult<String> {
    let Command::Calibrate(a) = parse("calibrate", args)? else {
        return Err(other("calibrate"));
    };
    let cols = columns(&records);
    let recs = array_records(&cols);
    let fit = py.detach(|| calibrate::fit(&a, &recs)).map_err(to_py)?;
    serde_json::to_string(&fit).map_err(|e| to_py(e.into()))
}

/// `palpate sample ARGS` with `--data TEST=<array:K>` taking the K-th of
/// `records`. Returns (names, draws, n_chains, n_draws, summary JSON): the
/// draws a flat float64 array moved out of palpate's Vec, chain-major
/// (reshape to (n_chains, n_draws, len(names)) for a view).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn sample_arrays<'py>(
    py: Python<'py>,
    args: Vec<String>,
    records: Vec<PyRecord<'py>>,
) -> PyResult<(Vec<String>, Bound<'py, PyArray1<f64>>, usize, usize, String)> {
    let Command::Sample(a) = parse("sample", args)? else {
        return Err(other("sample"));
    };
    let cols = columns(&records);
    let recs = array_records(&cols);
    let s = py.detach(|| sample::draw(&a, &recs)).map_err(to_py)?;
    let summary = serde_json::to_string(&s.summary).map_err(|e| to_py(e.into()))?;
    let (n_chains, n_draws) = (s.chains.n_chains, s.chains.n_draws);
    Ok((
        s.names,
        PyArray1::from_vec(py, s.chains.values),
        n_chains,
        n_draws,
        summary,
    ))
}
