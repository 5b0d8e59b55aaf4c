//! `palpate._native`: the Rust side of the Python package (docs/python.md).
//!
//! It runs palpate's own implementations in this process: the typed
//! library API ([`palpate_studies::api`]) for `simulate`, `calibrate`,
//! `sample` and `diagnose` ([`arrays`], numpy arrays in memory), a subcommand of
//! the command line (`run_cli`, so the options, defaults and error messages
//! are those of `palpate --help`), a study
//! ([`palpate_studies::study::runner::run_study_counted`]) or the merge of
//! its shards ([`palpate_studies::study::merge::merge`]). The GIL is released for
//! the whole run (`Python::detach`), so Python threads (a Dask worker's
//! other tasks) go on meanwhile. An error is raised as `PalpateError` with
//! the message the command line prints (`error: ...` and each
//! `caused by: ...`). The Q1 identification of `calibrate`
//! (`identify_q1`) and the R2 scan of `simulate` call the API too.

mod arrays;

use clap::Parser;
use palpate_studies::cli::{dispatch, join_negative_values, Cli};
use palpate_studies::run::shard::Shard;
use palpate_studies::study::runner::{run_study_counted, RunObserver, RunOptions};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

pyo3::create_exception!(
    _native,
    PalpateError,
    pyo3::exceptions::PyException,
    "An error of palpate, with the message the command line prints."
);

/// The message of an error as `palpate` prints it (without `error: `).
fn message(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        text.push_str(&format!("\n  caused by: {cause}"));
    }
    text
}

pub(crate) fn to_py(e: anyhow::Error) -> PyErr {
    PalpateError::new_err(message(&e))
}

/// `palpate ARGS...` parsed as the command line parses it: Ok(Ok(cli)),
/// Ok(Err(text)) for `--help`/`--version`, or PalpateError with clap's
/// message for a bad option.
fn try_parse(args: Vec<String>) -> PyResult<Result<Cli, String>> {
    let argv = std::iter::once("palpate".to_string())
        .chain(args)
        .map(std::ffi::OsString::from);
    match Cli::try_parse_from(join_negative_values(argv)) {
        Ok(cli) => Ok(Ok(cli)),
        Err(e) => {
            use clap::error::ErrorKind;
            let text = e.render().to_string();
            match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => Ok(Err(text)),
                _ => Err(PalpateError::new_err(
                    text.trim_end().trim_start_matches("error: ").to_string(),
                )),
            }
        }
    }
}

/// Runs `palpate ARGS...` in this process, the GIL released. Returns the
/// help text for `--help`/`--version`, else None; raises PalpateError with
/// the command line's message (clap's for a bad option).
#[pyfunction]
fn run_cli(py: Python<'_>, args: Vec<String>) -> PyResult<Option<String>> {
    let cli = match try_parse(args)? {
        Ok(cli) => cli,
        Err(help) => return Ok(Some(help)),
    };
    py.detach(|| dispatch(cli)).map_err(to_py)?;
    Ok(None)
}

/// Progress lines on stderr (verbose) or nothing.
struct Say(bool);

impl RunObserver for Say {
    fn message(&self, text: &str) {
        if self.0 {
            eprintln!("{text}");
        }
    }
}

/// Runs a study manifest into its run folder (default runs/<study name>),
/// or one shard of it (`shard="I/N"`). Returns a dict: folder, computed,
/// cached, others (units of other shards not yet cached), deferred_steps.
#[pyfunction]
#[pyo3(signature = (manifest, out=None, shard=None, fresh=false, verbose=false))]
fn run_study<'py>(
    py: Python<'py>,
    manifest: PathBuf,
    out: Option<PathBuf>,
    shard: Option<String>,
    fresh: bool,
    verbose: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let shard = shard
        .map(|s| s.parse::<Shard>())
        .transpose()
        .map_err(|e| PalpateError::new_err(format!("shard {e}")))?;
    let options = RunOptions { out, fresh, shard };
    let s = py
        .detach(|| run_study_counted(&manifest, &options, &Say(verbose)))
        .map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("folder", s.folder)?;
    d.set_item("computed", s.units.computed)?;
    d.set_item("cached", s.units.cached)?;
    d.set_item("others", s.units.others)?;
    d.set_item("deferred_steps", s.deferred_steps)?;
    Ok(d)
}

/// Merges the shards of a run folder (`palpate merge`). Returns a dict:
/// folder, shards, cached, computed.
#[pyfunction]
#[pyo3(signature = (run_dir, verbose=false))]
fn merge<'py>(py: Python<'py>, run_dir: PathBuf, verbose: bool) -> PyResult<Bound<'py, PyDict>> {
    let m = py
        .detach(|| palpate_studies::study::merge::merge(&run_dir, &Say(verbose)))
        .map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("folder", m.folder)?;
    d.set_item("shards", m.shards)?;
    d.set_item("cached", m.cached)?;
    d.set_item("computed", m.computed)?;
    Ok(d)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("PalpateError", m.py().get_type::<PalpateError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(run_cli, m)?)?;
    m.add_function(wrap_pyfunction!(run_study, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::sample, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::identify_q1, m)?)?;
    Ok(())
}
