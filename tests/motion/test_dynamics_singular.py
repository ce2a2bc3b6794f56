"""Forward dynamics through singular configurations: the IFToMM A02 chain (N = 2), whose
bars all line up with the ground twice a turn (Phi_q loses rank 2 there, one per loop) while
its motion stays smooth: every crank turns by the angle theta of the one-coordinate equation
((N + 1)/3 + N) theta'' = -((N + 1)/2 + N) g cos(theta), integrated here by SciPy at 1e-12.

- the run follows that equation through the passages at the default tolerances and at
  rtol = atol = 1e-10 (it stopped at t = 6.54 and t = 8.998 with "the step size fell below
  its minimum"; rtol 1e-10 with atol 1e-12 still stops at t = 0.714);
- each passage is reported where theta crosses a multiple of pi (the reference's own
  roots), flagged on the row after it, and warned about by the command line;
- --stop-at-singular stops at the first with a located message and the rows before it;
- a driven crank reaching its limit position (a lock-up) stops there, named, rows kept.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from cli_support import Ran, symkin_main
from motion_support import kernel
from scipy.integrate import solve_ivp
from test_iftomm_benchmarks import _bench_script, a02_chain

import symkin

ROOT = Path(__file__).resolve().parents[2]
N, G = 2, 9.81


def _reference(t1: float) -> Any:
    inertia, weight = (N + 1) / 3 + N, ((N + 1) / 2 + N) * G
    return solve_ivp(lambda _t, y: [y[1], -weight / inertia * math.cos(y[0])], (0.0, t1),
                     [math.pi / 2, -1.0], method="DOP853", rtol=1e-12, atol=1e-12,
                     dense_output=True)


def _chain(folder: Path, t1: float, integrator: str = "") -> Path:
    text = _bench_script("a02_n_four_bar").mechanism(N).replace(
        "time: {t0: 0, t1: 10, dt: 0.01}", f"{integrator}time: {{t0: 0, t1: {t1}, dt: 0.01}}")
    path = folder / "a02_chain.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _passage_times(t1: float) -> np.ndarray:
    """Where the reference's theta crosses a multiple of pi (the bars line up)."""
    reference = _reference(t1)
    grid = np.linspace(0.0, t1, 20001)
    turns = np.floor(reference.sol(grid)[0] / math.pi)
    found = []
    for k in np.flatnonzero(np.diff(turns)):
        level = max(turns[k], turns[k + 1]) * math.pi
        low, high = grid[k], grid[k + 1]
        for _ in range(60):
            mid = (low + high) / 2
            same = (reference.sol(mid)[0] - level) * (reference.sol(low)[0] - level) > 0
            low, high = (mid, high) if same else (low, mid)
        found.append((low + high) / 2)
    return np.array(found)


def _check_follows(run: Any) -> None:
    theta = _reference(float(run.t[-1])).sol(run.t)[0]
    cranks = [run.coordinates.index(f"crank{k}.phi") for k in range(N + 1)]
    assert np.max(np.abs(run.q[:, cranks] - theta[:, None])) < 1e-6
    couplers = [run.coordinates.index(f"coupler{k}.phi") for k in range(N)]
    assert np.max(np.abs(run.q[:, couplers])) < 1e-6


@pytest.fixture(scope="module")
def default_run() -> Any:
    """The chain at the file's (default) tolerances on its grid of 0.01 s, to t = 7: the
    kernel of test_iftomm_benchmarks.py's A02 tests (the run's one derivation of the chain)."""
    return symkin.solve(kernel(a02_chain(), "numpy"), t=np.linspace(0.0, 7.0, 701))


def test_default_tolerances_pass_seven_passages_on_the_cranks_equation(default_run: Any) -> None:
    assert default_run.t[-1] == pytest.approx(7.0)
    _check_follows(default_run)


def test_tight_tolerance_passes_them_too(tmp_path: Path) -> None:
    path = _chain(tmp_path, 9.1, "integrator: {rtol: 1e-10, atol: 1e-10}\n")
    run = symkin.solve(symkin.compile(symkin.derive(path), backend="numpy"))
    assert run.t[-1] == pytest.approx(9.1)  # it stopped at t = 8.998
    _check_follows(run)


def test_each_passage_is_reported_where_the_bars_line_up(default_run: Any) -> None:
    expected = _passage_times(7.0)
    assert expected.size == 7  # 6.54 was where the run stopped
    times = np.array([s[0] for s in default_run.singular])
    np.testing.assert_allclose(times, expected, rtol=0, atol=1e-6)
    assert all(s[1] == 2 for s in default_run.singular)  # one per loop
    after = np.searchsorted(default_run.t, expected)
    assert np.flatnonzero(default_run.flagged).tolist() == after.tolist()


@pytest.fixture
def symkin_run() -> Callable[..., Ran]:
    """``symkin run ARGS`` in ``cwd``, in this process (cli_support.symkin_main: an
    exception it lets out fails the test, as a traceback would)."""

    def run(*args: str, cwd: Path) -> Ran:
        return symkin_main("run", *args, cwd=cwd)

    return run

    return run


def test_cli_warns_of_each_passage_and_stops_at_the_first_when_asked(
        tmp_path: Path, symkin_run: Callable[..., Ran]) -> None:
    path = _chain(tmp_path, 1.5)
    first, second = _passage_times(1.5)
    result = symkin_run(str(path), "--backend", "numpy", "-o", "out.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    warnings = [line for line in result.stderr.splitlines() if "warning:" in line]
    assert len(warnings) == 2
    for line, at in zip(warnings, (first, second)):
        said = re.search(r"passes a singular configuration at t = ([0-9.]+)", line)
        assert said is not None and abs(float(said.group(1)) - at) < 1e-6
        assert "loses rank 2" in line and "interpolated" not in line
    stopped = symkin_run(str(path), "--backend", "numpy", "--stop-at-singular", "-o",
                         "out.npz", cwd=tmp_path)
    assert stopped.returncode == 1
    said = re.search(r"singular configuration is reached at t = ([0-9.]+)", stopped.stderr)
    assert said is not None and abs(float(said.group(1)) - first) < 1e-6
    assert "--stop-at-singular" in stopped.stderr
    data = np.load(tmp_path / "out.npz")
    assert data["t"].size == int(np.searchsorted(np.linspace(0, 1.5, 151), first))
    assert not data["flagged"].any()


# tests/mechanisms/non_grashof.yaml with masses and a free pendulum beside it (so that it
# has fewer drivers than freedoms): the driven crank reaches its limit position at
# t* = acos(-1/4), where the coupler and the rocker line up and the motion cannot go on.
LOCKUP = """\
name: lockup
parameters: {a: 2.0, b: 2.0, c: 2.0, d: 3.0, m: 1.0}
bodies:
  crank:   {q0: [0, 0, 0], points: {A: [a, 0]}, mass: m, inertia: m*a**2/12, com: [a/2, 0]}
  coupler: {q0: [2, 0, 1.3], points: {B: [b, 0]}, mass: m, inertia: m*b**2/12, com: [b/2, 0]}
  rocker:  {q0: [3, 0, 1.8], points: {B: [c, 0]}, mass: m, inertia: m*c**2/12, com: [c/2, 0]}
  bob:     {q0: [0, -1, 0], mass: m, inertia: m/12, com: [0, 0]}
joints:
  - {type: revolute, name: O2, i: ground,  j: crank,   sA: [0, 0], sB: [0, 0]}
  - {type: revolute, name: A,  i: crank,   j: coupler, sA: A,      sB: [0, 0]}
  - {type: revolute, name: B,  i: coupler, j: rocker,  sA: B,      sB: B}
  - {type: revolute, name: O4, i: rocker,  j: ground,  sA: [0, 0], sB: [d, 0]}
  - {type: revolute, name: P,  i: ground,  j: bob,     sA: [0, 0], sB: [0, 1]}
drivers:
  - {type: angle, name: input, i: crank, j: ground, theta: "t"}
forces:
  - {type: gravity, g: [0, -9.81]}
initial: {velocities: {bob.phi: 0.5}}
time: {t0: 0, t1: 2.5, dt: 0.05}
"""


def test_a_lock_up_stops_at_the_limit_position_naming_it(
        tmp_path: Path, symkin_run: Callable[..., Ran]) -> None:
    (tmp_path / "lockup.yaml").write_text(LOCKUP, encoding="utf-8")
    result = symkin_run("lockup.yaml", "--backend", "numpy", "-o", "out.npz", cwd=tmp_path)
    assert result.returncode == 1
    said = re.search(r"the motion stops at t = ([0-9.]+): a lock-up: Phi_q loses rank 1",
                     result.stderr)
    assert said is not None and abs(float(said.group(1)) - math.acos(-0.25)) < 1e-6
    assert "O4 revolute rocker-ground" in result.stderr
    data = np.load(tmp_path / "out.npz")
    assert data["t"][-1] == pytest.approx(1.8)  # the rows before it, the crank as driven
    np.testing.assert_allclose(data["q"][:, 2], data["t"], rtol=0, atol=1e-9)
