"""The code of docs/python.md runs as written, and the package keeps its word.

Run from anywhere: ``python -m pytest python/tests`` (the blocks run from
the repository's root, as the page says).
"""

from __future__ import annotations

import os
import re
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest

import palpate

ROOT = Path(__file__).resolve().parents[2]


def blocks(page: str) -> list[tuple[str, str]]:
    """The ```python blocks of a page: (tag, code); tag is "" or e.g. "dask"."""
    text = (ROOT / "docs" / page).read_text()
    return [(m.group(1).strip(), m.group(2)) for m in re.finditer(r"```python([^\n]*)\n(.*?)```", text, re.S)]


@pytest.fixture
def at_root():
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        yield
    finally:
        os.chdir(here)


def test_the_page_runs_block_after_block(at_root):
    found = blocks("python.md")
    assert len(found) >= 7, "docs/python.md lost its examples"
    namespace: dict = {}
    ran = []
    for tag, code in found:
        if tag == "dask":
            try:
                import dask  # noqa: F401
            except ImportError:
                print("docs/python.md: the dask block is skipped (dask not installed)")
                continue
        exec(compile(code, f"docs/python.md ({tag or 'python'})", "exec"), namespace)
        ran.append(tag)
    assert ran.count("") == sum(1 for t, _ in found if t == "")


def binary() -> Path | None:
    for profile in ("debug", "release"):
        p = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / profile / "palpate"
        if p.is_file():
            return p
    return None


def test_errors_carry_the_message_of_the_command_line(tmp_path):
    bad = tmp_path / "u.csv"
    bad.write_text("stretch,stress_MPa\n1,0\n1.1,abc\n")
    with pytest.raises(palpate.PalpateError) as e:
        palpate.calibrate("yeoh", {"uniaxial": bad})
    said = str(e.value)
    assert "u.csv:3: column `stress_MPa`: `abc` is not a number" in said, said
    exe = binary()
    if exe is None:
        pytest.skip("no target/*/palpate to compare the message with")
    out = subprocess.run(
        [exe, "calibrate", "--law", "yeoh", "--data", f"uniaxial={bad}", "--json", str(tmp_path / "f.json")],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 2
    assert out.stderr.strip() == "error: " + said


def test_bad_options_are_named():
    with pytest.raises(palpate.PalpateError, match="--law"):
        palpate.cli("calibrate", "--law", "no-such-law", "--data", "uniaxial=x.csv")
    with pytest.raises(TypeError, match="no_such_option"):
        palpate.simulate("C1", law="neo-hookean", params={"C10": 0.1}, no_such_option=1)
    with pytest.raises(palpate.PalpateError, match="shard index 3 is not below the shard count 2"):
        palpate.run_study("studies/treloar-laws.toml", shard="3/2")
    with pytest.raises(palpate.PalpateError, match="columns of different lengths"):
        palpate.calibrate("yeoh", {"uniaxial": (np.ones(3), np.ones(4))})
    assert "Usage: palpate" in palpate.cli("--help")


def test_the_gil_is_released_while_palpate_runs():
    """A Python thread counts while an FE run goes on in another."""
    count = 0
    started = threading.Event()

    def run():
        started.set()
        palpate.simulate("C1", law="neo-hookean", params={"C10": 0.1}, mesh="medium", depth=2.0, step=0.05, error_estimate="off")

    t = threading.Thread(target=run)
    t.start()
    started.wait()
    while t.is_alive():
        count += 1
    t.join()
    # With the GIL held for the run this thread would get at most a few
    # switch intervals (5 ms each) before and after it.
    assert count > 100_000, count


def test_numpy_records_read_as_the_files_do(tmp_path):
    path = ROOT / "studies/data/treloar/uniaxial.csv"
    rows = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    x, y = np.loadtxt(rows[1:], delimiter=",", unpack=True)
    a = palpate.calibrate("mooney-rivlin", {"uniaxial": path})
    b = palpate.calibrate("mooney-rivlin", {"uniaxial": (x, y)})
    c = palpate.calibrate("mooney-rivlin", {"uniaxial": {"stretch": x, "stress_MPa": y}})
    assert a.params == b.params == c.params



def test_sample_returns_inference_data_with_the_same_draws():
    az = pytest.importorskip("arviz")
    path = ROOT / "studies/data/treloar/uniaxial.csv"
    kw = dict(sampler="nuts", draws=100, max_draws=100, tune=100, seed=3)
    plain = palpate.sample("neo-hookean", {"uniaxial": path}, arviz=False, **kw)
    idata = palpate.sample("neo-hookean", {"uniaxial": path}, **kw)
    c10 = idata.posterior["C10"].values
    assert c10.shape == (4, 100)
    assert np.array_equal(c10, plain.draws["C10"])
    assert "C10" in str(az.summary(idata))
