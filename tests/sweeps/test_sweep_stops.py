"""Failing sets of a sweep at C speed (sweeps.stops): a set the C batch stops on at a limit
position is finished from its rows with no re-run, every other failed set is re-run as before,
and every set is what its own ``symkin.solve`` gives (reason, stop time to the grid, rows).

References: each set's own ``symkin.solve``, and for the crank-slider the closed form of its
limit position. The slider's point lies on the line y = c; the rod (length b) reaches it from
the crank tip (a cos theta, a sin theta) while |c - a sin theta| <= b. With theta = t^2 + pi/2,
sin theta = cos t^2, so (c - b <= a always for these designs) the motion stops where
cos t^2 = (c - b) / a: t_limit = sqrt(arccos((c - b) / a)), for t^2 within [0, pi].
"""

from __future__ import annotations

import numpy as np
import pytest

import symkin
from symkin.errors import SolveError
from symkin.sweeps import batch, stops
from tests.driver_support import derive, kernel_for

T = np.linspace(0.0, 1.5, 31)


@pytest.fixture(scope="module", params=["c", "numpy"])
def crank_slider(request, crank_slider_system):
    return kernel_for(crank_slider_system, request.param)


@pytest.fixture
def reruns(monkeypatch):
    """The sets re-run through symkin.solve, by index within their chunk."""
    seen: list[int] = []
    original = batch._solve_one

    def spy(kernel, p, t, q0, options, chunk, j):
        seen.append(j)
        return original(kernel, p, t, q0, options, chunk, j)

    monkeypatch.setattr(batch, "_solve_one", spy)
    return seen


def _limit_time(p: np.ndarray) -> float:
    a, b, c = p
    ratio = (c - b) / a
    return float(np.sqrt(np.arccos(ratio))) if -1.0 <= ratio <= 1.0 else np.inf


def _designs(count: int, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.array([1.0, 5.0, 4.0]) * (1 + rng.uniform(-0.05, 0.05, size=(count, 3)))


def _same_as_solve(kernel, result, j: int, p: np.ndarray, t: np.ndarray) -> SolveError | None:
    """Set j of result against its own symkin.solve: same reason, time, rows."""
    try:
        trajectory = symkin.solve(kernel, t=t, params=p)
    except SolveError as failure:
        done = failure.trajectory.t.size
        assert result.reasons[j] == failure.reason
        assert result.t_reached[j] == failure.t
        assert result.solved[j] == done
        assert np.array_equal(result.q[j, :done], failure.trajectory.q)
        assert np.isnan(result.q[j, done:]).all()
        return failure
    assert result.status[j] == 0 and result.reasons[j] == ""
    assert np.abs(result.q[j] - trajectory.q).max() <= 1e-12
    return None


def test_limit_sets_end_without_rerun_and_equal_per_set_solve(crank_slider, reruns) -> None:
    designs = _designs(200)
    limits = np.array([_limit_time(p) for p in designs])
    failing = np.flatnonzero(limits <= T[-1])
    assert failing.size >= 3, "the draw must hold sets that reach their limit"
    result = symkin.sweep(crank_slider, designs, T, workers=1)
    assert np.array_equal(np.flatnonzero(result.status), failing)
    if crank_slider.backend == "c":  # only a set whose fold is near t[k] goes again
        assert set(reruns) <= set(failing) and len(reruns) < failing.size
        h = T[1] - T[0]
        assert all(T[result.solved[j]] - limits[j] < 0.1 * h for j in reruns)
    for j in failing:
        failure = _same_as_solve(crank_slider, result, j, designs[j], T)
        assert failure is not None and failure.reason == "limit position"
        k = result.solved[j]
        assert T[k - 1] < limits[j] <= T[k]  # the closed form lies in the reported interval
        assert "drivers[0] angle crank-ground" in result.messages[j]
    for j in np.flatnonzero(result.status == 0)[:20]:
        _same_as_solve(crank_slider, result, j, designs[j], T)


@pytest.mark.parametrize("points", [11, 151])
def test_limit_sets_on_coarse_and_fine_grids_equal_per_set_solve(crank_slider_system, points,
                                                                 reruns) -> None:
    """The fold's extrapolation is off by up to a third of a step on 11 points, early on 151:
    a fold it cannot place before t[k] is re-run, so every set is still solve's."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    t = np.linspace(0.0, 1.5, points)
    designs = _designs(150, seed=points)
    limits = np.array([_limit_time(p) for p in designs])
    failing = np.flatnonzero(limits <= t[-1])
    result = symkin.sweep(kernel, designs, t, workers=1)
    assert np.array_equal(np.flatnonzero(result.status), failing)
    assert set(reruns) <= set(failing)
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
    the drivers take no part in the dependency, so the set is re-run and passes it."""
    kernel = kernel_for(derive("parallelogram"), backend)
    t = np.linspace(0.0, 1.0, 21)
    result = symkin.sweep(kernel, np.zeros((2, 0)), t, workers=1)
    if backend == "c":
        assert reruns == [0, 1]
    for j in range(2):
        assert _same_as_solve(kernel, result, j, np.zeros(0), t) is None
    assert result.ok.all()


def test_limit_stop_refuses_what_it_cannot_tell(crank_slider_system) -> None:
    """Too few rows, a finished grid, or rows that do not approach a fold: re-run."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    options = symkin.runtime.driver.default_options(kernel)
    p = np.array([1.0, 5.0, 4.2])  # limit at sqrt(arccos(-0.8)) = 1.6065 > 1.5: none here
    solution = symkin.solve(kernel, t=T, params=p)
    rows = (solution.q, solution.dq, solution.d2q)
    for solved in (0, 1, T.size):
        assert stops.limit_stop(kernel, p, T, rows, solved, kernel.q0, options) is None
    assert stops.limit_stop(kernel, p, T, rows, 10, kernel.q0, options) is None  # far from it
    nan = solution.q.copy()
    nan[28] = np.nan
    assert stops.limit_stop(kernel, p, T, (nan, *rows[1:]), 29, kernel.q0, options) is None


@pytest.mark.parametrize("offset", [-0.02, -0.002, 0.002, 0.02])
def test_a_fold_just_before_or_past_a_grid_point_stops_where_solve_stops(crank_slider_system,
                                                                          offset) -> None:
    """A limit at t = 1.4 + offset grid steps (c = b + a cos t^2): before 1.4 the set stops
    at 1.4, past it at 1.45, as symkin.solve decides with its substeps."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    h = T[1] - T[0]
    limit = 1.4 + offset * h
    designs = np.array([[1.0, 5.0, 5.0 + np.cos(limit**2)]])
    assert abs(_limit_time(designs[0]) - limit) < 1e-12
    result = symkin.sweep(kernel, designs, T, workers=1)
    failure = _same_as_solve(kernel, result, 0, designs[0], T)
    assert failure is not None and failure.reason == "limit position"
    assert result.t_reached[0] == pytest.approx(1.4 if offset < 0 else 1.45)


@pytest.mark.parametrize("offset", [-0.003, 0.003])
def test_the_closer_look_tells_a_fold_just_before_t_k_from_one_just_past(crank_slider_system,
                                                                        offset) -> None:
    """Rows up to t[k-1] = 1.35 (k = 28, t[k] = 1.4) and a limit at 1.4 + offset grid steps:
    the two-point extrapolation cannot tell on which side of t[k] it lies; the closer look
    must (past t[k]: symkin.solve's substeps reach t[k], so None, the set is re-run)."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    options = symkin.runtime.driver.default_options(kernel)
    h = T[1] - T[0]
    p = np.array([1.0, 5.0, 5.0 + np.cos((1.4 + offset * h) ** 2)])
    solution = symkin.solve(kernel, t=T[:28], params=p)
    rows = (solution.q, solution.dq, solution.d2q)
    stop = stops.limit_stop(kernel, p, T, rows, 28, kernel.q0, options)
    if offset < 0:
        assert stop is not None and stop.t == T[28] and stop.reason == "limit position"
    else:
        assert stop is None
