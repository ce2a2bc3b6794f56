"""The generated ``<prefix>_solve_edge`` called through cffi (the C backend's
``runtime.protocol.EdgeSolver``): the substeps and the bisection to a limit position of a set
the C batch stopped on, at C speed (used by ``sweeps.stops``)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.backends.c.csolver import fill_options
from symkin.contract.options import Options
from symkin.runtime.protocol import EdgeFound

Array = NDArray[np.float64]


class EdgeSolver:
    """The structs of ``<prefix>_solve_edge``, allocated once and reused call after call."""

    def __init__(self, ffi: Any, lib: Any, name: str, nq: int) -> None:
        self._ffi, self._lib, self._name, self._n = ffi, lib, name, nq
        self._options = ffi.new(f"{name}_options *")
        self._state = ffi.new(f"{name}_state *")
        self._work = ffi.new_allocator(should_clear_after_alloc=False)(f"{name}_workspace *")
        self._report = ffi.new(f"{name}_report *")
        self._edge = ffi.new(f"{name}_edge_report *")
        self._set: tuple[Options, float] | None = None
        self._solve = getattr(lib, f"{name}_solve_edge")
        self._p = ffi.new(f"{name}_real[]", max(int(getattr(lib, f"{name.upper()}_NP")), 1))
        self.dtype = np.float32 if ffi.sizeof(f"{name}_real") == 4 else np.float64

    def __call__(self, options: Options, p: Array, start: tuple[float, Array, Array, Array],
                 cond: float, t: float, h_min: float, delta: float, unit: float = 1.0
                 ) -> EdgeFound:
        """From the solved point ``start`` (t, q, dq, ddq; its condition estimate ``cond``)
        towards the grid point t, decided in the length unit ``unit`` (q, dq, ddq in and out
        in the mechanism's own)."""
        if self._set is None or options is not self._set[0] or unit != self._set[1]:
            fill_options(self._lib, self._name, self._options, options, unit)
            self._set = (options, unit)
        state, n, memmove, dtype = self._state, self._n, self._ffi.memmove, self.dtype
        size = n * np.dtype(dtype).itemsize
        state.t = start[0]
        for target, values in zip((state.q, state.dq, state.ddq), start[1:]):
            memmove(target, np.ascontiguousarray(values, dtype=dtype), size)
        state.started = 1
        memmove(self._p, np.ascontiguousarray(p, dtype=dtype), p.size * np.dtype(dtype).itemsize)
        outcome = self._solve(self._options, self._p, t, h_min, delta, cond, state, self._work,
                              self._report, self._edge)
        rows = np.frombuffer(self._ffi.buffer(state, 3 * size), dtype=dtype).astype(np.float64)
        edge = self._edge
        return EdgeFound(int(outcome), float(edge.failed), float(edge.cond), float(state.t),
                         rows[:n], rows[n:2 * n], rows[2 * n:], int(edge.substeps))
