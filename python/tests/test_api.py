"""The package's API: keywords checked by Python, result objects, quiet
unless asked, and palpate's own messages for values it refuses."""

from __future__ import annotations

import inspect
import os
from pathlib import Path

import numpy as np
import pytest

import palpate

ROOT = Path(__file__).resolve().parents[2]
TRELOAR = ROOT / "studies/data/treloar/uniaxial.csv"
C1 = dict(law="neo-hookean", params={"C10": 0.2}, mesh="coarse", depth=1.0, step=0.5)


def treloar() -> tuple[np.ndarray, np.ndarray]:
    rows = [line for line in TRELOAR.read_text().splitlines() if line and not line.startswith("#")]
    return np.loadtxt(rows[1:], delimiter=",", unpack=True)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: palpate.calibrate("yeoh", {"uniaxial": TRELOAR}, estimater="lm"), "estimater"),
        (lambda: palpate.simulate("C1", law="neo-hookean", params={"C10": 0.2}, mesh_size="coarse"), "mesh_size"),
        (lambda: palpate.sample("neo-hookean", {"uniaxial": TRELOAR}, n_draws=10), "n_draws"),
        (lambda: palpate.diagnose({"uniaxial": TRELOAR}, bse="yeoh"), "bse"),
        (lambda: palpate.run_study("studies/treloar-laws.toml", shards="0/2"), "shards"),
        (lambda: palpate.merge("runs/x", quiet=True), "quiet"),
    ],
)
def test_a_misspelt_keyword_is_a_type_error_naming_it(call, name):
    """Raised by Python before palpate runs (no usage text of the command line)."""
    with pytest.raises(TypeError, match=name) as e:
        call()
    assert "Usage" not in str(e.value)


def test_every_option_is_a_keyword_of_the_signature():
    """The options are listed (help(), an editor's completion), not **kwargs."""
    for f in (palpate.calibrate, palpate.simulate, palpate.sample, palpate.diagnose, palpate.run_study, palpate.merge):
        kinds = {p.kind for p in inspect.signature(f).parameters.values()}
        assert inspect.Parameter.VAR_KEYWORD not in kinds, f.__name__
        assert "verbose" in inspect.signature(f).parameters, f.__name__
    assert {"residual", "estimator", "fix", "viscoelastic"} <= set(inspect.signature(palpate.calibrate).parameters)
    assert {"mesh", "depth", "step", "error_estimate", "prony"} <= set(inspect.signature(palpate.simulate).parameters)
    assert {"sampler", "draws", "tune", "parallel", "seed", "prior", "box"} <= set(inspect.signature(palpate.sample).parameters)


def test_a_value_palpate_refuses_carries_its_message():
    stretch, stress = treloar()
    with pytest.raises(palpate.PalpateError, match="expected lm, bfgs or lbfgs"):
        palpate.calibrate("yeoh", {"uniaxial": (stretch, stress)}, estimator="newton")
    with pytest.raises(palpate.PalpateError, match="residual"):
        palpate.calibrate("yeoh", {"uniaxial": (stretch, stress)}, residual="squared")


def test_calibration_is_an_object_with_arrays_and_the_report():
    stretch, stress = treloar()
    fit = palpate.calibrate("mooney-rivlin", {"uniaxial": (stretch, stress)})
    assert isinstance(fit, palpate.Calibration)
    assert list(fit.params) == ["C10", "C01"] and all(isinstance(v, float) for v in fit.params.values())
    assert set(fit.standard_errors) == {"C10", "C01"}
    assert fit.converged is True and 0 < fit.r2 <= 1 and fit.law == fit.report["law"]
    (p,) = fit.predictions
    assert isinstance(p, palpate.Prediction) and p.test == "uniaxial" and p.fitted
    assert isinstance(p.predicted, np.ndarray) and p.predicted.shape == stretch.shape
    assert np.array_equal(p.observed, stress)
    text = repr(fit)
    assert text.startswith("Calibration(law=") and "C10" in text and "r2=" in text
    assert len(text) < 400, text
    d = fit.to_dict()
    assert d["params"] == fit.params and isinstance(d["predictions"][0]["predicted"], list)
    assert d["report"]["params"]["C10"]["value"] == fit.params["C10"]


def test_curve_is_an_object_with_arrays():
    c = palpate.simulate("C1", error_estimate="off", **C1)
    assert isinstance(c, palpate.Curve)
    assert c.displacement_mm.tolist() == [0.0, 0.5, 1.0] and c.force_N.shape == (3,)
    assert c.time_s is None and c.error_estimate_N is None
    assert any("volumetric" in line for line in c.comments)
    assert "force_N=array(shape=(3,))" in repr(c)
    assert c.to_dict()["displacement_mm"] == [0.0, 0.5, 1.0]


def test_posterior_is_an_object_with_arrays():
    stretch, stress = treloar()
    post = palpate.sample("neo-hookean", {"uniaxial": (stretch, stress)}, sampler="demc", draws=20,
                          max_draws=20, tune=20, parallel=1, seed=1, arviz=False)
    assert isinstance(post, palpate.Posterior)
    # chains x draws: DE-MC runs a population of chains even on one thread
    chains, draws = post.draws["C10"].shape
    assert chains >= 1 and draws == 20
    assert "C10" in post.summary["params"]
    assert "Posterior(draws={C10" in repr(post)


def quiet_calls():
    stretch, stress = treloar()
    return {
        "calibrate": lambda v: palpate.calibrate("yeoh", {"uniaxial": (stretch, stress)}, verbose=v),
        # the FE summary and the error estimate's line
        "simulate": lambda v: palpate.simulate("C1", verbose=v, **C1),
        # the sampler's progress and summary
        "sample": lambda v: palpate.sample("neo-hookean", {"uniaxial": (stretch, stress)}, sampler="demc",
                                           draws=20, max_draws=20, tune=20, parallel=1, arviz=False, verbose=v),
        # the diagnosis summary and explanation
        "diagnose": lambda v: palpate.diagnose({"uniaxial": (stretch, stress)}, folds=2, verbose=v),
    }


@pytest.mark.parametrize("name", ["calibrate", "simulate", "sample", "diagnose"])
def test_nothing_is_printed_unless_asked(name, capfd):
    call = quiet_calls()[name]
    call(False)
    out, err = capfd.readouterr()
    assert out == "" and err == "", (out, err)
    if name in ("simulate", "sample", "diagnose"):
        # the same call with verbose=True does print: the quiet test can fail
        call(True)
        out, err = capfd.readouterr()
        assert out or err


def test_output_comes_back_after_a_quiet_call_fails(capfd):
    with pytest.raises(palpate.PalpateError):
        palpate.calibrate("yeoh", {"uniaxial": TRELOAR}, estimator="newton")
    os.write(1, b"out\n")
    os.write(2, b"err\n")
    assert capfd.readouterr() == ("out\n", "err\n")


def test_a_study_run_is_quiet_and_an_object(tmp_path, capfd, monkeypatch):
    monkeypatch.chdir(ROOT)
    run = palpate.run_study("studies/treloar-laws.toml", tmp_path / "run")
    out, err = capfd.readouterr()
    assert out == "" and err == "", (out, err)
    assert isinstance(run, palpate.StudyRun) and run.folder == tmp_path / "run"
    assert run.computed > 0 and run.results["study"]
    assert "results" not in repr(run) and "computed=" in repr(run)


def message(call) -> str:
    with pytest.raises(palpate.PalpateError) as e:
        call()
    return str(e.value)


def test_sample_returns_the_table_and_warnings_quietly(capfd):
    stretch, stress = treloar()
    kw = dict(sampler="demc", draws=20, max_draws=20, tune=20, parallel=1, seed=1, arviz=False)
    post = palpate.sample("neo-hookean", {"uniaxial": (stretch, stress)}, **kw)
    assert capfd.readouterr() == ("", "")
    assert post.table.startswith("demc on uniaxial neo-hookean"), post.table
    # 20 draws cannot reach the bulk ESS of 400
    assert post.warnings and post.warnings[0].startswith("warning: not converged"), post.warnings
    # the table is the command line's, but for the wall time on its first line
    palpate.cli("sample", "--law", "neo-hookean", "--data", f"uniaxial={TRELOAR}", "--sampler", "demc",
                "--draws", "20", "--max-draws", "20", "--tune", "20", "--parallel", "1", "--seed", "1")
    out, err = capfd.readouterr()
    assert out.splitlines()[1:] == post.table.splitlines()[1:]
    assert post.warnings[0] in err.splitlines()


def test_fe_records_go_in_memory_and_errors_are_the_command_lines(tmp_path):
    """The FE benchmarks of sample, the Q1 identification and the R2 scan
    take their records and options in memory (no temporary file); their
    refusals are the command line's, word for word."""
    d, f = np.array([0.0, 0.5, 1.0]), np.array([0.0, 0.1, 0.3])
    assert "Q1 arrays: a Q1 record is a timed ramp-and-hold: it needs a time_s column" in message(
        lambda: palpate.calibrate("neo-hookean", (d, f), benchmark="Q1"))
    assert "it needs a time_s column" in message(
        lambda: palpate.sample("neo-hookean", (d, f), benchmark="Q1", box={"C10": (0.001, 0.01)}, arviz=False))
    path = tmp_path / "q1.csv"
    path.write_text("displacement_mm,force_N\n0,0\n0.5,0.1\n1,0.3\n")
    assert message(lambda: palpate.calibrate("yeoh", {"uniaxial": TRELOAR}, stages="elastic")) == message(
        lambda: palpate.cli("calibrate", "--law", "yeoh", "--data", f"uniaxial={TRELOAR}", "--stages", "elastic"))
    assert message(lambda: palpate.calibrate("neo-hookean", path, benchmark="Q1", fit_mesh=-1.0)) == message(
        lambda: palpate.cli("calibrate", "--benchmark", "Q1", "--law", "neo-hookean", "--data", str(path),
                            "--fit-mesh", "-1"))
    assert message(lambda: palpate.simulate("R2", nodules="75:15")) == message(
        lambda: palpate.cli("simulate", "--benchmark", "R2", "--nodules", "75:15"))
    assert message(lambda: palpate.simulate("R2", rd=1.0, params={"mu": 0.005})) == message(
        lambda: palpate.cli("simulate", "--benchmark", "R2", "--rd", "1", "--param", "mu=0.005"))
    # accuracy: a keyword of simulate, refused for C1 as the command line refuses it
    assert message(lambda: palpate.simulate("C1", accuracy=0.01, error_estimate="off", **C1)) == message(
        lambda: palpate.cli("simulate", "--benchmark", "C1", "--law", "neo-hookean", "--param", "C10=0.2",
                            "--mesh", "coarse", "--depth", "1", "--step", "0.5", "--accuracy", "0.01",
                            "--error-estimate", "off"))
