"""``symkin run MECH --inputs table.csv``: the table's run equals the time-driven run of the
same motion; every mistake in the table or the command is refused, located, with exit 2.

The commands run in this process (``cli_support.symkin_main``: ``cli.main``, what the console
script calls): a fresh Python per command cost a second each in imports alone. One test runs
a real process, so the exit status and the absence of a traceback are also seen from outside."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, symkin_main

ROOT = Path(__file__).resolve().parents[2]
INPUT = ROOT / "examples" / "crank_slider_input.yaml"
TIMED = ROOT / "examples" / "crank_slider.yaml"


@pytest.fixture
def symkin_cli() -> Callable[..., Ran]:
    """``symkin ARGS`` run in ``cwd`` in this process (cli_support.symkin_main: an exception
    the command lets out, a traceback for the user, fails the test)."""

    def call(*args: str, cwd: Path) -> Ran:
        return symkin_main(*args, cwd=cwd)

    return call

    return call


@pytest.fixture
def run(symkin_cli: Callable[..., Ran]) -> Callable[..., Ran]:
    """``symkin run ARGS`` in ``cwd``."""
    return lambda *args, cwd: symkin_cli("run", *args, cwd=cwd)


def _table(path: Path, header: str, rows: list[str]) -> Path:
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


def _motion(t: np.ndarray) -> list[str]:
    return [f"{x!r},{x * x + np.pi / 2!r},{2 * x!r},2.0" for x in map(float, t)]


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_table_run_equals_the_time_driven_run(run: Callable[..., Ran], tmp_path: Path,
                                               backend: str) -> None:
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


def test_positions_only_table_writes_nan_rates(run: Callable[..., Ran], tmp_path: Path) -> None:
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
    ("t,crank_angle", ["0,1_5"], "u.csv:2", "'1_5' is not a finite number"),  # not 15
    ("t,crank_angle", [], "u.csv", "no rows of values"),
])
def test_bad_tables_are_refused_with_their_place(run: Callable[..., Ran], tmp_path: Path,
                                                 header: str, rows: list[str], where: str,
                                                 says: str) -> None:
    table = _table(tmp_path / "u.csv", header, rows)
    got = run(str(INPUT), "--backend", "numpy", "--inputs", str(table), cwd=tmp_path)
    assert got.returncode == 2
    assert where in got.stderr and says in got.stderr, got.stderr


def test_input_mechanism_without_table_and_table_without_inputs(run: Callable[..., Ran],
                                                                 tmp_path: Path) -> None:
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


def test_a_table_with_a_byte_order_mark_reads_as_without(run: Callable[..., Ran],
                                                          tmp_path: Path) -> None:
    """Spreadsheets write "CSV UTF-8" with a byte-order mark before the header."""
    plain = _table(tmp_path / "plain.csv", "t,crank_angle", GOOD)
    marked = tmp_path / "marked.csv"
    marked.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    for table, out in ((plain, "a.npz"), (marked, "b.npz")):
        got = run(str(INPUT), "--backend", "numpy", "--inputs", str(table), "-o", out,
                  cwd=tmp_path)
        assert got.returncode == 0, got.stderr
    assert np.array_equal(np.load(tmp_path / "a.npz")["q"], np.load(tmp_path / "b.npz")["q"])


@pytest.mark.parametrize("output", ["u.csv", "link.csv", "./sub/../u.csv"])
def test_the_results_never_replace_the_input_table(run: Callable[..., Ran], tmp_path: Path,
                                                    output: str) -> None:
    table = _table(tmp_path / "u.csv", "t,crank_angle", GOOD)
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.csv").symlink_to(table)
    before = table.read_bytes()
    got = run(str(INPUT), "--backend", "numpy", "--inputs", "u.csv", "-o", output,
              cwd=tmp_path)
    assert got.returncode == 2 and "is the --inputs table" in got.stderr, got.stderr
    assert table.read_bytes() == before


def test_sweep_and_scan_mistakes_about_inputs_are_the_users(symkin_cli: Callable[..., Ran],
                                                            tmp_path: Path) -> None:
    """Exit 2, as run gives, and in the command line's words: a sweep of a mechanism with
    inputs (it exited 1, as for a design that failed), --input for a mechanism without
    (the message named Python's inputs= and told to give --input as well as to leave it out)."""
    got = symkin_cli("sweep", str(INPUT), "--backend", "numpy", "--vary", "a=0.9:1.1:3",
                  cwd=tmp_path)
    assert got.returncode == 2 and "input drivers (crank_angle)" in got.stderr, got.stderr
    got = symkin_cli("scan", str(TIMED), "--backend", "numpy", "--input", "x=1", cwd=tmp_path)
    assert got.returncode == 2 and "leave out --input" in got.stderr, got.stderr
    assert "inputs=" not in got.stderr and "give --input" not in got.stderr


def test_a_real_process_exits_2_without_a_traceback(tmp_path: Path) -> None:
    """The same refusal seen from outside: ``python -m symkin`` exits with status 2 and says
    where, with no traceback."""
    table = _table(tmp_path / "u.csv", "t,crank_angle", ["0,1.5", "0.1,nan"])
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    got = subprocess.run([sys.executable, "-m", "symkin", "run", str(INPUT), "--backend",
                          "numpy", "--inputs", str(table)], cwd=tmp_path, env=env, check=False,
                         capture_output=True, text=True, timeout=300)
    assert got.returncode == 2, got.stderr
    assert "Traceback" not in got.stderr and "u.csv:3" in got.stderr, got.stderr
