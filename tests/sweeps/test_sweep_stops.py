"""Failing sets of a sweep at C speed (sweeps.stops): a set the C batch stops on along the grid
goes on in the generated ``<prefix>_solve_edge`` (the substeps and the bisection to the limit
time in C), with no re-run, and ends as its own ``symkin.solve`` ends it: the same reason, grid
point, bisected time (SolveFailure.reached, in the message) and rows; every other failed set is
re-run as before.

References: each set's own ``symkin.solve`` (the substeps in Python, runtime.solving.edges), and for
the crank-slider the closed form of its limit position. The slider's point lies on the line y = c;
the rod (length b) reaches it from the crank tip (a cos theta, a sin theta) while
|c - a sin theta| <= b. With theta = t^2 + pi/2, sin theta = cos t^2, so (c - b <= a always for
these designs) the motion stops where cos t^2 = (c - b) / a: t_limit = sqrt(arccos((c - b) /
a)), for t^2 within [0, pi].
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import symkin
from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.sweeps import stops
from tests.driver_support import derive, kernel_for, same_condition

T = np.linspace(0.0, 1.5, 31)
BISECTED = re.compile(r"bisected to ([0-9.e+-]+) \.\. ([0-9.e+-]+);")


def _limit_time(p: np.ndarray) -> float:
    a, b, c = p
    ratio = (c - b) / a
    return float(np.sqrt(np.arccos(ratio))) if -1.0 <= ratio <= 1.0 else np.inf


def _designs(count: int, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.array([1.0, 5.0, 4.0]) * (1 + rng.uniform(-0.05, 0.05, size=(count, 3)))


def _same_as_solve(kernel, result, j: int, p: np.ndarray, t: np.ndarray) -> SolveError | None:
    """Set j of result against its own symkin.solve: same reason, time, message, rows."""
    try:
        trajectory = symkin.solve(kernel, t=t, params=p)
    except SolveError as failure:
        done = failure.trajectory.t.size
        assert result.reasons[j] == failure.reason
        assert result.t_reached[j] == failure.t
        # the same words and bisected time; the condition there is C's estimate (to 1 %)
        same_condition(result.messages[j], str(failure))
        assert result.solved[j] == done
        assert np.array_equal(result.q[j, :done], failure.trajectory.q)
        assert np.isnan(result.q[j, done:]).all()
        return failure
    assert result.status[j] == 0 and result.reasons[j] == ""
    assert np.abs(result.q[j] - trajectory.q).max() <= 1e-12
    return None


def _bisected(message: str) -> tuple[float, float]:
    found = BISECTED.search(message)
    assert found is not None, message
    return float(found.group(1)), float(found.group(2))


def test_limit_sets_end_without_rerun_and_equal_per_set_solve(crank_slider, reruns) -> None:
    # 200 draws hold five sets that reach their limit; swept: those five among the first 40
    # (each set is its own solve, so the other 155 passing sets prove nothing more)
    drawn = _designs(200)
    reach = np.flatnonzero([_limit_time(p) <= T[-1] for p in drawn])
    designs = drawn[np.union1d(np.arange(40), reach)]
    limits = np.array([_limit_time(p) for p in designs])
    failing = np.flatnonzero(limits <= T[-1])
    assert failing.size >= 3, "the draw must hold sets that reach their limit"
    result = symkin.sweep(crank_slider, designs, T, workers=1)
    assert np.array_equal(np.flatnonzero(result.status), failing)
    if crank_slider.backend == "c":  # the C edge treatment ends every one of them
        assert reruns == []
    h = T[1] - T[0]
    for j in failing:
        failure = _same_as_solve(crank_slider, result, j, designs[j], T)
        assert failure is not None and failure.reason == "limit position"
        k = result.solved[j]
        assert T[k - 1] < limits[j] <= T[k]  # the closed form lies in the reported interval
        # bisected: the last time solved lies within 1e-8 grid steps of the closed form (Newton
        # converges to tol_phi a hair past the fold, where the residual is that small)
        last, failed = _bisected(result.messages[j])
        assert last == pytest.approx(failure.reached, abs=1e-12) and last < failed
        assert abs(limits[j] - failure.reached) < 1e-8 * h
        assert "drivers[0] angle crank-ground" in result.messages[j]
    for j in np.flatnonzero(result.status == 0)[:20]:
        _same_as_solve(crank_slider, result, j, designs[j], T)


@pytest.mark.parametrize("points", [11, 151])
def test_limit_sets_on_coarse_and_fine_grids_equal_per_set_solve(crank_slider_system, points,
                                                                 reruns) -> None:
    kernel = symkin.compile(crank_slider_system, backend="c")
    t = np.linspace(0.0, 1.5, points)
    designs = _designs(150, seed=points)
    limits = np.array([_limit_time(p) for p in designs])
    failing = np.flatnonzero(limits <= t[-1])
    result = symkin.sweep(kernel, designs, t, workers=1)
    assert np.array_equal(np.flatnonzero(result.status), failing)
    assert reruns == []
    for j in failing:
        assert _same_as_solve(kernel, result, j, designs[j], t).reason == "limit position"
        k = result.solved[j]
        assert t[k - 1] < limits[j] <= t[k]


def test_failed_assembly_is_rerun_and_reported_as_solve_does(crank_slider, reruns) -> None:
    designs = np.array([[1.0, 5.0, 4.0], [1.0, 5.0, 7.0], [1.0, 5.0, 3.5]])  # c > a + b
    result = symkin.sweep(crank_slider, designs, T, workers=1)
    assert list(result.status != 0) == [False, True, False]
    if crank_slider.backend == "c":
        assert reruns == [1]
    failure = _same_as_solve(crank_slider, result, 1, designs[1], T)
    assert failure is not None and failure.reason == "no assembly"
    assert result.solved[1] == 0


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_passable_singular_configuration_is_rerun_and_passed(backend, reruns) -> None:
    """The parallelogram's change point (t = 0.5): the C batch stops a grid step before it;
    the C edge treatment finds a step over it that converges, so the set is re-run (the
    runtime passes it) and solves."""
    kernel = kernel_for(derive("parallelogram"), backend)
    t = np.linspace(0.0, 1.0, 21)
    result = symkin.sweep(kernel, np.zeros((2, 0)), t, workers=1)
    if backend == "c":
        assert reruns == [0, 1]
    for j in range(2):
        assert _same_as_solve(kernel, result, j, np.zeros(0), t) is None
    assert result.ok.all()


def test_edge_stop_leaves_what_it_cannot_end_to_solve(crank_slider_system) -> None:
    """No rows (the assembly), a finished grid, a status with no edge treatment, or
    stop_at_singular: None, the set is re-run."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    edge = kernel.edge_solver()
    options = driver.default_options(kernel)
    p = np.array([1.0, 5.0, 4.2])
    solution = symkin.solve(kernel, t=T, params=p)
    rows = (solution.q, solution.dq, solution.d2q)
    for solved, status in ((0, 1), (T.size, 1), (10, 0), (10, 3)):
        stopped = stops.Stopped(rows, solved, status, 1.0)
        assert stops.edge_stop(kernel, edge, p, T, stopped, options) is None
    stopped = stops.Stopped(rows, 10, 1, 1.0)
    at_singular = driver.default_options(kernel).__class__(stop_at_singular=True)
    assert stops.edge_stop(kernel, edge, p, T, stopped, at_singular) is None
    # a point the plain step missed but the substeps reach: the set goes on in symkin.solve
    assert stops.edge_stop(kernel, edge, p, T, stopped, options) is None


@pytest.mark.parametrize("offset", [-0.02, -0.002, 0.002, 0.02])
def test_a_fold_just_before_or_past_a_grid_point_stops_where_solve_stops(crank_slider_system,
                                                                          offset) -> None:
    """A limit at t = 1.4 + offset grid steps (c = b + a cos t^2): before 1.4 the set stops
    at 1.4, past it at 1.45, bisected to the closed form, as symkin.solve decides."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    h = T[1] - T[0]
    limit = 1.4 + offset * h
    designs = np.array([[1.0, 5.0, 5.0 + np.cos(limit**2)]])
    assert abs(_limit_time(designs[0]) - limit) < 1e-12
    result = symkin.sweep(kernel, designs, T, workers=1)
    failure = _same_as_solve(kernel, result, 0, designs[0], T)
    assert failure is not None and failure.reason == "limit position"
    assert result.t_reached[0] == pytest.approx(1.4 if offset < 0 else 1.45)
    assert _bisected(result.messages[0])[0] == pytest.approx(limit, abs=1e-8 * h)
