"""Arrays in and out without copies where docs/python.md says so, with the
results of the file path.

* out (``simulate``'s curve, ``sample``'s draws): the array's memory is
  palpate's Vec, moved into numpy; numpy sees an array that does not own its
  data and whose ``base`` is rust-numpy's container of that Vec. A copy made
  anywhere on the way (``np.array``, ``astype``, ``json`` -> list -> array)
  would own its data.
* in (``calibrate``, ``sample``): the caller's float64 arrays themselves,
  not copies, are what the Python side hands to palpate (checked by
  identity), and palpate reads them as borrowed slices.
* the same numbers as the file path (the command line with CSV/JSON files).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import palpate
from palpate import _native

ROOT = Path(__file__).resolve().parents[2]
TRELOAR = ROOT / "studies/data/treloar/uniaxial.csv"


def treloar() -> tuple[np.ndarray, np.ndarray]:
    rows = [line for line in TRELOAR.read_text().splitlines() if line and not line.startswith("#")]
    stretch, stress = np.loadtxt(rows[1:], delimiter=",", unpack=True)
    return np.ascontiguousarray(stretch), np.ascontiguousarray(stress)


def owner(a: np.ndarray):
    """The object at the end of an array's ``base`` chain, and whether any
    array on the way owns its data (a copy would)."""
    owns = False
    while isinstance(a, np.ndarray):
        owns = owns or a.flags.owndata
        a = a.base
    return a, owns


def assert_moved_from_rust(a: np.ndarray) -> None:
    base, owns = owner(a)
    assert not owns, "an array on the way owns its data: a copy"
    assert type(base).__name__ == "PySliceContainer", f"memory owned by {type(base)!r}, not a Rust Vec"


C1 = dict(law="neo-hookean", params={"C10": 0.2}, mesh="coarse", depth=1.0, step=0.25, error_estimate="off")


def test_simulate_moves_the_curve_out_and_equals_the_csv(tmp_path):
    c = palpate.simulate("C1", **C1)
    for k in ("displacement_mm", "force_N"):
        a = getattr(c, k)
        assert a.dtype == np.float64 and a.shape == (5,)
        assert_moved_from_rust(a)
    # The file path: the command line's CSV (forces to 10 significant
    # digits, displacements to 6 decimals), the same numbers as text.
    csv = tmp_path / "c1.csv"
    palpate.cli("simulate", "--benchmark", "C1", "--law", "neo-hookean", "--param", "C10=0.2",
                "--mesh", "coarse", "--depth", "1.0", "--step", "0.25", "--error-estimate", "off", "--csv", csv)
    rows = [r.split(",") for r in csv.read_text().splitlines() if r and not r.startswith("#")][1:]
    # (Rust writes 1.7e2 where Python writes 1.7e+02: compare the numbers.)
    assert [float(f"{d:.6f}") for d in c.displacement_mm] == [float(r[0]) for r in rows]
    assert [float(f"{f:.9e}") for f in c.force_N] == [float(r[1]) for r in rows]
    assert c.force_N[-1] > 0
    assert c.comments == [line[2:] for line in csv.read_text().splitlines() if line.startswith("# ")]


def test_calibrate_hands_the_callers_arrays_to_palpate_and_fits_as_from_the_file(monkeypatch):
    stretch, stress = treloar()
    seen = []
    real = _native.calibrate

    def spy(law, data, records, **options):
        seen.append(records)
        return real(law, data, records, **options)

    monkeypatch.setattr(_native, "calibrate", spy)
    fit = palpate.calibrate("yeoh", {"uniaxial": (stretch, stress)})
    (names, cols), = seen[0]
    assert names == ["stretch", "stress_MPa"]
    assert cols[0] is stretch and cols[1] is stress, "the arrays were copied before palpate"
    from_file = palpate.calibrate("yeoh", {"uniaxial": TRELOAR})
    assert fit.params == from_file.params and fit.sse == from_file.sse
    assert np.array_equal(fit.predictions[0].predicted, from_file.predictions[0].predicted)


def test_other_dtypes_and_strided_views_are_converted_and_fit_the_same():
    stretch, stress = treloar()
    base = palpate.calibrate("neo-hookean", {"uniaxial": {"stretch": stretch, "stress_MPa": stress}})
    # A strided (non-contiguous) view is copied once in Rust; float32 is converted in Python.
    wide = np.zeros((stretch.size, 2))
    wide[:, 0] = stress
    strided = palpate.calibrate("neo-hookean", {"uniaxial": (stretch, wide[:, 0])})
    assert not wide[:, 0].flags.c_contiguous
    assert strided.params == base.params
    f32 = palpate.calibrate("neo-hookean", {"uniaxial": (stretch.astype(np.float32), stress)})
    assert f32.converged


def test_sample_moves_the_draws_out_and_equals_the_files(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    stretch, stress = treloar()
    opts = dict(sampler="nuts", draws=60, max_draws=60, tune=60, parallel=2, seed=3)
    post = palpate.sample("neo-hookean", {"uniaxial": (stretch, stress)}, arviz=False, **opts)
    c10 = post.draws["C10"]
    assert c10.shape == (2, 60)
    assert_moved_from_rust(c10)
    # The file path: the command line reading the CSV, writing the draws as JSON.
    chains = tmp_path / "chains.json"
    palpate.cli("sample", "--law", "neo-hookean", "--data", f"uniaxial={TRELOAR}", "--sampler", "nuts",
                "--draws", "60", "--max-draws", "60", "--tune", "60", "--parallel", "2", "--seed", "3",
                "--chains", chains)
    ch = json.loads(chains.read_text())
    values = np.asarray(ch["values"]).reshape(ch["n_chains"], ch["n_draws"], len(ch["names"]))
    assert list(post.draws) == ch["names"]
    for j, name in enumerate(ch["names"]):
        assert np.array_equal(post.draws[name], values[:, :, j]), name


def message(call) -> str:
    with pytest.raises(palpate.PalpateError) as e:
        call()
    return str(e.value)


def test_errors_carry_the_command_lines_messages(tmp_path):
    stretch, stress = treloar()
    assert "expected lm, bfgs or lbfgs" in message(
        lambda: palpate.calibrate("yeoh", {"uniaxial": (stretch, stress)}, estimator="newton"))
    # The same message as the command line's, word for word.
    assert message(lambda: palpate.simulate("C1", law="nonsense", params={"C10": 0.2})) == message(
        lambda: palpate.cli("simulate", "--benchmark", "C1", "--law", "nonsense", "--param", "C10=0.2"))
    assert message(lambda: palpate.sample("neo-hookean", {"uniaxial": TRELOAR}, sampler="gibbs", arviz=False)) == message(
        lambda: palpate.cli("sample", "--law", "neo-hookean", "--data", f"uniaxial={TRELOAR}", "--sampler", "gibbs"))
    # A bad value in an array: the CSV reader's message, with the row's line
    # as in the CSV the file path writes (header = line 1).
    bad = stress.copy()
    bad[1] = np.nan
    assert "uniaxial arrays:3: column `stress_MPa`: value is NaN or infinite" in message(
        lambda: palpate.calibrate("yeoh", {"uniaxial": (stretch, bad)}))


def test_a_c1_force_record_as_arrays_fits_and_samples_as_the_file():
    path = ROOT / "tests/data/mesa2011/c1-compression.csv"
    rows = [line for line in path.read_text().splitlines() if line and not line.startswith("#")]
    d, f = np.loadtxt(rows[1:], delimiter=",", unpack=True)
    a = palpate.calibrate("neo-hookean", (d, f), benchmark="C1")
    b = palpate.calibrate("neo-hookean", path, benchmark="C1")
    assert a.params == b.params and a.sse == b.sse
    kw = dict(benchmark="C1", sampler="demc", draws=50, max_draws=50, tune=50, parallel=1, seed=2, arviz=False)
    x = palpate.sample("neo-hookean", {"displacement_mm": d, "force_N": f}, **kw)
    y = palpate.sample("neo-hookean", path, **kw)
    assert np.array_equal(x.draws["C10"], y.draws["C10"])
    assert_moved_from_rust(x.draws["C10"])


def test_diagnose_reads_arrays_in_memory_as_the_file():
    """No temporary file: the arrays are the record, diagnosed as the CSV is."""
    stretch, stress = treloar()
    a = palpate.diagnose({"uniaxial": (stretch, stress)}, folds=2)
    b = palpate.diagnose({"uniaxial": TRELOAR}, folds=2)
    assert a.verdict == b.verdict and a.ranking == b.ranking and a.ranking
