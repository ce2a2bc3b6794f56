"""Flags where the error is (issue 29, item 4): the error model lets only the coordinates that
enter Phi_q or Phi_t (here the angles) carry the error of q into dq and ddq.

References are closed forms written here or in the neighbouring tests, never the code under
test: the lazy tongs (bench/scaling_limit.py; every bar at the driven angle
a(t) = 0.7 + 0.2 sin t, tests/runtime/test_tightening.closed_form) and the chain of ten
parallelogram four-bars crossing its singular configuration at t = 0.5
(tests/runtime/test_edges_singular.chain_reference). A point is "off" when q, dq or ddq
misses its target (1e-8, 1e-7, 1e-6) times max(1, max |x|) there.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from driver_support import BACKENDS, derive, kernel_for
from test_edges_singular import TARGETS, chain_reference
from test_tightening import closed_form

import symkin
from symkin.runtime import driver
from symkin.runtime.solving import accuracy, linalg, newton
from symkin.spec import validate as model

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))

UNITS = 18  # 36 bars: the model of every coordinate flags every point of the tongs from here
STRADDLE = np.linspace(0.45, 0.55, 151) + 1e-5  # a fine grid across t = 0.5, off it by 1e-5


def off(solved: tuple[np.ndarray, ...], exact: tuple[np.ndarray, ...]) -> np.ndarray:
    """Per point: True where q, dq or ddq misses its target (the module docstring)."""
    missed = np.zeros(len(solved[0]), dtype=bool)
    for got, want, target in zip(solved, exact, TARGETS):
        scale = np.maximum(1.0, np.abs(want).max(axis=1))
        missed |= np.abs(got - want).max(axis=1) > target * scale
    return missed


@pytest.fixture(scope="module")
def tongs() -> symkin.System:
    import scaling_limit

    return symkin.derive(model.from_dict(scaling_limit.tongs(UNITS)))


def test_only_the_angles_of_the_tongs_enter_phi_q(tongs: symkin.System,
                                                  tmp_path: Path) -> None:
    kernel = symkin.compile(tongs, backend="numpy")  # built once (run cache)
    angles = [name.endswith(".phi") for name in kernel.coordinates]
    assert np.array_equal(kernel.nonlinear, angles)


@pytest.mark.parametrize("backend", BACKENDS)
def test_long_tongs_accurate_and_not_flagged(tongs: symkin.System, backend: str,
                                             tmp_path: Path) -> None:
    kernel = symkin.compile(tongs, backend=backend)  # built once (run cache)
    assert kernel.backend == backend
    t = np.arange(301) * 0.001
    trajectory = symkin.solve(kernel, t=t)
    exact = closed_form(UNITS, t)
    missed = off((trajectory.q, trajectory.dq, trajectory.d2q), exact)
    assert not missed.any()
    assert trajectory.flagged.sum() <= 2 * missed.sum()  # none
    assert np.abs(trajectory.d2q - exact[2]).max() < 1e-11  # errors of 1e-12, not 1e-6


def test_the_norm_bound_alone_flags_the_tongs(tongs: symkin.System, tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """The contract broken on purpose: without the propagated model (the norm bound of the
    error alone decides), every point of the same accurate run is flagged."""
    kernel = symkin.compile(tongs, backend="numpy")  # built once (run cache)
    monkeypatch.setattr(newton, "_propagation", lambda *args: None)
    trajectory = symkin.solve(kernel, t=np.arange(301) * 0.001)
    assert trajectory.flagged.all()


@pytest.fixture(scope="module")
def chain_runs() -> dict[str, object]:
    runs = {}
    for backend in BACKENDS:
        kernel = kernel_for(derive("parallelogram_chain"), backend)
        assert kernel.backend == backend
        runs[backend] = driver.solve(kernel, t=STRADDLE)
    return runs


def _chain_off(trajectory) -> np.ndarray:
    return off((trajectory.q, trajectory.dq, trajectory.d2q), chain_reference(trajectory.t, 10))


@pytest.mark.parametrize("backend", BACKENDS)
def test_straddle_no_point_off_unflagged(chain_runs, backend: str) -> None:
    trajectory = chain_runs[backend]
    missed = _chain_off(trajectory)
    assert trajectory.t.size == STRADDLE.size
    assert 1 <= missed.sum() <= 5  # the points next to the singular configuration
    assert not (missed & ~trajectory.flagged).any()
    # the model of every coordinate flagged 27 points here
    assert trajectory.flagged.sum() <= 20


def test_straddle_both_backends_flag_the_same_points(chain_runs) -> None:
    numpy_run, c_run = (chain_runs[b] for b in BACKENDS)
    assert np.array_equal(numpy_run.flagged, c_run.flagged)


@pytest.mark.parametrize("backend", BACKENDS)
def test_straddle_flags_at_most_twice_the_points_off(chain_runs, backend: str) -> None:
    trajectory = chain_runs[backend]
    assert trajectory.flagged.sum() <= 2 * _chain_off(trajectory).sum()


def test_rows_estimate_is_the_norm_of_those_rows_of_the_inverse() -> None:
    """Hager's estimate of ||P A^-1||_1 never exceeds it and, on these matrices, equals it."""
    rng = np.random.default_rng(29)
    for _ in range(20):
        n = int(rng.integers(3, 40))
        a = np.eye(n) * 3 + rng.normal(size=(n, n))
        rows = rng.random(n) < 0.4
        inverse = np.linalg.inv(a)
        exact = np.abs(inverse[rows]).sum(axis=0).max(initial=0.0)
        factors = linalg.factor(a)
        estimate = accuracy.inverse_norm1(factors.solve, factors.solve_transposed, n, rows)
        assert estimate <= exact * (1 + 1e-12)
        assert estimate >= exact / 3


def test_propagated_position_error_is_the_error_of_dq_and_ddq(chain_runs) -> None:
    """accuracy.propagated, given the actual position error (q less the closed form), gives
    the actual errors of dq and ddq at the points near the singular configuration: there the
    errors of dq and ddq are the position error carried through the solves (to first order,
    the derivation in its docstring)."""
    trajectory = chain_runs["numpy"]
    kernel = kernel_for(derive("parallelogram_chain"), "numpy")
    p = np.asarray(kernel.p_values, dtype=float)
    exact = chain_reference(trajectory.t, 10)
    near = np.flatnonzero(trajectory.cond > 2e4)
    assert near.size >= 5
    for i in near:
        solved = (trajectory.q[i], trajectory.dq[i], trajectory.d2q[i])
        got = _propagate(kernel, p, trajectory.t[i], solved, solved[0] - exact[0][i])
        actual = [float(np.abs(x[i] - want[i]).max())
                  for x, want in ((trajectory.dq, exact[1]), (trajectory.d2q, exact[2]))]
        assert np.allclose(got, actual, rtol=0.1)


def _propagate(kernel, p: np.ndarray, t: float, solved: tuple[np.ndarray, ...],
               error: np.ndarray) -> tuple[float, float]:
    """accuracy.propagated of this position error, with the dense Phi_q of the kernel."""
    q, dq, ddq = solved
    factors = linalg.factor(kernel.phi_q(q, t, p))
    return accuracy.propagated(
        factors.solve, error, float(np.abs(error).max()), 1e-7,
        lambda d: kernel.phi_q(q + d, t, p) @ dq + kernel.phi_t(q + d, t, p),
        lambda d, v: kernel.gamma(q + d, dq + v, t, p) - kernel.phi_q(q + d, t, p) @ ddq)
