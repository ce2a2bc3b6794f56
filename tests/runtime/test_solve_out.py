"""solve's result arrays: written in place with ``out=``, checked with a clear error, and the
C grid loop's short way back (the whole grid solved in C) giving the same bytes as the general
path through assembly and edge treatment.

References: the slider of the textbook crank-slider in closed form (Example 2.7: crank angle
f1 = t^2 + pi/2, slider x3 = a cos f1 + sqrt(b^2 - (c - a sin f1)^2)), and, for the contract
"the same numbers, written into your arrays", a fresh solve of the same grid.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from driver_support import BACKENDS, derive, kernel_for

import symkin
from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.solving.result_arrays import allocate

ARRAYS = ("t", "q", "dq", "d2q", "cond", "flagged")
TIMES = np.linspace(0.0, 1.5, 31)


def slider_x(t: np.ndarray, a: float, b: float, c: float) -> np.ndarray:
    f1 = t**2 + np.pi / 2
    return a * np.cos(f1) + np.sqrt(b**2 - (c - a * np.sin(f1)) ** 2)


@pytest.fixture(scope="module", params=BACKENDS)
def kernel(request, crank_slider_system):
    kernel = kernel_for(crank_slider_system, request.param)
    assert kernel.backend == request.param
    return kernel


@pytest.fixture(scope="module")
def c_kernel(crank_slider_system):
    kernel = symkin.compile(crank_slider_system, backend="c")
    assert kernel.backend == "c" and kernel.has_grid_solver
    return kernel


def _same(a: Trajectory, b: Trajectory) -> None:
    for name in (*ARRAYS, "params", "point_vectors"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.coordinates == b.coordinates and a.points == b.points
    assert a.singular == b.singular and a.lu_fallbacks == b.lu_fallbacks


def test_out_trajectory_is_written_in_place(kernel) -> None:
    first = driver.solve(kernel, t=TIMES, params=[1.0, 5.0, 4.0])
    second = driver.solve(kernel, t=TIMES, params=[1.1, 4.8, 4.1], out=first)
    for name in ARRAYS:
        assert getattr(second, name) is getattr(first, name), name
    _same(second, driver.solve(kernel, t=TIMES, params=[1.1, 4.8, 4.1]))
    assert np.abs(second.q[:, 6] - slider_x(TIMES, 1.1, 4.8, 4.1)).max() < 1e-10
    assert np.array_equal(second.params, [1.1, 4.8, 4.1])


def test_out_tuple_of_arrays(kernel) -> None:
    q, dq, d2q = (np.full((TIMES.size, kernel.nq), np.nan) for _ in range(3))
    result = driver.solve(kernel, t=list(TIMES), out=(q, dq, d2q))
    assert result.q is q and result.dq is dq and result.d2q is d2q
    _same(result, driver.solve(kernel, t=TIMES))
    assert np.abs(q[:, 6] - slider_x(TIMES, 1.0, 5.0, 4.0)).max() < 1e-10


def test_out_with_the_grid_of_the_result_itself(c_kernel) -> None:
    """t=previous.t, out=previous: the grid is read before it is overwritten (by itself)."""
    previous = driver.solve(c_kernel, t=TIMES)
    again = driver.solve(c_kernel, t=previous.t, params={"a": 0.9}, out=previous)
    assert again.t is previous.t and np.array_equal(again.t, TIMES)
    assert np.abs(again.q[:, 6] - slider_x(TIMES, 0.9, 5.0, 4.0)).max() < 1e-10


def test_out_with_sensitivities_and_a_float_kernel(crank_slider_system, c_kernel) -> None:
    previous = driver.solve(c_kernel, t=TIMES)
    with_q_p = driver.solve(c_kernel, t=TIMES, out=previous, sensitivities=True)
    assert with_q_p.q is previous.q and with_q_p.q_p is not None
    assert with_q_p.q_p.shape == (TIMES.size, c_kernel.nq, 3)
    single = symkin.compile(crank_slider_system, backend="c", real="float")
    assert single.backend == "c" and single.real == "float"
    previous = driver.solve(single, t=TIMES)
    result = driver.solve(single, t=TIMES, params=[1.05, 5.0, 4.0], out=previous)
    assert result.q is previous.q and result.q.dtype == np.float64
    _same(result, driver.solve(single, t=TIMES, params=[1.05, 5.0, 4.0]))
    assert np.abs(result.q[:, 6] - slider_x(TIMES, 1.05, 5.0, 4.0)).max() < 1e-4


def _rows(n: int = 9, size: int = TIMES.size) -> np.ndarray:
    return np.empty((size, n))


BAD_OUTS = {
    "not arrays": (lambda: {"q": _rows()}, "out must be a Trajectory"),
    "two arrays": (lambda: (_rows(), _rows()), "out must be a Trajectory"),
    "list member": (lambda: (_rows(), _rows(), [[0.0] * 9] * 31), "must be a NumPy array"),
    "rows": (lambda: (_rows(size=30), _rows(), _rows()), "shape (30, 9); this solve needs (31, 9)"),
    "columns": (lambda: (_rows(), _rows(8), _rows()), "shape (31, 8)"),
    "float32": (lambda: (_rows(), _rows(), np.zeros((31, 9), np.float32)), "dtype float32"),
    "strided": (lambda: (_rows(), np.empty((9, 31)).T, _rows()), "not C-contiguous"),
    "read-only": (lambda: (_rows(), _rows(), _read_only()), "read-only"),
    "same array": (lambda: (lambda a: (a, _rows(), a))(_rows()), "share memory"),
    "overlapping views": (lambda: (lambda big: (big[:31], big[1:32], _rows()))(
        np.empty((40, 9))), "q (out[0]) and dq (out[1]) share memory"),
}


def _read_only() -> np.ndarray:
    array = _rows()
    array.setflags(write=False)
    return array


@pytest.mark.parametrize("case", BAD_OUTS)
def test_bad_out_is_refused_with_a_clear_error(case: str, c_kernel) -> None:
    make, message = BAD_OUTS[case]
    with pytest.raises(SolveError) as caught:
        driver.solve(c_kernel, t=TIMES, out=make())
    assert message in str(caught.value) and type(caught.value) is SolveError


def test_out_trajectory_of_another_grid_is_refused(c_kernel) -> None:
    shorter = driver.solve(c_kernel, t=TIMES[:10])
    with pytest.raises(SolveError, match=r"out: t has shape \(10,\); this solve needs \(31,\)"):
        driver.solve(c_kernel, t=TIMES, out=shorter)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_failure_views_the_rows_written_into_out(backend: str, crank_slider_system) -> None:
    """a = 1.1, b = 3.5: the rod cannot reach the slide line past a limit position (see
    test_edges_limits_assembly); the rows before it are in the caller's arrays."""
    kernel = kernel_for(crank_slider_system, backend)
    assert kernel.backend == backend
    q, dq, d2q = _rows(), _rows(), _rows()
    with pytest.raises(driver.SolveFailure) as caught:
        driver.solve(kernel, t=TIMES, params={"a": 1.1, "b": 3.5}, out=(q, dq, d2q))
    partial = caught.value.trajectory
    done = partial.t.size
    assert 0 < done < TIMES.size and caught.value.reason == "limit position"
    assert np.shares_memory(partial.q, q) and np.array_equal(partial.q, q[:done])
    assert np.abs(q[:done, 6] - slider_x(TIMES[:done], 1.1, 3.5, 4.0)).max() < 1e-10


def test_the_short_way_back_builds_every_field(c_kernel) -> None:
    """The C loop's result is built without the dataclass constructor: every field is set, as
    the constructor sets it, and the point vectors are those of kernel.point_vectors."""
    fast = driver.solve(c_kernel, t=TIMES, params=[1.1, 4.8, 4.1])
    assert set(vars(fast)) == {field.name for field in dataclasses.fields(Trajectory)}
    built = dataclasses.replace(fast)  # through __init__ and its checks
    _same(fast, built)
    assert np.array_equal(fast.point_vectors, c_kernel.point_vectors([1.1, 4.8, 4.1]))
    assert fast.q_p is None and fast.dq_p is None


def test_the_short_way_back_equals_the_general_path(c_kernel) -> None:
    """The same grid through the general path (the C loop driven by driver._c_loop and the
    result built by driver._trajectory after it) gives the same bytes."""
    fast = driver.solve(c_kernel, t=TIMES, params=[1.1, 4.8, 4.1])
    p = np.array([1.1, 4.8, 4.1])
    run = allocate(TIMES, c_kernel.nq, None)
    solver = c_kernel.grid_solver(driver.default_options(c_kernel), c_kernel.q0, p)
    try:
        assert driver._c_loop(c_kernel, run, solver, p, None).status == 0
    finally:
        solver.release()
    _same(fast, driver._trajectory(c_kernel, run, p))


def test_rows_before_an_edge_are_the_same_bytes() -> None:
    """Parallelogram chain (C): a grid that crosses the singular configuration at t = 0.5
    takes the edge treatment; one that stops before it returns straight from the C loop. The
    rows they share are the same bytes."""
    kernel = kernel_for(derive("parallelogram_chain"), "c")
    assert kernel.backend == "c"
    across = 0.5 + 0.05 * np.arange(-10, 11)
    general = driver.solve(kernel, t=across)
    assert general.singular and general.t.size == across.size  # the edge was taken
    short = driver.solve(kernel, t=across[:9])
    assert not short.singular
    for name in ARRAYS:
        assert np.array_equal(getattr(short, name), getattr(general, name)[:9]), name


def test_the_file_grid_is_made_once_and_never_shared(c_kernel) -> None:
    first = driver.solve(c_kernel)
    first.t[:] = -1.0
    second = driver.solve(c_kernel)
    assert second.t[0] == 0.0 and second.t[-1] == 1.5 and second.t is not first.t
    assert driver.time_points(c_kernel, None).flags.writeable


def test_the_callers_grid_and_parameters_are_copied(c_kernel) -> None:
    times, p = TIMES.copy(), np.array([1.0, 5.0, 4.0])
    result = driver.solve(c_kernel, t=times, params=p)
    assert result.t is not times and result.params is not p
    times[:] = 0.0
    p[:] = 0.0
    assert result.t[-1] == 1.5 and np.array_equal(result.params, [1.0, 5.0, 4.0])


def test_out_into_a_memory_mapped_file(tmp_path, c_kernel) -> None:
    """Arrays of a file on disk (np.memmap, an ndarray subclass with a base) are written."""
    shape = (TIMES.size, c_kernel.nq)
    q, dq, d2q = (np.lib.format.open_memmap(tmp_path / f"{name}.npy", mode="w+",
                                            dtype=np.float64, shape=shape)
                  for name in ("q", "dq", "d2q"))
    result = driver.solve(c_kernel, t=TIMES, out=(q, dq, d2q))
    assert result.q is q
    q.flush()
    assert np.array_equal(np.load(tmp_path / "q.npy"), driver.solve(c_kernel, t=TIMES).q)
