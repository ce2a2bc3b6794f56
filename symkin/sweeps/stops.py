"""A set the C batch stopped on, finished without re-running it: the generated solver's edge
treatment decides it as ``symkin.solve`` would.

The C batch reports where a set stopped (the grid index k of the first point its plain step
could not solve), the condition estimate at its last row, and has written the rows before it.
A per-set ``symkin.solve`` goes on from the same rows (the same generated grid loop) into
``runtime.solving.edges``: substeps halved on failure down to about 1e-9 of the grid step, then a
step over the blocked time, some 1,400 Newton iterations in Python (700 times the cost of a solved
set). Here the generated ``<prefix>_solve_edge`` takes those substeps in C, from the batch's
last row; where they stop (no step over the blocked time converges), the set ends as
``symkin.solve`` ends it: a limit position or no convergence (runtime.solving.edges.stopped_at), at
the grid point t[k], with the same bisected time and message
(runtime.solving.failures.explain_stop).

Left to ``symkin.solve`` (None here): a set whose substeps reach t[k] or find a position the
motion passes (it goes on), one stopped at its first point (the assembly) or on a value that
is not finite (no edge treatment there), and stop_at_singular runs. A set solved in another
length unit (runtime.solving.units) is treated in it, as symkin.solve treats it; the caller hands
only sets whose start is not singular (sweeps.starts decided both for the chunk).
Imports NumPy and the runtime only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.contract.status import NOT_FINITE, OK
from symkin.contract.tuning import EDGE_SUBSTEPS
from symkin.runtime.protocol import EDGE_STOPPED, EdgeSolver, KinematicsKernel
from symkin.runtime.solving import edges, failures
from symkin.runtime.solving.newton import Point
from symkin.runtime.solving.units import ScaledKernel

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
    status, the condition estimate at its last row, and the length unit it was decided in
    (runtime.solving.units; the rows are in the kernel's own)."""

    rows: tuple[Array, Array, Array]
    solved: int
    status: int
    cond: float
    unit: float = 1.0


def edge_stop(kernel: KinematicsKernel, edge: EdgeSolver, p: Array, t: Array,
              stopped: Stopped, options: Options) -> Stop | None:
    """The stop of a set the batch stopped on, or None when symkin.solve must run it."""
    return edge_stops(kernel, edge, p[None], t, [stopped], options)[0]


def edge_stops(kernel: KinematicsKernel, edge: EdgeSolver, params: Array, t: Array,
               stopped: list[Stopped], options: Options) -> list[Stop | None]:
    """edge_stop of many sets (params (m, NP), one Stopped each): the edge treatment set by set
    in C, then the limit positions named together (one SVD call, edges.limit_motions)."""
    found = [_edge(kernel, edge, p, t, one, options) for p, one in zip(params, stopped)]
    limits = [j for j, stop in enumerate(found) if stop is not None and stop[0].limit]
    if limits:
        with np.errstate(all="ignore"):
            jacobians = np.array([_jacobian(kernel, params[j], found[j], stopped[j].unit)
                                  for j in limits])
            names = edges.limit_motions(kernel, jacobians)
        for j, (aligned, drivers) in zip(limits, names):
            resolution = found[j][0]  # type: ignore[index]
            resolution.aligned, resolution.drivers = aligned, drivers
    return [None if stop is None else _explained(stop[0], stop[1]) for stop in found]


def _edge(kernel: KinematicsKernel, edge: EdgeSolver, p: Array, t: Array, stopped: Stopped,
          options: Options) -> tuple[edges.Resolution, float] | None:
    """The unnamed stop of one set and its grid point t[k], or None (edge_stop)."""
    k = stopped.solved
    if not 0 < k < t.size or stopped.status in (OK, NOT_FINITE) or options.stop_at_singular:
        return None
    q, dq, ddq = stopped.rows
    with np.errstate(all="ignore"):
        _, h_min, delta = edges.substeps(float(t[k - 1]), float(t[k]))
        found = edge(options, p, (float(t[k - 1]), q[k - 1], dq[k - 1], ddq[k - 1]),
                     stopped.cond, float(t[k]), h_min, delta, stopped.unit)
        if found.outcome != EDGE_STOPPED:
            return None
        reached = edges.State(found.t, Point(found.q, found.dq, found.ddq, found.cond, False))
        stop = edges.stopped_at(kernel, p, options, reached, found.failed, stopped.cond,
                                named=False)
        if found.substeps >= EDGE_SUBSTEPS:  # the bound on the substeps: no limit to name
            stop.limit, stop.substeps = False, found.substeps
    return stop, float(t[k])


def _jacobian(kernel: KinematicsKernel, p: Array, stop: tuple[edges.Resolution, float] | None,
              unit: float) -> Array:
    """Phi_q where the set stopped, seen in its unit (as symkin.solve names the limit)."""
    assert stop is not None and stop[0].reached is not None
    reached = stop[0].reached
    if unit == 1.0:
        return np.asarray(kernel.phi_q(reached.point.q, reached.t, p), dtype=np.float64)
    view = ScaledKernel(kernel, unit)
    return view.phi_q(reached.point.q / view.column, reached.t, p)


def _explained(stop: edges.Resolution, t: float) -> Stop:
    message, reason = failures.explain_stop(stop, t)
    assert stop.reached is not None
    return Stop(reason, message, t, stop.reached.t)
