"""``symkin run MECH --inputs table.csv``: the table's run equals the time-driven run of the
same motion; every mistake in the table or the command is refused, located, with exit 2."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
INPUT = ROOT / "examples" / "crank_slider_input.yaml"
TIMED = ROOT / "examples" / "crank_slider.yaml"


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    result = subprocess.run([sys.executable, "-m", "symkin", "run", *args], cwd=cwd, env=env,
                            check=False, capture_output=True, text=True, timeout=300)
    assert "Traceback" not in result.stderr, result.stderr
    return result


def _table(path: Path, header: str, rows: list[str]) -> Path:
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


def _motion(t: np.ndarray) -> list[str]:
    return [f"{x!r},{x * x + np.pi / 2!r},{2 * x!r},2.0" for x in map(float, t)]


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_table_run_equals_the_time_driven_run(tmp_path: Path, backend: str) -> None:
    t = np.linspace(0, 1.5, 31)
    table = _table(tmp_path / "u.csv", "t,crank_angle,crank_angle_t,crank_angle_tt", _motion(t))
    got = run(str(INPUT), "--backend", backend, "--inputs", str(table), "-o", "in.npz",
              cwd=tmp_path)
    assert got.returncode == 0, got.stderr
    ref = run(str(TIMED), "--backend", backend, "--t0", "0", "--t1", "1.5", "--dt", "0.05",
              "-o", "ref.npz", cwd=tmp_path)
    assert ref.returncode == 0, ref.stderr
    a, b = np.load(tmp_path / "in.npz"), np.load(tmp_path / "ref.npz")
    assert np.array_equal(a["t"], t)
    for name in ("q", "dq", "d2q"):
        scale = max(1.0, float(np.abs(b[name]).max()))
        assert np.abs(a[name] - b[name]).max() / scale < 1e-12, name


def test_positions_only_table_writes_nan_rates(tmp_path: Path) -> None:
    t = np.linspace(0, 1, 11)
    rows = [f"{x!r},{x + 1.5!r}" for x in map(float, t)]
    table = _table(tmp_path / "u.csv", "t,crank_angle", rows)
    got = run(str(INPUT), "--backend", "numpy", "--inputs", str(table), "-o", "out.csv",
              cwd=tmp_path)
    assert got.returncode == 0, got.stderr
    data = np.genfromtxt(tmp_path / "out.csv", delimiter=",", names=True)
    assert np.allclose(data["crankphi"], t + 1.5, atol=1e-12, rtol=0)
    assert np.isnan(data["crankphi_t"]).all()


GOOD = ["0,1.5", "0.1,1.6"]


@pytest.mark.parametrize("header, rows, where, says", [
    ("time,crank_angle", GOOD, "u.csv:1", "the first column must be t"),
    ("t,crank_angle,crank_speed", ["0,1,2"], "u.csv:1", "unknown column 'crank_speed'"),
    ("t,crank_angle_t", ["0,1"], "u.csv:1", "(the inputs' values) are missing"),
    ("t,crank_angle,crank_angle_tt", ["0,1,2"], "u.csv:1", "need the rates"),
    ("t,crank_angle,crank_angle", ["0,1,2"], "u.csv:1", "given twice"),
    ("t,crank_angle", ["0,1.5", "0.1,nan"], "u.csv:3", "'nan' is not a finite number"),
    ("t,crank_angle", ["0,1.5", "0.1,x"], "u.csv:3", "'x' is not a finite number"),
    ("t,crank_angle", ["0,1.5", "0.1"], "u.csv:3", "1 values, but the header has 2"),
    ("t,crank_angle", ["0,1.5", "0.2,1", "0.1,1"], "u.csv:4", "the times must increase"),
    ("t,crank_angle", ["0,1.5", "0,1"], "u.csv:3", "the times must increase"),
    ("t,crank_angle", ["1e999,1"], "u.csv:2", "not a finite number"),
    ("t,crank_angle", [], "u.csv", "no rows of values"),
])
def test_bad_tables_are_refused_with_their_place(tmp_path: Path, header: str, rows: list[str],
                                                 where: str, says: str) -> None:
    table = _table(tmp_path / "u.csv", header, rows)
    got = run(str(INPUT), "--backend", "numpy", "--inputs", str(table), cwd=tmp_path)
    assert got.returncode == 2
    assert where in got.stderr and says in got.stderr, got.stderr


def test_input_mechanism_without_table_and_table_without_inputs(tmp_path: Path) -> None:
    got = run(str(INPUT), "--backend", "numpy", cwd=tmp_path)
    assert got.returncode == 2 and "--inputs TABLE.csv" in got.stderr
    assert "crank_angle_t" in got.stderr  # the columns it expects
    table = _table(tmp_path / "u.csv", "t,crank_angle", GOOD)
    got = run(str(TIMED), "--backend", "numpy", "--inputs", str(table), cwd=tmp_path)
    assert got.returncode == 2 and "no input drivers" in got.stderr
    got = run(str(INPUT), "--backend", "numpy", "--inputs", str(table), "--dt", "0.1",
              cwd=tmp_path)
    assert got.returncode == 2 and "leave out --dt" in got.stderr
    got = run(str(INPUT), "--backend", "numpy", "--inputs", "missing.csv", cwd=tmp_path)
    assert got.returncode == 2 and "cannot read the input table" in got.stderr
