"""The result objects of the palpate package: numpy arrays and the report
as attributes, a short ``repr``, and ``to_dict()`` for JSON-like data."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np


def _plain(value: Any) -> Any:
    """A value as JSON-like data: arrays as lists, paths as text."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return value.to_dict()
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _short(value: Any) -> str:
    if isinstance(value, np.ndarray):
        return f"array(shape={value.shape})"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, dict):
        if len(value) > 6 or any(isinstance(v, (dict, list, np.ndarray)) for v in value.values()):
            return "{" + ", ".join(map(str, value)) + "}"
        return "{" + ", ".join(f"{k}: {_short(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return f"[{len(value)} items]"
    return repr(value)


class _Result:
    """Common behaviour: ``to_dict()`` and a one-line ``repr`` of the fields
    (arrays by shape, the full report left out)."""

    _repr_skip: tuple[str, ...] = ("report",)

    def to_dict(self) -> dict:
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def __repr__(self) -> str:
        fields = [
            f"{f.name}={_short(getattr(self, f.name))}"
            for f in dataclasses.fields(self)
            if f.name not in self._repr_skip and getattr(self, f.name) is not None
        ]
        return f"{type(self).__name__}({', '.join(fields)})"


@dataclasses.dataclass(repr=False)
class Prediction(_Result):
    """One data set of a calibration: the observed and predicted values
    along the stretch (or displacement in mm), and the fit's R^2 and RMS."""

    data: str
    test: str
    fitted: bool
    r2: float
    rms: float
    stretch_or_displacement: np.ndarray
    observed: np.ndarray
    predicted: np.ndarray
    time: np.ndarray | None = None


@dataclasses.dataclass(repr=False)
class Calibration(_Result):
    """A fit (``palpate.calibrate``): ``params`` (name -> value), their
    ``standard_errors``, ``r2``, ``rms``, ``sse``, ``converged``,
    ``identifiable``, ``predictions`` (one :class:`Prediction` per data set)
    and ``report``, the whole result as the command line's ``--json`` writes
    it."""

    law: str
    params: dict
    standard_errors: dict
    r2: float | None
    rms: float | None
    sse: float | None
    converged: bool | None
    identifiable: bool | None
    predictions: list
    report: dict

    @classmethod
    def from_report(cls, report: dict) -> "Calibration":
        params = report.get("params") or {}
        values = {k: v.get("value") if isinstance(v, dict) else v for k, v in params.items()}
        ses = {k: v.get("standard_error") for k, v in params.items() if isinstance(v, dict)}
        preds = []
        for p in report.get("predictions") or []:
            arr = {k: np.asarray(p[k], dtype=float) for k in ("stretch_or_displacement", "observed", "predicted")}
            time = np.asarray(p["time"], dtype=float) if p.get("time") is not None else None
            preds.append(Prediction(p.get("data"), _test_name(p.get("test")), p.get("fitted"), p.get("r2"), p.get("rms"),
                                    time=time, **arr))
        return cls(report.get("law", ""), values, ses, report.get("r2"), report.get("rms"), report.get("sse"),
                   report.get("converged"), report.get("identifiable"), preds, report)


@dataclasses.dataclass(repr=False)
class Curve(_Result):
    """A simulated force curve (``palpate.simulate``): ``displacement_mm``,
    ``force_N`` and, when present, ``time_s`` and ``error_estimate_N``
    (numpy arrays); R2 scans carry ``position_mm`` and ``force_x_N``
    instead of ``displacement_mm``, and their pressing phase
    (``press_displacement_mm``, ``press_force_N``, ``press_force_x_N``). ``comments``: the lines the CSV of the
    command line starts with (model, volumetric treatment, error estimate)."""

    force_N: np.ndarray
    displacement_mm: np.ndarray | None = None
    time_s: np.ndarray | None = None
    error_estimate_N: np.ndarray | None = None
    position_mm: np.ndarray | None = None
    force_x_N: np.ndarray | None = None
    press_displacement_mm: np.ndarray | None = None
    press_force_N: np.ndarray | None = None
    press_force_x_N: np.ndarray | None = None
    comments: list = dataclasses.field(default_factory=list)
    title: str | None = None


@dataclasses.dataclass(repr=False)
class Posterior(_Result):
    """Posterior draws (``palpate.sample`` without ArviZ): ``draws`` (name
    -> array of shape (chains, draws)), ``summary`` (the command line's
    ``--json``: per parameter mean, sd, rhat, ess, ...), ``table`` and
    ``warnings`` (what the command line prints)."""

    draws: dict
    summary: dict
    table: str = ""
    warnings: list = dataclasses.field(default_factory=list)

    _repr_skip = ("summary", "table", "warnings")


@dataclasses.dataclass(repr=False)
class Diagnosis(_Result):
    """A gap diagnosis (``palpate.diagnose``): ``verdict``, ``ranking`` (the
    effects, best first) and ``report`` (the GAP.md contract as a dict)."""

    verdict: Any
    ranking: list
    report: dict


@dataclasses.dataclass(repr=False)
class StudyRun(_Result):
    """A study run (``palpate.run_study``) or merge (``palpate.merge``):
    the run ``folder``, the unit counts and, once the study is complete,
    ``results`` (results.json as a dict)."""

    folder: Path
    computed: int
    cached: int
    others: int | None = None
    shards: int | None = None
    deferred_steps: list | None = None
    results: dict | None = None

    _repr_skip = ("results",)


def _test_name(test):
    """The test kind as its name: the library writes a homogeneous test as
    ``{"homogeneous": "uniaxial"}`` and the others as a plain string."""
    if isinstance(test, dict) and len(test) == 1:
        return str(next(iter(test.values())))
    return test
