"""The arrays a solve writes: allocated once per call, or the caller's own (``out=``).

Fresh arrays are made with ``np.empty``: a row is shown only once it is solved, so nothing
needs zero-filling, and the C solver writes into them directly. A caller that solves again
and again can hand back the arrays of an earlier result (numpy's ``out=`` convention): they
are checked once per call — shape, dtype, layout, no overlap — and written in place, so a
long grid does not pay for fresh pages on every solve.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from symkin.errors import SolveError
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.solving.edges import Passage, State
from symkin.runtime.solving.newton import Point

Array = NDArray[np.float64]
Out = Trajectory | Sequence[Array]


class Run:
    """The arrays of one solve, filled point by point; ``done`` points are valid.

    Attributes:
        t: the time points (T,), owned by the run (a copy of the caller's grid).
        q, dq, d2q: (T, N) rows; cond (T,) the condition estimates; flagged (T,) the flags.
        done: how many leading rows are solved.
        forces_out: (lam (T, N), loads (T, NLOADS)) for the C grid loop of a kernel with
            inverse dynamics, NaN where it did not write; None otherwise.
        fallbacks: the generated sparse LU's fall-backs to dense LU (C solver).
        passages: the singular configurations passed through.
        caller_owned: the arrays are the caller's (``out=``): a partial result views them
            rather than copying its rows out.
        lever_arm: the length scale at the first row (runtime.solving.start.lever_arm, raw),
            as the solver that solved it found it from its own Phi_q there, in the kernel's
            own unit; None where it was not reported (then the start check works it out).
    """

    __slots__ = ("caller_owned", "cond", "d2q", "done", "dq", "fallbacks", "flagged",
                 "forces_out", "lever_arm", "passages", "q", "t")

    def __init__(self, t: Array, q: Array, dq: Array, d2q: Array, cond: Array,
                 flagged: NDArray[np.bool_], caller_owned: bool = False) -> None:
        self.t, self.q, self.dq, self.d2q = t, q, dq, d2q
        self.cond, self.flagged = cond, flagged
        self.done = 0
        self.fallbacks = 0
        self.passages: list[Passage] = []
        self.caller_owned = caller_owned
        self.lever_arm: float | None = None
        # inverse dynamics: (lam, loads) rows the C grid loop fills (NaN: not filled there)
        self.forces_out: tuple[Array, Array] | None = None

    def store(self, k: int, point: Point) -> None:
        self.q[k], self.dq[k], self.d2q[k] = point.q, point.dq, point.ddq
        self.cond[k], self.flagged[k] = point.cond, point.flagged
        self.done = k + 1

    def state(self, k: int) -> State:
        """Point k as the predictor's state."""
        return State(float(self.t[k]), Point(self.q[k], self.dq[k], self.d2q[k],
                                             float(self.cond[k]), bool(self.flagged[k])))


def allocate(times: Array, n: int, out: Out | None) -> Run:
    """The run's arrays for the grid ``times`` and N = n coordinates: fresh, or ``out``'s."""
    if out is None:
        size, empty = times.size, np.empty
        rows = (size, n)
        return Run(times.copy(), empty(rows), empty(rows), empty(rows), empty(size),
                   empty(size, np.bool_))
    return _reuse(times, n, out)


def _reuse(times: Array, n: int, out: Out) -> Run:
    size = times.size
    if isinstance(out, Trajectory):
        arrays = (out.t, out.q, out.dq, out.d2q, out.cond, out.flagged)
        names: tuple[str, ...] = ("t", "q", "dq", "d2q", "cond", "flagged")
    elif isinstance(out, (tuple, list)) and len(out) == 3:
        arrays = (np.empty(size), *out, np.empty(size), np.empty(size, dtype=np.bool_))
        names = ("t", "q (out[0])", "dq (out[1])", "d2q (out[2])", "cond", "flagged")
    else:
        raise SolveError("out must be a Trajectory returned by an earlier solve, or a tuple "
                         f"(q, dq, d2q) of three arrays; got {type(out).__name__}")
    rows = (size, n)
    for name, array, shape, dtype in zip(names, arrays, ((size,), rows, rows, rows, (size,),
                                                         (size,)), _DTYPES):
        if not (isinstance(array, np.ndarray) and array.shape == shape
                and array.dtype == dtype):
            _refuse(name, array, shape, dtype)
        flags = array.flags
        if not (flags.c_contiguous and flags.writeable):
            _refuse(name, array, shape, dtype)
    # Two distinct arrays that own their memory (no base) cannot overlap: that settles the
    # usual case, an earlier solve's arrays, without the costlier test of every pair.
    if len({id(a) for a in arrays}) < len(arrays) or \
            any(a.base is not None for a in arrays):
        _check_disjoint(arrays, names)
    np.copyto(arrays[0], times)
    return Run(*arrays, caller_owned=True)


_DTYPES = (np.dtype(np.float64),) * 5 + (np.dtype(np.bool_),)


def _refuse(name: str, array: object, shape: tuple[int, ...], dtype: np.dtype) -> None:
    """Raise the SolveError that says what is wrong with one output array."""
    if not isinstance(array, np.ndarray):
        raise SolveError(f"out: {name} must be a NumPy array, got {type(array).__name__}")
    what = "(time points, coordinates)" if len(shape) == 2 else "(time points)"
    if array.shape != shape:
        problem = f"has shape {array.shape}; this solve needs {shape} {what}"
    elif array.dtype != dtype:
        problem = f"has dtype {array.dtype}; the solve writes {dtype}"
    elif not array.flags.c_contiguous:
        problem = "is not C-contiguous (a strided view); pass a contiguous array"
    else:
        problem = "is read-only"
    raise SolveError(f"out: {name} {problem}")


def _check_disjoint(arrays: Sequence[NDArray[np.generic]], names: Sequence[str]) -> None:
    """No two output arrays may share memory (each would overwrite the other's rows)."""
    for i, a in enumerate(arrays):
        for j in range(i):
            if np.may_share_memory(a, arrays[j]):
                raise SolveError(f"out: {names[j]} and {names[i]} share memory; pass "
                                 "separate arrays")
