"""palpate from Python: calibrate, simulate, sample, diagnose and run studies.

Every function runs palpate's own Rust implementation in this process, with
the GIL released while it runs. Each takes its options as keywords checked
by Python (a misspelt one raises ``TypeError``); a value palpate refuses
raises :class:`PalpateError` carrying the message the command line prints.
Arrays go in as numpy arrays (or file paths) and come out as numpy arrays
in result objects (:class:`Calibration`, :class:`Curve`,
:class:`Posterior`, :class:`Diagnosis`, :class:`StudyRun`; ``to_dict()``
gives JSON-like data). The functions print nothing unless ``verbose=True``.
``calibrate``, ``simulate``, ``sample`` and ``diagnose`` call palpate's
typed library API (the functions the command line calls after reading its
options) and pass arrays in memory (no copy at the boundary, docs/python.md
says where).

See docs/python.md for a worked example.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _native
from ._native import PalpateError, __version__
from ._native import merge as _merge
from ._native import run_cli as _run_cli
from ._native import run_study as _run_study
from ._quiet import quiet as _quiet
from ._results import Calibration, Curve, Diagnosis, Posterior, Prediction, StudyRun

__all__ = [
    "PalpateError",
    "__version__",
    "calibrate",
    "simulate",
    "sample",
    "diagnose",
    "run_study",
    "merge",
    "cli",
    "Calibration",
    "Curve",
    "Diagnosis",
    "Posterior",
    "Prediction",
    "StudyRun",
]

# The columns of a record given as (x, y) arrays, per test (the reader's names).
_COLUMNS = {
    "uniaxial": ("stretch", "stress_MPa"),
    "biaxial": ("stretch", "stress_MPa"),
    "planar": ("stretch", "stress_MPa"),
    "simple_shear": ("amount_of_shear", "shear_stress_MPa"),
}
_FORCE = ("displacement_mm", "force_N")


def cli(*args: str) -> str | None:
    """Runs ``palpate ARGS...`` in this process (``cli("--help")`` returns the help)."""
    return _run_cli([str(a) for a in args])


def _columns(value: Any, test: str | None, name: str) -> tuple[list[str], list[np.ndarray]] | None:
    """A record's column names and float64 columns, or None for a path.

    Arrays: a mapping ``{column: array}`` with the reader's column names
    (``stretch``, ``stress_MPa``, ``time_s``, ``displacement_mm``,
    ``force_N``, ...), or a pair ``(x, y)`` (stretch and nominal stress in
    MPa for a homogeneous test; displacement in mm and force in N for a
    benchmark record), or an (n, 2) array read the same way. A float64
    array is taken as it is (``np.asarray`` makes no copy of it); other
    dtypes are converted.
    """
    if isinstance(value, (str, os.PathLike)):
        return None
    if isinstance(value, Mapping):
        names = list(value.keys())
        cols = [_column(value[k]) for k in names]
    else:
        arr = value if isinstance(value, (tuple, list)) else np.asarray(value, dtype=np.float64).T
        if len(arr) != 2:
            raise PalpateError(
                f"record `{name}`: give a path, a mapping {{column: array}} or a pair (x, y); got {len(arr)} columns"
            )
        names = list(_COLUMNS.get((test or "").lower(), _FORCE))
        cols = [_column(c) for c in arr]
    if len({c.size for c in cols}) != 1:
        sizes = ", ".join(f"{n}: {c.size}" for n, c in zip(names, cols))
        raise PalpateError(f"record `{name}`: columns of different lengths ({sizes})")
    return names, cols


def _column(values: Any) -> np.ndarray:
    """A column as a 1-D float64 array: a 1-D float64 array is returned as
    it is (the same object, so palpate reads the caller's memory)."""
    a = np.asarray(values, dtype=np.float64)
    return a if a.ndim == 1 else a.ravel()


def _data_in_memory(data: Any, benchmark: str | None) -> tuple[list[str], list]:
    """``--data`` options and the records they name: a record given as
    arrays is ``--data TEST=<array:K>`` with K its place in the list (passed
    to palpate in memory), a path is ``--data TEST=PATH``."""
    records: list = []

    def option(value: Any, test: str | None, name: str) -> str:
        columns = _columns(value, test, name)
        if columns is None:
            return os.fspath(value)
        records.append(columns)
        return f"<array:{len(records) - 1}>"

    if benchmark is not None and not isinstance(data, Mapping) or _is_columns(data):
        return ["--data", option(data, None, "record")], records
    if isinstance(data, (str, os.PathLike)):
        return ["--data", os.fspath(data)], records
    out = []
    for i, (test, rec) in enumerate(data.items()):
        base = test.split("[", 1)[0]
        out += ["--data", f"{test}={option(rec, base, f'{i}-{base}')}"]
    return out, records


def _is_columns(data: Any) -> bool:
    """A mapping of column names to arrays (one record), not of tests to records."""
    return isinstance(data, Mapping) and any(
        k in ("displacement_mm", "force_N", "time_s") for k in data.keys()
    )


def _experiment_option(experiment: Any) -> list[str]:
    """``--experiment`` for a description given as a dict (passed as JSON
    text, read by the same description types as an experiment file), a
    file path or a preset's name."""
    if experiment is None:
        return []
    if isinstance(experiment, Mapping):
        return ["--experiment", json.dumps(experiment)]
    if isinstance(experiment, (str, os.PathLike)):
        return ["--experiment", os.fspath(experiment)]
    raise TypeError(f"experiment: expected a dict, a file path or a preset name, not {type(experiment).__name__}")


def calibrate(
    law: str | None = None,
    data: Any = None,
    *,
    experiment: Any = None,
    benchmark: str | None = None,
    residual: str = "absolute",
    estimator: str = "lm",
    fix: Mapping[str, float] | None = None,
    viscoelastic: str | None = None,
    stages: str | None = None,
    prony_terms: int | None = None,
    fit_mesh: float | None = None,
    correct_mesh: float | None = None,
    time_step: float | None = None,
    edge_radius: float | None = None,
    fit_edge_radius: float | None = None,
    mesh_check: float | None = None,
    compare: bool = False,
    profile: bool = False,
    verbose: bool = False,
) -> Calibration:
    """Fits ``law`` to ``data`` (as ``palpate calibrate``).

    ``data``: ``{test: record}`` for homogeneous tests (test = uniaxial,
    biaxial, planar, simple_shear, with reading options in brackets as on
    the command line, e.g. ``"simple_shear[weight=0.5]"``), or one force
    record with ``benchmark="C1"`` (or ``"Q1"``, the staged FE
    identification). A record is a CSV path, ``(x, y)`` arrays or
    ``{column: array}``.

    ``experiment``: a lab's own experiment (a dict with the fields of an
    experiment file, a file path or a preset's name, docs/guide/experiment.md)
    instead of ``law``: its fitted parameters are estimated from one force
    record by finite elements, its fixed ones held.

    ``residual``: absolute, relative or normalised; ``estimator``: lm, bfgs
    or lbfgs; ``fix``: parameters held, e.g. ``{"C01": 0.0}``;
    ``viscoelastic``: ``"qlv:N"`` or ``"finite:N"`` for timed records. The
    options ``stages`` to ``profile`` are those of ``benchmark="Q1"``
    (``palpate calibrate --help`` says what each does). ``verbose``: print
    palpate's progress and report.

    Returns a :class:`Calibration` (``params``, ``standard_errors``, ``r2``,
    ``converged``, ``predictions`` with numpy arrays, ``report``).

    Records given as float64 arrays go to palpate in memory (read there as
    borrowed slices), for ``benchmark="Q1"`` too.
    """
    if data is None:
        raise TypeError("calibrate() missing required argument: 'data'")
    if law is None and experiment is None:
        raise TypeError("calibrate() needs 'law' or 'experiment'")
    q1_options = dict(stages=stages, prony_terms=prony_terms, fit_mesh=fit_mesh, correct_mesh=correct_mesh,
                      time_step=time_step, edge_radius=edge_radius, fit_edge_radius=fit_edge_radius,
                      mesh_check=mesh_check, compare=compare, profile=profile)
    if (benchmark or "").lower() != "q1":
        given = [k for k, v in q1_options.items() if v not in (None, False)]
        if given:
            name = "--" + given[0].replace("_", "-")
            if experiment is not None:
                raise PalpateError(f"{name}: not an option of an experiment's calibration "
                                   "(its description holds the model)")
            raise PalpateError(f"{name}: an option of --benchmark Q1 (the staged inverse FE identification)")
        one_record = benchmark if experiment is None else "experiment"
        data_args, records = _data_in_memory(data, one_record)
        specs = data_args[1::2]  # the values of the --data options
        experiment_text = _experiment_option(experiment)[1:] or [None]
        report = _native.calibrate(
            law, specs, records, experiment=experiment_text[0], benchmark=benchmark, residual=residual,
            estimator=estimator, fix=[(k, float(v)) for k, v in (fix or {}).items()],
            viscoelastic=viscoelastic, verbose=verbose)
        return Calibration.from_report(report)
    # The staged identification of one ramp-and-hold record.
    for name, given in (("viscoelastic", viscoelastic is not None), ("fix", bool(fix))):
        if given:
            raise PalpateError(f"--{name}: not an option of --benchmark Q1")
    if residual != "absolute" or estimator != "lm":
        raise PalpateError("--benchmark Q1 fits by Levenberg-Marquardt on absolute residuals "
                           "(--residual absolute, --estimator lm)")
    if law is None:
        raise TypeError("calibrate(benchmark='Q1') needs 'law'")
    data_args, records = _data_in_memory(data, benchmark)
    if len(data_args) != 2:
        raise PalpateError(f"--benchmark Q1: give one record (--data FILE), got {len(data_args) // 2}")
    report, text = _native.identify_q1(law, data_args[1], records, verbose=verbose, **q1_options)
    if verbose:
        print(text, end="")
    return Calibration.from_report(report)


def simulate(
    benchmark: str | None = None,
    law: str | None = None,
    params: Mapping[str, float] | None = None,
    *,
    experiment: Any = None,
    mesh: str | int | None = None,
    depth: float | None = None,
    step: float | None = None,
    friction: float | None = None,
    tool: str | None = None,
    element: str | None = None,
    bulk: str | float | None = None,
    bonded: bool = False,
    sliding_base: bool = False,
    edge_radius: float | None = None,
    prony: str | None = None,
    ramp: float | None = None,
    hold: float | None = None,
    error_estimate: str = "on",
    order: float | None = None,
    accuracy: float | None = None,
    rd: float | None = None,
    nodules: str | None = None,
    nodule_law: str | None = None,
    nodule_params: Mapping[str, float] | None = None,
    verbose: bool = False,
) -> Curve:
    """Runs a finite-element benchmark or a lab's own experiment (as
    ``palpate simulate``).

    ``experiment``: the description (a dict with the fields of an experiment
    file, a file path or a preset's name, docs/guide/experiment.md) instead
    of ``benchmark``; it holds the specimen, materials, tool, protocol and
    mesh, so the benchmark's options do not apply; ``params`` set its
    parameters by name (default: their starts).

    ``params``: the law's parameters by name (MPa). ``mesh``: coarse,
    medium, fine or a level; ``depth`` and ``step`` in mm; ``friction``,
    ``tool``, ``element``, ``bulk``, ``bonded`` (C1), ``sliding_base`` (N1),
    ``edge_radius`` (Q1); ``prony="g1=..,tau1=.."`` with ``ramp`` and
    ``hold`` in s; ``error_estimate`` ``"on"``/``"off"`` and ``order``;
    ``accuracy`` (N1, N3): the mesh chosen for this relative error of the
    force instead of ``mesh``; R2: ``rd``, ``nodules``, ``nodule_law``,
    ``nodule_params``.
    ``palpate simulate --help`` says what each does and its default.
    ``verbose``: print the FE summary and the error estimate.

    Returns a :class:`Curve`: ``displacement_mm``, ``force_N`` and, when
    present, ``time_s``, ``error_estimate_N`` (R2: ``position_mm``,
    ``force_N``, ``force_x_N``, ``error_estimate_N`` and the pressing phase,
    ``press_displacement_mm``, ``press_force_N``, ``press_force_x_N``), and
    ``comments``. The arrays are palpate's own vectors, moved into numpy (no
    copy, full precision).
    """
    if (benchmark is None) == (experiment is None):
        raise TypeError("simulate() needs exactly one of 'benchmark' and 'experiment'")
    curve = _native.simulate(
        benchmark, (_experiment_option(experiment)[1:] or [None])[0], law,
        [(k, float(v)) for k, v in (params or {}).items()],
        friction=friction, rd=rd, nodules=nodules, nodule_law=nodule_law,
        nodule_params=[(k, float(v)) for k, v in (nodule_params or {}).items()],
        bonded=bonded, sliding_base=sliding_base, tool=tool, element=element, edge_radius=edge_radius,
        depth=depth, step=step, mesh=None if mesh is None else str(mesh), accuracy=accuracy,
        bulk=_text(bulk), error_estimate=error_estimate, order=order, prony=prony, ramp=ramp, hold=hold,
        verbose=verbose)
    return Curve(**curve)


def _text(value: Any) -> str | None:
    """An option that is a number or a name (``bulk=1000.0`` or ``"exact"``)
    as palpate reads it."""
    if value is None:
        return None
    return repr(value) if isinstance(value, float) else str(value)


def sample(
    law: str | None = None,
    data: Any = None,
    *,
    experiment: Any = None,
    benchmark: str | None = None,
    sampler: str = "nuts",
    draws: int | None = None,
    max_draws: int | None = None,
    tune: int | None = None,
    parallel: int | None = None,
    seed: int = 0,
    sigma: float | None = None,
    ar1: bool = False,
    prior: Mapping[str, str] | None = None,
    evidence: bool = False,
    box: Mapping[str, tuple[float, float]] | None = None,
    mesh: str | int | None = None,
    bulk: str | float | None = None,
    friction: float | None = None,
    prony: str | None = None,
    edge_radius: float | None = None,
    design: int | None = None,
    holdout: int | None = None,
    cache: str | os.PathLike | None = None,
    arviz: bool | None = None,
    verbose: bool = False,
):
    """Samples the posterior of ``law``'s parameters (as ``palpate sample``).

    ``data`` as for :func:`calibrate`. ``experiment``: a lab's own
    experiment (a dict, a file path or a preset's name) instead of ``law``,
    sampled through a surrogate of its FE model (``box`` for each of its
    parameters). ``sampler``: nuts, ensemble or demc; ``draws``,
    ``max_draws``, ``tune``, ``parallel`` (chains), ``seed``; ``sigma``
    (noise, estimated when None), ``ar1``; ``prior={"C10":
    "lognormal:-7,1"}``; ``evidence`` (thermodynamic integration, needs a
    proper prior on every parameter). FE benchmarks (N1, N3, Q1): ``box={"C10":
    (lo, hi)}``, ``mesh``, ``bulk``, ``friction``, ``prony``,
    ``edge_radius``, ``design``, ``holdout``, ``cache`` (the surrogate's).
    ``palpate sample --help`` says what each does and its default.
    ``verbose``: print the sampler's progress, its table and warnings.

    Returns an ArviZ ``InferenceData`` (posterior draws per parameter, dims
    chain x draw; the summary in ``attrs``) when arviz is importable
    (``arviz=False`` refuses it), else a :class:`Posterior` (``draws``:
    name -> array chains x draws; ``summary``, the report of ``palpate
    sample --json``; ``table`` and ``warnings``, what the command line prints).

    The draws are palpate's own vector moved into numpy (no copy): each
    parameter's array is a strided view of it. Records given as float64
    arrays go to palpate in memory, for the FE benchmarks too.
    """
    if data is None:
        raise TypeError("sample() missing required argument: 'data'")
    if law is None and experiment is None:
        raise TypeError("sample() needs 'law' or 'experiment'")
    fe = experiment is not None or (benchmark or "").lower() in ("n1", "n3", "q1")
    one_record = benchmark if experiment is None else "experiment"
    data_args, records = _data_in_memory(data, one_record)
    boxes = [f"{k}={float(lo)!r},{float(hi)!r}" for k, (lo, hi) in (box or {}).items()]
    # The surrogate's cache reports its FE runs on the process's stderr itself.
    with _quiet(fe and not verbose):
        names, flat, n_chains, n_draws, summary, table, warnings = _native.sample(
            law, data_args[1::2], records, experiment=(_experiment_option(experiment)[1:] or [None])[0],
            benchmark=benchmark, sampler=sampler, draws=draws, max_draws=max_draws, tune=tune,
            parallel=parallel, seed=seed, sigma=sigma, ar1=ar1,
            prior=[f"{k}={v}" for k, v in (prior or {}).items()], boxes=boxes,
            mesh=None if mesh is None else str(mesh), bulk=_text(bulk), friction=friction, prony=prony,
            edge_radius=edge_radius, design=design, holdout=holdout,
            cache=None if cache is None else os.fspath(cache), evidence=evidence, verbose=verbose)
    if verbose:
        print(table, end="")
        for w in warnings:
            print(w, file=sys.stderr)
    values = flat.reshape(n_chains, n_draws, len(names))  # a view of palpate's vector
    drawn = {name: values[:, :, j] for j, name in enumerate(names)}
    if arviz is not False:
        try:
            import arviz as az  # noqa: PLC0415
        except ImportError:
            if arviz:
                raise
        else:
            try:
                idata = az.from_dict(posterior=drawn)  # arviz < 1: InferenceData
            except TypeError:
                idata = az.from_dict({"posterior": drawn})  # arviz >= 1: an xarray DataTree
            idata.posterior.attrs["palpate_summary"] = json.dumps(summary)
            return idata
    return Posterior(drawn, summary, table, list(warnings))


def diagnose(
    data: Any,
    *,
    benchmark: str | None = None,
    base: str = "neo-hookean",
    effects: list[str] | None = None,
    alpha: float | None = None,
    folds: int | None = None,
    verbose: bool = False,
) -> Diagnosis:
    """Diagnoses the gap between a base model and a record (as ``palpate diagnose``).

    ``data``: one record, ``{test: record}`` with one entry for a homogeneous
    test, or a force record with ``benchmark="C1"`` / ``"N1"``. ``base``:
    the base law; ``effects``: the candidate effects (all by default);
    ``alpha`` and ``folds`` as ``palpate diagnose --help``. ``verbose``:
    print the report. Records given as float64 arrays go to palpate in
    memory.

    Returns a :class:`Diagnosis`: ``verdict``, ``ranking`` and ``report``
    (the GAP.md contract as a dict).
    """
    data_args, records = _data_in_memory(data, benchmark)
    if len(data_args) != 2:
        raise PalpateError("diagnose: give one record (a mapping with one test, or one benchmark record)")
    report = _native.diagnose(data_args[1], records, benchmark=benchmark, base=base, effects=list(effects or []),
                              alpha=alpha, folds=folds, verbose=verbose)
    return Diagnosis(report.get("verdict"), report.get("ranking") or [], report)


def run_study(manifest: str | os.PathLike, out: str | os.PathLike | None = None, *, shard: str | None = None, fresh: bool = False, verbose: bool = False) -> StudyRun:
    """Runs a study manifest (``palpate run``) into its run folder.

    With ``shard="I/N"`` computes only that slice of the study's units into
    the folder's cache (docs/cluster.md); :func:`merge` then assembles the
    results. Returns a :class:`StudyRun`: ``folder`` (a Path), the unit
    counts (``computed``, ``cached``, ``others``), ``deferred_steps`` and,
    for a whole run, ``results`` (results.json as a dict).
    """
    with _quiet(not verbose):
        s = _run_study(os.fspath(manifest), None if out is None else os.fspath(out), shard, fresh, verbose)
    folder = Path(s["folder"])
    results = json.loads((folder / "results.json").read_text()) if shard is None else None
    return StudyRun(folder, s["computed"], s["cached"], others=s["others"],
                    deferred_steps=list(s["deferred_steps"]), results=results)


def merge(run_dir: str | os.PathLike, *, verbose: bool = False) -> StudyRun:
    """Assembles a study's results from its shards (``palpate merge``).

    Returns a :class:`StudyRun`: ``folder``, ``shards``, the units taken from
    the cache (``cached``) and computed by the merge (``computed``), and
    ``results``.
    """
    with _quiet(not verbose):
        m = _merge(os.fspath(run_dir), verbose)
    folder = Path(m["folder"])
    results = json.loads((folder / "results.json").read_text())
    return StudyRun(folder, m["computed"], m["cached"], shards=m["shards"], results=results)
