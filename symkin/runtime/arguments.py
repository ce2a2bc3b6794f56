"""The arguments of a solve, checked once: the time grid, the parameter values, the first
guess. Shared by symkin.solve, symkin scan and symkin.sweep (through the driver, which
re-exports these names), so that all three refuse the same mistakes with the same message.

They run on every call of a solve, so each is a few vectorised operations on the array as
given (no copy of a grid that is already float64) rather than a pass per rule.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin import limits
from symkin.errors import SolveError
from symkin.limits import listed
from symkin.runtime.protocol import KinematicsKernel

Array = NDArray[np.float64]


def grid(t0: float, t1: float, dt: float) -> Array:
    """t0 + k dt for k = 0, 1, ... up to t1 included, computed per point (no drift).

    The end point is snapped to t1 when the interval holds a whole number of steps, so that
    0:0.05:1.5 ends at 1.5 exactly, as MATLAB's colon does.
    """
    if not (dt > 0 and t1 >= t0 and math.isfinite(t1 - t0)):
        raise SolveError(f"bad time grid t0={t0}, t1={t1}, dt={dt}: need dt > 0 and t1 >= t0")
    if limits.grid_points(t0, t1, dt) > limits.MAX_GRID_POINTS:
        raise SolveError(f"the grid t0={t0}, t1={t1}, dt={dt} has more than "
                         f"{limits.MAX_GRID_POINTS} points; use a larger dt")
    steps = math.floor((t1 - t0) / dt + 1e-9)
    times = t0 + dt * np.arange(steps + 1, dtype=float)
    if abs(times[-1] - t1) <= 1e-9 * dt:
        times[-1] = t1
    return times


def time_points(kernel: KinematicsKernel, t: ArrayLike | None) -> Array:
    """The times to solve at: the file's grid (t None), or t checked (finite, increasing).

    The caller's array itself when it is already a 1-D float64 array (no copy is made).
    """
    if t is None:
        return _file_grid(*kernel.time_grid).copy()
    if type(t) is np.ndarray and t.dtype is _FLOAT64 and t.ndim == 1 \
            and 0 < t.size <= _CHECKED_SIZE:
        key = t.tobytes()  # a grid passed again and again: the same bytes, the same verdict
        if key not in _CHECKED:
            _check_times(t)
            if len(_CHECKED) >= 16:
                _CHECKED.clear()
            _CHECKED.add(key)
        return t
    return _check_times(_floats(t, "t"))


_CHECKED: set[bytes] = set()
"""Short grids (up to _CHECKED_SIZE points) time_points has found valid, by their bytes."""
_CHECKED_SIZE = 256


def _check_times(times: Array) -> Array:
    """times as time_points returns them (finite, increasing, 1-D), or a SolveError."""
    if times.ndim != 1:
        times = np.atleast_1d(times)
    # Finite ends as Python floats (their sum overflows to inf without a NumPy warning).
    if times.ndim != 1 or times.size == 0 or \
            not math.isfinite(times.item(0) + times.item(-1)):
        raise SolveError("t must be a non-empty 1-D sequence of finite times")
    # Strictly increasing steps between finite ends: then every time is finite (a NaN fails
    # the comparison). One comparison counted, where diff, isfinite and all would take more.
    if times.size > 1 and np.count_nonzero(times[1:] > times[:-1]) != times.size - 1:
        if not np.all(np.isfinite(times)):
            raise SolveError("t must be a non-empty 1-D sequence of finite times")
        raise SolveError("t must be strictly increasing")
    return times


@functools.lru_cache(maxsize=32)
def _file_grid(t0: float, t1: float, dt: float) -> Array:
    """grid(t0, t1, dt), made once per grid (a kernel's own grid is asked for again and again);
    read-only, so that the shared array can only be copied."""
    times = grid(t0, t1, dt)
    times.setflags(write=False)
    return times


def parameter_values(kernel: KinematicsKernel,
                     params: Mapping[str, float] | ArrayLike | None) -> Array:
    """Nominal parameter values, overridden by name (a mapping) or replaced (a sequence);
    always a new array, which the caller may keep."""
    if params is None:
        nominal = kernel.p_values
        if type(nominal) is np.ndarray and nominal.dtype is _FLOAT64:  # a kernel's own
            return nominal.copy()
        return np.array(nominal, dtype=float)
    # An array is the common case in a loop; the Mapping test (an ABC) is the costlier one.
    if not isinstance(params, np.ndarray) and isinstance(params, Mapping):
        values = np.array(kernel.p_values, dtype=float)
        names = list(kernel.parameter_names)
        for name, value in params.items():
            if name not in names:
                known = listed(names) or "none"
                raise SolveError(f"unknown parameter {name!r}; the mechanism has: {known}")
            number = _floats(value, f"params[{name!r}]")
            if number.ndim:
                raise SolveError(f"params[{name!r}] must be one number, not {number.size}")
            values[names.index(name)] = number
        return values
    given = np.array(_floats(params, "params"))
    if given.shape != kernel.p_values.shape:
        raise SolveError(f"params has {given.size} values; the mechanism has "
                         f"{kernel.p_values.size}")
    return given


def first_guess(kernel: KinematicsKernel, q0: ArrayLike | None) -> Array:
    """The first guess at t[0]: the file's q0, or q0 checked (read, never written)."""
    q = kernel.q0 if q0 is None else q0
    if not (type(q) is np.ndarray and q.dtype is _FLOAT64):  # else as it is (_floats)
        q = _floats(q, "q0")
    if q.shape != (len(kernel.coordinates),):
        raise SolveError(f"q0 has {q.size} values; the mechanism has "
                         f"{len(kernel.coordinates)} coordinates")
    return q


_FLOAT64 = np.dtype(np.float64)


def _floats(value: ArrayLike, what: str) -> Array:
    """value as float64 (no copy of a float64 array); text or complex numbers are a SolveError
    that names the argument, not a ValueError from NumPy or a silently dropped imaginary part."""
    if type(value) is np.ndarray and value.dtype is _FLOAT64:  # the usual case, as it is
        return value
    if np.iscomplexobj(value):
        raise SolveError(f"{what} must be real numbers, not complex")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise SolveError(f"{what} must be numbers: {error}") from None
