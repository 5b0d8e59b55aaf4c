"""palpate from Python: calibrate, simulate, sample, diagnose and run studies.

Every function runs palpate's own Rust implementation in this process (the
code behind the ``palpate`` command line, with its options, defaults and
checks), with the GIL released while it runs. Arrays go in as numpy arrays
(or file paths) and come out as numpy arrays; an error is raised as
:class:`PalpateError` carrying the message the command line prints.
``calibrate``, ``simulate`` and ``sample`` pass arrays in memory (no copy
at the boundary, docs/python.md says where); ``diagnose`` goes through
temporary files.

See docs/python.md for a worked example.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _native
from ._native import PalpateError, __version__
from ._native import merge as _merge
from ._native import run_cli as _run_cli
from ._native import run_study as _run_study

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


def _write_record(value: Any, test: str | None, folder: str, name: str) -> str:
    """A record as a file path: a path as it is; arrays written as CSV
    (see :func:`_columns`), for the functions that read files only."""
    columns = _columns(value, test, name)
    if columns is None:
        return os.fspath(value)
    names, cols = columns
    path = os.path.join(folder, f"{name}.csv")
    # repr-exact: 17 significant digits read back to the same doubles.
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    return path


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


def _data_options(data: Any, benchmark: str | None, folder: str) -> list[str]:
    """``--data`` options for a mapping {test: record} or one benchmark record."""
    if benchmark is not None and not isinstance(data, Mapping) or _is_columns(data):
        return ["--data", _write_record(data, None, folder, "record")]
    if isinstance(data, (str, os.PathLike)):
        return ["--data", os.fspath(data)]
    out = []
    for i, (test, rec) in enumerate(data.items()):
        base = test.split("[", 1)[0]
        path = _write_record(rec, base, folder, f"{i}-{base}")
        out += ["--data", f"{test}={path}"]
    return out


def _is_columns(data: Any) -> bool:
    """A mapping of column names to arrays (one record), not of tests to records."""
    return isinstance(data, Mapping) and any(
        k in ("displacement_mm", "force_N", "time_s") for k in data.keys()
    )


def _flags(options: Mapping[str, Any]) -> list[str]:
    """Keyword options as command-line options: ``mesh="coarse"`` ->
    ``--mesh coarse``; True -> a flag; a list or tuple -> the option repeated;
    a mapping -> ``--key NAME=VALUE`` repeated; None and False are left out."""
    out: list[str] = []
    for key, value in options.items():
        opt = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            out.append(opt)
        elif isinstance(value, Mapping):
            for k, v in value.items():
                if isinstance(v, (tuple, list)):
                    v = ",".join(repr(float(x)) for x in v)
                out += [opt, f"{k}={v}"]
        elif isinstance(value, (list, tuple)):
            for v in value:
                out += [opt, str(v)]
        else:
            out += [opt, repr(value) if isinstance(value, float) else str(value)]
    return out


def calibrate(law: str, data: Any, *, benchmark: str | None = None, fix: Mapping[str, float] | None = None, **options: Any) -> dict:
    """Fits ``law`` to ``data`` (``palpate calibrate``).

    ``data``: ``{test: record}`` for homogeneous tests (test = uniaxial,
    biaxial, planar, simple_shear, with reading options in brackets as on
    the command line), or one force record with ``benchmark="C1"``. A
    record is a CSV path, ``(x, y)`` arrays or ``{column: array}``.
    Options as ``palpate calibrate --help``: ``residual``, ``estimator``,
    ``viscoelastic``, ...; ``fix={"C01": 0.0}``.

    Returns the JSON of ``--json`` as a dict, with ``params`` (name ->
    value) and, per data set in ``predictions``, numpy arrays.

    Records given as float64 arrays go to palpate in memory (read there as
    borrowed slices); ``benchmark="Q1"`` (the staged FE identification)
    reads files, so its record is written to a temporary CSV.
    """
    flags = _flags({"benchmark": benchmark, "fix": fix, **options})
    if (benchmark or "").lower() != "q1":
        data_args, records = _data_in_memory(data, benchmark)
        result = json.loads(_native.calibrate_arrays(["--law", law, *data_args, *flags], records))
        _arrays(result)
        return result
    with tempfile.TemporaryDirectory(prefix="palpate-") as tmp:
        out = os.path.join(tmp, "fit.json")
        args = ["calibrate", "--law", law, *_data_options(data, benchmark, tmp), "--json", out]
        _run_cli(args + flags)
        result = json.loads(Path(out).read_text())
    _arrays(result)
    return result


def _arrays(result: dict) -> None:
    """Lists of numbers in a result as numpy arrays; ``params`` by value."""
    params = result.get("params")
    if isinstance(params, dict):
        result["param_values"] = {k: v.get("value") if isinstance(v, dict) else v for k, v in params.items()}
    for p in result.get("predictions", []) or []:
        for k in ("stretch_or_displacement", "time", "observed", "predicted"):
            if k in p and isinstance(p[k], list):
                p[k] = np.asarray(p[k], dtype=float)


def simulate(benchmark: str, law: str | None = None, params: Mapping[str, float] | None = None, **options: Any) -> dict:
    """Runs a finite-element benchmark (``palpate simulate``).

    ``params``: the law's parameters by name (MPa); options as ``palpate
    simulate --help`` (``mesh``, ``depth``, ``step``, ``friction``,
    ``error_estimate="off"``, ``prony``, ...). Returns the curve's columns as
    numpy arrays (``displacement_mm``, ``force_N`` and, when present,
    ``time_s``, ``error_estimate_N``; R2: ``position_mm``, ``force_N``,
    ``force_x_N``) and the ``comments`` the CSV carries.

    N1, N3, C1, Q1: the arrays are palpate's own vectors, moved into numpy
    (no copy, full precision). R2 (a scan) goes through a CSV file (values
    to the CSV's 10 significant digits).
    """
    args = ["--benchmark", benchmark]
    if law is not None:
        args += ["--law", law]
    for k, v in (params or {}).items():
        args += ["--param", f"{k}={float(v)!r}"]
    args += _flags(options)
    if benchmark.lower() != "r2":
        curve = _native.simulate_arrays(args)
        del curve["title"]
        return curve
    with tempfile.TemporaryDirectory(prefix="palpate-") as tmp:
        out = os.path.join(tmp, "curve.csv")
        _run_cli(["simulate", *args, "--csv", out])
        return _read_curve(out)


def _read_curve(path: str) -> dict:
    lines = Path(path).read_text().splitlines()
    comments = [line[1:].strip() for line in lines if line.startswith("#")]
    rows = [line for line in lines if line and not line.startswith("#")]
    header = rows[0].split(",")
    values = np.loadtxt(rows[1:], delimiter=",", ndmin=2) if len(rows) > 1 else np.empty((0, len(header)))
    out: dict = {name: values[:, i].copy() for i, name in enumerate(header)}
    out["comments"] = comments
    return out


def sample(law: str, data: Any, *, benchmark: str | None = None, seed: int = 0, arviz: bool | None = None, **options: Any):
    """Samples the posterior of ``law``'s parameters (``palpate sample``).

    ``data`` as for :func:`calibrate`; options as ``palpate sample --help``
    (``sampler``, ``draws``, ``max_draws``, ``tune``, ``parallel``,
    ``sigma``, ``prior={"C10": "lognormal:-7,1"}``, ``box`` for FE
    benchmarks, ...).

    Returns an ArviZ ``InferenceData`` (posterior draws per parameter,
    dims chain x draw; the summary in ``attrs``) when arviz is importable
    (``arviz=False`` refuses it), else a dict: ``draws`` (name -> array
    chains x draws), ``summary`` (the ``--json`` of the command line).

    The draws are palpate's own vector moved into numpy (no copy): each
    parameter's array is a strided view of it. Records given as float64
    arrays go to palpate in memory; for the FE benchmarks (N1, N3, Q1) the
    record is written to a temporary CSV (their surrogate reads files).
    """
    flags = _flags({"benchmark": benchmark, **options})
    with tempfile.TemporaryDirectory(prefix="palpate-") as tmp:
        if (benchmark or "").lower() in ("n1", "n3", "q1"):
            data_args, records = _data_options(data, benchmark, tmp), []
        else:
            data_args, records = _data_in_memory(data, benchmark)
        args = ["--law", law, *data_args, "--seed", str(seed), *flags]
        names, flat, n_chains, n_draws, summary = _native.sample_arrays(args, records)
    summary = json.loads(summary)
    values = flat.reshape(n_chains, n_draws, len(names))  # a view of palpate's vector
    draws = {name: values[:, :, j] for j, name in enumerate(names)}
    if arviz is not False:
        try:
            import arviz as az  # noqa: PLC0415
        except ImportError:
            if arviz:
                raise
        else:
            try:
                idata = az.from_dict(posterior=draws)  # arviz < 1: InferenceData
            except TypeError:
                idata = az.from_dict({"posterior": draws})  # arviz >= 1: an xarray DataTree
            idata.posterior.attrs["palpate_summary"] = json.dumps(summary)
            return idata
    return {"draws": draws, "summary": summary}


def diagnose(data: Any, *, benchmark: str | None = None, base: str = "neo-hookean", effects: list[str] | None = None, **options: Any) -> dict:
    """Diagnoses the gap between a base model and a record (``palpate diagnose``).

    ``data``: one record, ``{test: record}`` with one entry for a homogeneous
    test, or a force record with ``benchmark="C1"`` / ``"N1"``. Options as
    ``palpate diagnose --help`` (``alpha``, ``folds``). Returns the JSON of
    ``--json`` (the GAP.md contract) as a dict.
    """
    with tempfile.TemporaryDirectory(prefix="palpate-") as tmp:
        out = os.path.join(tmp, "gap.json")
        data_args = _data_options(data, benchmark, tmp)
        if len(data_args) != 2:
            raise PalpateError("diagnose: give one record (a mapping with one test, or one benchmark record)")
        args = ["diagnose", *data_args, "--base", base, "--json", out]
        if effects:
            args += ["--effects", ",".join(effects)]
        args += _flags({"benchmark": benchmark, **options})
        _run_cli(args)
        return json.loads(Path(out).read_text())


def run_study(manifest: str | os.PathLike, out: str | os.PathLike | None = None, *, shard: str | None = None, fresh: bool = False, verbose: bool = False) -> dict:
    """Runs a study manifest (``palpate run``) into its run folder.

    With ``shard="I/N"`` computes only that slice of the study's units into
    the folder's cache (docs/cluster.md); :func:`merge` then assembles the
    results. Returns ``folder`` (a Path), the unit counts (``computed``,
    ``cached``, ``others``), ``deferred_steps`` and, for a whole run,
    ``results`` (results.json as a dict).
    """
    s = _run_study(os.fspath(manifest), None if out is None else os.fspath(out), shard, fresh, verbose)
    s["folder"] = Path(s["folder"])
    if shard is None:
        s["results"] = json.loads((s["folder"] / "results.json").read_text())
    return s


def merge(run_dir: str | os.PathLike, *, verbose: bool = False) -> dict:
    """Assembles a study's results from its shards (``palpate merge``).

    Returns ``folder``, ``shards``, the units taken from the cache
    (``cached``) and computed by the merge (``computed``), and ``results``.
    """
    m = _merge(os.fspath(run_dir), verbose)
    m["folder"] = Path(m["folder"])
    m["results"] = json.loads((m["folder"] / "results.json").read_text())
    return m
