"""The grid loop in the generated C solver, in timed chunks; apart from the driver for size."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from symkin.contract.status import OK, SINGULAR
from symkin.runtime.protocol import GridSolver, KinematicsKernel
from symkin.runtime.solving.linalg import factor_at
from symkin.runtime.solving.newton import Newton
from symkin.runtime.solving.result_arrays import Run as _Run

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]


class _Chunks:
    """How many grid points one call of the C grid loop solves: about CHUNK_SECONDS of work,
    so that Ctrl-C (handled between calls) and progress reports answer quickly, while the
    Python between calls stays negligible."""

    CHUNK_SECONDS = 0.05
    FIRST = 256  # the first chunk's size: a grid this short is one call

    def __init__(self, total: int, reporting: bool) -> None:
        self.limit = max(1, total // 100) if reporting else total
        self.size = min(self.FIRST, self.limit)

    def took(self, seconds: float) -> None:
        """Scale the next chunk to the time this one took (at most 4x larger at once)."""
        grow = 4.0 if seconds <= 0 else min(4.0, self.CHUNK_SECONDS / seconds)
        self.size = int(min(self.limit, max(1, self.size * grow)))


def _c_run(run: _Run, solver: GridSolver, progress: Progress | None) -> int:
    """The grid loop in the generated C solver from point run.done, into the run's arrays
    (bound to the solver): one call per chunk, one call in all for a grid of up to
    _Chunks.FIRST points without progress reports. Stops at the first point the plain step
    cannot solve; returns what the last call solved (its report is the solver's)."""
    total, start = run.t.size, run.done
    if progress is None and total - start <= _Chunks.FIRST:
        solved = solver.advance(start, total)
        run.done = start + solved
        if start == 0:
            run.lever_arm = solver.first_lever_arm
        return solved
    chunks = _Chunks(total, progress is not None)
    solved = 0
    while start < total:
        stop = min(start + chunks.size, total)
        began = time.perf_counter()
        solved = solver.advance(start, stop)
        chunks.took(time.perf_counter() - began)
        if start == 0:  # the call that solved the first row reports its lever arm
            run.lever_arm = solver.first_lever_arm
        run.done = start + solved
        if solver.status != OK:
            break
        if progress is not None:
            progress(run.done, total)
        start = stop
    return solved


def _c_outcome(kernel: KinematicsKernel, run: _Run, solver: GridSolver, p: Array,
               solved: int) -> Newton:
    """The Newton outcome where the C grid loop stopped (status OK at the end of the grid)."""
    run.fallbacks = solver.fallbacks
    result = solver.outcome(solved)
    if result.status != OK:
        last = solver.last_q()
        factors = factor_at(kernel, last, result.t, p) if result.status == SINGULAR else None
        return Newton(last, result.status, result.iterations, result.residual, factors)
    # The last row written is the solver's q: no need to read it back from C.
    q = run.q[run.done - 1] if run.done else solver.last_q()
    return Newton(q, OK, result.iterations, result.residual, None)


def _c_loop(kernel: KinematicsKernel, run: _Run, solver: GridSolver, p: Array,
            progress: Progress | None) -> Newton:
    """The grid loop in the generated C solver from point run.done, and its outcome."""
    if run.done == run.t.size:  # the edge treatment solved the last point: the grid is done
        run.fallbacks = solver.fallbacks  # (the report still holds the failed call's status)
        return Newton(run.q[run.done - 1], OK, 0, 0.0, None)
    solver.bind(run.t, run.q, run.dq, run.d2q, run.cond, run.flagged, run.forces_out)
    return _c_outcome(kernel, run, solver, p, _c_run(run, solver, progress))
