"""Near, at and through singular configurations: every point written is either accurate to
1e-8 (q), 1e-7 (dq), 1e-6 (ddq), each times max(1, max|x|), or flagged; the motion continues
through the change point of a parallelogram; both backends decide alike.

References are closed forms, not the code under test. Chain of N parallelogram four-bars
(tests/mechanisms/parallelogram_chain.yaml, N = 10; parallelogram.yaml, N = 1): rocker i
pinned at (i, 0), length 1; coupler i joins the tips of rockers i and i + 1. On the
parallelogram branch with theta = 0.5 - t (so theta' = -1):
    rocker i:  [i, 0, theta],  [0, 0, -1],  [0, 0, 0]
    coupler i: [i + cos theta, sin theta, 0],  [sin theta, -cos theta, 0],
               [-cos theta, -sin theta, 0]
At theta = 0 every bar lies on the x axis: each loop i has the self-stress of a tension along
x carried by the x rows of O_i, A_i, B_i and O_{i+1} — N independent dependencies (rank loss N).
"""

from __future__ import annotations

import numpy as np
import pytest
from driver_support import BACKENDS, derive, kernel_for

from symkin.errors import SolveError
from symkin.runtime import driver

TARGETS = (1e-8, 1e-7, 1e-6)


def chain_reference(t: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    theta = 0.5 - np.asarray(t, dtype=float)
    zero, one = np.zeros_like(theta), np.ones_like(theta)
    q, dq, ddq = [], [], []
    for i in range(n + 1):
        q += [i * one, zero, theta]
        dq += [zero, zero, -one]
        ddq += [zero, zero, zero]
    for i in range(n):
        c, s = np.cos(theta), np.sin(theta)
        q += [i + c, s, zero]
        dq += [s, -c, zero]
        ddq += [-c, -s, zero]
    return np.stack(q, 1), np.stack(dq, 1), np.stack(ddq, 1)


def unflagged_errors(trajectory, n: int) -> np.ndarray:
    """Max error of q, dq, ddq over the unflagged points, each divided by its target times
    max(1, max|x|) at that point: every entry must be <= 1."""
    exact = chain_reference(trajectory.t, n)
    solved = (trajectory.q, trajectory.dq, trajectory.d2q)
    ratios = []
    for got, want, target in zip(solved, exact, TARGETS):
        scale = np.maximum(1.0, np.abs(want).max(axis=1))
        ratios.append(np.abs(got - want).max(axis=1) / (target * scale))
    ratios = np.array(ratios)[:, ~trajectory.flagged]
    return ratios.max(axis=1) if ratios.size else np.zeros(3)


@pytest.fixture(scope="module", params=BACKENDS)
def chain(request):
    kernel = kernel_for(derive("parallelogram_chain"), request.param)
    assert kernel.backend == request.param
    return kernel


def loop_rows(kernel, i: int) -> set[str]:
    """The x rows of loop i's joints O_i, O_{i+1}, A_i, B_i, by their names in the file."""
    names = {f"O{i}", f"O{i + 1}", f"A{i}", f"B{i}"}
    return {row for row in kernel.rows
            if row.endswith("(x)") and row.split(" ")[1] in names}


def test_at_the_singular_configuration_the_motion_continues(chain) -> None:
    times = 0.5 + 0.05 * np.arange(-10, 11)  # theta = 0 exactly at the middle point
    trajectory = driver.solve(chain, t=times)
    assert trajectory.t.size == times.size  # the run continues to the end
    assert (unflagged_errors(trajectory, 10) <= 1).all()
    assert trajectory.flagged[10] and trajectory.flagged.sum() <= 3
    # what was singular: rank loss 10, one loop of four x rows per lost rank
    [(t_singular, rank_loss, groups)] = trajectory.singular
    assert abs(t_singular - 0.5) < 1e-6 and rank_loss == 10
    assert sorted(map(set, groups), key=sorted) == sorted(
        (loop_rows(chain, i) for i in range(10)), key=sorted)


@pytest.mark.parametrize("offset", [1e-4, 1e-6, 1e-8, 1e-10, -2e-4])
def test_near_and_across_the_singular_configuration(chain, offset: float) -> None:
    """A grid point theta = offset from the singular one (negative: the grid straddles it)."""
    times = 0.5 - offset + 0.05 * np.arange(-10, 10)
    trajectory = driver.solve(chain, t=times)
    assert trajectory.t.size == times.size
    assert (unflagged_errors(trajectory, 10) <= 1).all()
    assert 1 <= trajectory.flagged.sum() <= 3  # a few points, not the run
    assert not trajectory.flagged[:8].any() and not trajectory.flagged[-8:].any()


def test_both_backends_flag_the_same_points() -> None:
    kernels = [kernel_for(derive("parallelogram_chain"), b) for b in BACKENDS]
    assert [k.backend for k in kernels] == list(BACKENDS)
    for offset in (0.0, 1e-5, 1e-9, -2e-4):
        times = 0.5 - offset + 0.05 * np.arange(-6, 6)
        numpy_run, c_run = (driver.solve(k, t=times) for k in kernels)
        assert np.array_equal(numpy_run.flagged, c_run.flagged)
        steady = ~numpy_run.flagged
        assert np.allclose(numpy_run.cond[steady], c_run.cond[steady], rtol=1e-6)


def test_stop_at_singular_keeps_the_old_stop(chain) -> None:
    with pytest.raises(SolveError) as caught:
        driver.solve(chain, t=0.5 + 0.05 * np.arange(-4, 5), stop_at_singular=True)
    failure = caught.value
    assert isinstance(failure, driver.SolveFailure) and failure.reason == "singular"
    assert failure.t == 0.5 and failure.trajectory.t.size == 4
    assert "loses rank 10" in str(failure)
    assert set(failure.rows) == set().union(*(loop_rows(chain, i) for i in range(10)))


@pytest.mark.parametrize("backend", BACKENDS)
def test_parallelogram_change_point(backend: str) -> None:
    kernel = kernel_for(derive("parallelogram"), backend)
    assert kernel.backend == backend
    trajectory = driver.solve(kernel)  # the file's grid 0 .. 1 by 0.05: theta = 0 at t = 0.5
    assert trajectory.t.size == 21
    assert (unflagged_errors(trajectory, 1) <= 1).all()
    assert trajectory.flagged[10] and trajectory.flagged.sum() == 1
    [(_, rank_loss, groups)] = trajectory.singular
    assert rank_loss == 1 and set(groups[0]) == loop_rows(kernel, 0)
    # after the change point the coupler stays parallel to the ground: the same branch
    assert np.abs(trajectory.q[11:, 8]).max() < 1e-9  # c0.phi
