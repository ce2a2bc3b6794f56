"""A set the C batch stopped on, finished without re-running it: the generated solver's edge
treatment decides it as ``symkin.solve`` would.

The C batch reports where a set stopped (the grid index k of the first point its plain step
could not solve), the condition estimate at its last row, and has written the rows before it.
A per-set ``symkin.solve`` goes on from the same rows (the same generated grid loop) into
``runtime.edges``: substeps halved on failure down to about 1e-9 of the grid step, then a step
over the blocked time, some 1,400 Newton iterations in Python (700 times the cost of a solved
set). Here the generated ``<prefix>_solve_edge`` takes those substeps in C, from the batch's
last row; where they stop (no step over the blocked time converges), the set ends as
``symkin.solve`` ends it: a limit position or no convergence (runtime.edges.stopped_at), at the
grid point t[k], with the same bisected time and message (runtime.failures.explain_stop).

Left to ``symkin.solve`` (None here): a set whose substeps reach t[k] or find a position the
motion passes (it goes on), one stopped at its first point (the assembly) or on a value that
is not finite (no edge treatment there), a singular start (runtime.start), a set solved in
another unit (runtime.units: the batch's rows are not that run's), and stop_at_singular runs.
Imports NumPy and the runtime only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.contract.status import NOT_FINITE, OK
from symkin.runtime import edges, failures, units
from symkin.runtime.newton import Point
from symkin.runtime.protocol import EDGE_STOPPED, EdgeSolver, KinematicsKernel
from symkin.runtime.start import singular_start

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Stop:
    """A set stopped between t[k-1] and t[k], as symkin.solve reports it."""

    reason: str
    message: str
    t: float  # the grid point t[k] (SolveFailure.t)
    reached: float  # the last time solved by the substeps (SolveFailure.reached)


@dataclass(frozen=True)
class Stopped:
    """How the batch left one set: its rows (q, dq, ddq, each (T, N)), the rows solved, its
    status and the condition estimate at its last row."""

    rows: tuple[Array, Array, Array]
    solved: int
    status: int
    cond: float


def edge_stop(kernel: KinematicsKernel, edge: EdgeSolver, p: Array, t: Array, q0: Array,
              stopped: Stopped, options: Options) -> Stop | None:
    """The stop of a set the batch stopped on, or None when symkin.solve must run it."""
    k = stopped.solved
    if not 0 < k < t.size or stopped.status in (OK, NOT_FINITE) or options.stop_at_singular:
        return None
    if units.unit_for(kernel, q0, float(t[0]), p) != 1.0:
        return None
    q, dq, ddq = stopped.rows
    with np.errstate(all="ignore"):
        if singular_start(kernel, q[0], float(t[0]), p, options) is not None:
            return None
        _, h_min, delta = edges.substeps(float(t[k - 1]), float(t[k]))
        found = edge(options, p, (float(t[k - 1]), q[k - 1], dq[k - 1], ddq[k - 1]),
                     stopped.cond, float(t[k]), h_min, delta)
        if found.outcome != EDGE_STOPPED:
            return None
        reached = edges.State(found.t, Point(found.q, found.dq, found.ddq, found.cond, False))
        stop = edges.stopped_at(kernel, p, options, reached, found.failed, stopped.cond)
    message, reason = failures.explain_stop(stop, float(t[k]))
    return Stop(reason, message, float(t[k]), found.t)
