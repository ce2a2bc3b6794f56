"""Tolerance analysis: Monte-Carlo statistics of the slider position against the first-order
estimate from q_p, the designs (grid, table, draws), and the `symkin sweep` command.

The first-order reference is built here from the closed form of Example 2.7 (slider x3 =
a cos phi1 + b cos phi2), not from the code under test: var x3 = sum_k (dx3/dp_k)^2 sigma_k^2.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, symkin_main

import symkin
from symkin.errors import UsageError
from symkin.sweeps import tolerance

ROOT = Path(__file__).resolve().parents[2]
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"


@pytest.fixture(scope="module")
def kernel(crank_slider_system):
    compiled = symkin.compile(crank_slider_system, backend="c")
    assert compiled.backend == "c"
    return compiled


def _slider_gradient(t: np.ndarray, a: float = 1.0, b: float = 5.0, c: float = 4.0):
    phi1 = t**2 + np.pi / 2
    s = (c - a * np.sin(phi1)) / b
    phi2 = np.arcsin(s)
    return np.column_stack([np.cos(phi1) + np.tan(phi2) * np.sin(phi1), 1 / np.cos(phi2),
                            -np.tan(phi2)])


@pytest.mark.parametrize("distribution", ["normal", "uniform"])
def test_monte_carlo_spread_of_the_slider_matches_first_order(kernel, distribution) -> None:
    half_widths = {"a": 0.002, "b": 0.005, "c": 0.004}  # small: linearisation must hold
    design = tolerance.monte_carlo_design(kernel, 4000, half_widths, distribution, seed=11)
    result = symkin.sweep(kernel, design)
    assert result.ok.all()
    x3 = result.q[:, :, 6]
    scale = 3.0 if distribution == "normal" else np.sqrt(3.0)
    sigma = np.array([half_widths[n] for n in "abc"]) / scale
    expected_std = np.sqrt((_slider_gradient(result.t) ** 2 * sigma**2).sum(axis=1))
    # the spread of a standard deviation estimated from 4000 draws is about 1.1 %
    assert np.allclose(x3.std(axis=0, ddof=1), expected_std, rtol=0.05)
    nominal = symkin.solve(kernel, t=result.t).q[:, 6]
    assert np.all(np.abs(x3.mean(axis=0) - nominal) < 4 * expected_std / np.sqrt(4000) + 1e-6)
    # the estimate symkin prints agrees with the same reference
    estimate = tolerance.point_sensitivities(kernel, result.t)["rod.P"][1][:, 0]
    spread = tolerance.sigmas(kernel, half_widths, distribution)
    assert np.allclose(tolerance.first_order_std(estimate, spread), expected_std, rtol=1e-8)


def test_grid_design_is_the_product(kernel) -> None:
    design = tolerance.grid_design(kernel, [tolerance.Vary("a", 0.9, 1.1, 3),
                                            tolerance.Vary("c", 3.5, 4.0, 2)])
    assert design.shape == (6, 3)
    assert sorted(map(tuple, design[:, [0, 2]].round(12))) == sorted(
        (a, c) for a in (0.9, 1.0, 1.1) for c in (3.5, 4.0))
    assert np.all(design[:, 1] == 5.0)


def test_table_design_and_its_errors(kernel, tmp_path: Path) -> None:
    table = tmp_path / "t.csv"
    table.write_text("b,a\n5.1,0.9\n4.9,1.1\n")
    assert tolerance.table_design(kernel, table).tolist() == [[0.9, 5.1, 4.0], [1.1, 4.9, 4.0]]
    for text, message in [("d\n1\n", "unknown parameter 'd'"), ("a\nx\n", ":2: a: 'x'"),
                          ("a,b\n1\n", "1 values for 2 columns"), ("a\n", "at least one row"),
                          ("a\nnan\n", "not a finite")]:
        table.write_text(text)
        with pytest.raises(UsageError, match=message):
            tolerance.table_design(kernel, table)


def sweep_cli(*args: str, cwd: Path) -> Ran:
    """``symkin sweep ARGS`` in this process (tests/cli_support.py); the interrupt below runs in
    a real one."""
    return symkin_main("sweep", *args, cwd=cwd)


def test_cli_grid_writes_npz_and_reports_failures(tmp_path: Path) -> None:
    # The rod reaches the slider line y = c from the crank tip y2 = a sin(phi1) when
    # b >= c - y2. At t0 (phi1 = pi/2) that needs b >= 4 - a: b = 2.5 (both a) and b = 3 with
    # a = 0.9 cannot be assembled (3 sets). Over the grid y2 falls to a sin(3.82) = -0.63 a, so
    # b >= 4 + 0.63 a: only b = 5 and 5.5 (4 sets) get through; the other 7 stop on the way.
    result = sweep_cli(str(TEXTBOOK), "--vary", "b=2.5:5.5:7", "--vary", "a=0.9:1.1:2",
                       "-o", "s.npz", "--plot", "s.png", "--workers", "1", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "solved 4 of 14 parameter sets" in result.stdout
    # The 7 that stop on the way stop where the rod can no longer reach the slider line: the
    # driven motion's limit position (a coarse grid step may also end one in no convergence).
    failed = next(line for line in result.stdout.splitlines() if line.startswith("failed:"))
    counts = dict(reversed(part.strip().split(" ", 1)) for part in failed[7:].split(","))
    assert counts.pop("no assembly") == "3" and "limit position" in counts
    assert sum(int(n) for n in counts.values()) == 7
    assert "b=2.5" in result.stdout and "rod.P.x" in result.stdout
    data = np.load(tmp_path / "s.npz")
    assert data["q"].shape == (14, 31, 9) and (data["status"] == 4).sum() == 3
    assert (tmp_path / "s.png").stat().st_size > 0


def test_cli_monte_carlo_prints_the_first_order_estimate(tmp_path: Path) -> None:
    result = sweep_cli(str(TEXTBOOK), "--monte-carlo", "300", "--tolerance", "a=±0.01",
                       "--tolerance", "b=+-0.2%", "--seed", "3", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "solved 300 of 300" in result.stdout and "first order ±3σ" in result.stdout


def test_cli_set_fixes_the_parameters_not_varied(tmp_path: Path) -> None:
    # --set c=4.2 moves the slider line (y = c) for every set; the slider's y equals c
    # whatever a and b are (the prismatic joint holds it on that line).
    result = sweep_cli(str(TEXTBOOK), "--vary", "a=0.9:1.1:3", "--set", "c=4.2", "-o", "s.npz",
                       cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    data = np.load(tmp_path / "s.npz")
    names = [str(n) for n in data["coordinates"]]
    assert np.all(data["params"][:, 2] == 4.2)
    np.testing.assert_allclose(data["q"][:, :, names.index("slider.y")], 4.2, atol=1e-12)
    bad = sweep_cli(str(TEXTBOOK), "--vary", "a=0.9:1.1:3", "--set", "zz=1", cwd=tmp_path)
    assert bad.returncode == 2 and "no parameter 'zz'" in bad.stderr

@pytest.mark.parametrize("args, message", [
    (["--vary", "b=1:2"], "NAME=LO:HI:COUNT"),
    (["--vary", "zz=1:2:3"], "unknown parameter 'zz'"),
    (["--vary", "b=1:inf:3"], "not a finite number"),
    (["--monte-carlo", "10"], "needs at least one --tolerance"),
    (["--monte-carlo", "10", "--tolerance", "a=about 1"], "NAME=±X"),
    (["--monte-carlo", "10", "--tolerance", "a=-1"], "must not be negative"),
    (["--vary", "b=4:5:2", "--params", "x.csv"], "one way"),
    (["--vary", "b=4:5:2", "-o", "s.csv"], ".npz"),
    (["--params", "missing.csv"], "cannot read the parameter table"),
    (["--vary", "b=4:5:2", "--workers", "0"], "at least 1"),
])
def test_cli_bad_input_exits_2_with_one_message(tmp_path: Path, args, message) -> None:
    result = sweep_cli(str(TEXTBOOK), *args, cwd=tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr and result.stderr.startswith("symkin: error:")
    assert len(result.stderr.strip().splitlines()) == 1


def test_cli_too_many_sets_is_refused_before_any_work(tmp_path: Path) -> None:
    result = sweep_cli(str(TEXTBOOK), "--vary", "a=0.9:1.1:1000", "--vary", "b=5:6:1000",
                       cwd=tmp_path)
    assert result.returncode == 2 and "points in all, more than the" in result.stderr


def test_cli_interrupt_exits_130_without_a_traceback(tmp_path: Path) -> None:
    import signal
    import time

    from cli_support import ctrl_c_as_at_a_terminal

    squeezer = str(ROOT / "examples" / "andrews_squeezer.yaml")
    warm = sweep_cli(squeezer, "--monte-carlo", "1", "--tolerance", "xa=±1e-5", cwd=tmp_path)
    assert warm.returncode == 0, warm.stderr  # the kernel is built: the wait below is solving
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    process = subprocess.Popen(
        # Andrews' squeezer, 160000 sets x 61 points: far longer than the wait below
        [sys.executable, "-m", "symkin", "sweep", squeezer, "--monte-carlo", "160000", "--tolerance", "xa=±1e-5", "--workers", "1"], cwd=tmp_path,
        env=env, preexec_fn=ctrl_c_as_at_a_terminal,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(4)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 130, out + err
    assert "Traceback" not in err and "interrupted" in err
