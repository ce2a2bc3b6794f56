"""One chunk of a sweep solved in this process: the kernel's batch solver (the generated
``<prefix>_solve_batch`` of a C kernel), or the driver set by set for a kernel without one.

The batch runs plain Newton from q0 at t[0], like the first attempt of ``symkin.solve``. A set
it stops on along the grid goes on from its last row in the generated edge treatment
(sweeps.stops: the substeps and the bisection to a limit position in C, no re-run); any other
set it cannot solve is handed to ``symkin.solve`` itself, which adds the damped assembly, the
passage through singular configurations, and names the reason (no assembly, singular, no
convergence, not finite) — so every set of a sweep is what a per-set ``solve`` gives, failures
included (same reason, stop time, bisected time in the message, and rows), and a failed set
costs at most its own re-run.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.contract.status import OK
from symkin.runtime import driver
from symkin.runtime.kernel import Kernel
from symkin.runtime.protocol import BatchSolver, EdgeSolver
from symkin.sweeps.starts import reversed_starts, set_units, singular_starts
from symkin.sweeps.stops import Stopped, edge_stops

Array = NDArray[np.float64]

# Status of a failed set, by the reason symkin.solve gives (0 = solved).
REASON_CODES = {"no convergence": 1, "singular": 2, "not finite": 3, "no assembly": 4}


@dataclass
class Chunk:
    """The results of sets [start, start + m) of a sweep.

    Attributes:
        q, dq, d2q: (m, T, N); rows a set did not reach are NaN.
        status: (m,) 0 = solved, else REASON_CODES[reason].
        solved: (m,) time points solved per set.
        t_reached: (m,) the time of the last point attempted (t[-1] for a solved set).
        iterations: (m,) Newton iterations of the C batch (0 where it did not run).
        reasons, messages: per set, "" when solved.
    """

    q: Array
    dq: Array
    d2q: Array
    status: NDArray[np.int64]
    solved: NDArray[np.int64]
    t_reached: Array
    iterations: NDArray[np.int64]
    reasons: NDArray[np.object_]
    messages: NDArray[np.object_]

    def rows(self, part: slice) -> Chunk:
        """The sets ``part`` of this chunk as views: solving into them fills this chunk."""
        return Chunk(*(getattr(self, f.name)[part] for f in dataclasses.fields(self)))


def empty_chunk(m: int, t: Array, size: int) -> Chunk:
    """Room for m sets (q, dq, d2q not initialised: every row is written or set to NaN)."""
    shape = (m, t.size, size)
    return Chunk(np.empty(shape), np.empty(shape), np.empty(shape),
                 np.zeros(m, dtype=np.int64), np.full(m, t.size, dtype=np.int64),
                 np.full(m, t[-1]), np.zeros(m, dtype=np.int64),
                 np.full(m, "", dtype=object), np.full(m, "", dtype=object))


def solve_chunk(kernel: Kernel, params: Array, t: Array, q0: Array,
                options: Options | None = None, into: Chunk | None = None) -> Chunk:
    """Solve every row of ``params`` (m, NP) over ``t`` from ``q0`` ((N,) or (m, N)), into
    ``into`` (m rows, e.g. ``rows`` of a larger chunk) or a new chunk."""
    options = options or driver.default_options(kernel)
    m, size = params.shape[0], len(kernel.coordinates)
    chunk = empty_chunk(m, t, size) if into is None else into
    starts = np.broadcast_to(q0, (m, size))
    batch = kernel.batch_solver
    pending = range(m) if batch is None else _batch(kernel, batch, params, t, q0, options, chunk)
    for j in pending:
        _solve_one(kernel, params[j], t, starts[j], options, chunk, j)
    return chunk


def _batch(kernel: Kernel, batch: BatchSolver, params: Array, t: Array, q0: Array,
           options: Options, chunk: Chunk) -> list[int]:
    """The chunk through the backend's batch, each set in its unit (sweeps.starts); returns the
    sets left to symkin.solve: those the batch could not solve and the edge treatment does not
    end, a singular start, a first row that is no assembly (sweeps.starts), and a set in
    another unit than 1 where the batch cannot honour it."""
    units = set_units(batch, params, float(t[0]), q0)
    status, iterations, solved, cond, start_cond = batch(params, t, q0, options, chunk.q,
                                                         chunk.dq, chunk.d2q, units)
    chunk.iterations[:] = iterations
    singular = singular_starts(kernel, batch, params, float(t[0]), chunk.q[:, 0], solved,
                               start_cond, units, options)
    unassembled = reversed_starts(kernel, params, float(t[0]), chunk.q[:, 0], solved)
    rerun = singular | unassembled | ((units != 1.0) & (not batch.scale_free))
    failed = np.flatnonzero((status != OK) & ~rerun)
    edge = kernel.edge_solver() if failed.size else None
    ended = set() if edge is None else _edges(kernel, edge, params, t, options, chunk, failed,
                                              (solved, status, cond, units))
    return [int(j) for j in np.flatnonzero(rerun | (status != OK)) if int(j) not in ended]


def _edges(kernel: Kernel, edge: EdgeSolver, params: Array, t: Array, options: Options,
           chunk: Chunk, failed: NDArray[np.intp],
           report: tuple[NDArray[np.int32], NDArray[np.int32], Array, Array]) -> set[int]:
    """The failed sets the edge treatment ends as symkin.solve would (sweeps.stops), written
    into the chunk; the others must be re-run."""
    solved, status, cond, units = report
    stopped = [Stopped((chunk.q[j], chunk.dq[j], chunk.d2q[j]), int(solved[j]),
                       int(status[j]), float(cond[j]), float(units[j])) for j in failed]
    ended = set()
    for j, stop in zip(failed.tolist(), edge_stops(kernel, edge, params[failed], t, stopped,
                                                   options)):
        if stop is None:
            continue
        done = int(solved[j])
        chunk.status[j] = REASON_CODES.get(stop.reason, max(REASON_CODES.values()) + 1)
        chunk.reasons[j], chunk.messages[j] = stop.reason, stop.message
        chunk.t_reached[j], chunk.solved[j] = stop.t, done
        for target in (chunk.q, chunk.dq, chunk.d2q):
            target[j, done:] = np.nan
        ended.add(j)
    return ended


def _solve_one(kernel: Kernel, p: Array, t: Array, q0: Array, options: Options, chunk: Chunk,
               j: int) -> None:
    """Set j through symkin.solve: its rows, or its partial rows and the reason it failed."""
    try:
        trajectory = driver.solve(kernel, t=t, q0=q0, params=p, options=options)
    except driver.SolveFailure as failure:
        trajectory = failure.trajectory
        chunk.status[j] = REASON_CODES.get(failure.reason, max(REASON_CODES.values()) + 1)
        chunk.reasons[j] = failure.reason or "failed"
        chunk.messages[j] = str(failure)
        chunk.t_reached[j] = failure.t
    done = trajectory.t.size
    chunk.solved[j] = done
    for target, rows in zip((chunk.q, chunk.dq, chunk.d2q),
                            (trajectory.q, trajectory.dq, trajectory.d2q)):
        target[j, :done] = rows
        target[j, done:] = np.nan
    if chunk.status[j] == OK:
        chunk.t_reached[j] = t[-1]
