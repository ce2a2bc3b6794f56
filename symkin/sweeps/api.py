"""``symkin.sweep``: many parameter sets of one mechanism over one time grid.

One compiled kernel serves every set (parameters are run-time inputs of the generated code).
In this process the generated ``<prefix>_solve_batch`` solves a whole chunk in one C call;
``workers=N`` spreads chunks over local processes and ``client=`` over a Dask cluster. Every
set is what ``symkin.solve(kernel, t, q0, params)`` gives for it, failures included: a set
that cannot be solved is marked with its reason and never stops the others.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin import limits
from symkin.contract.options import Options
from symkin.errors import SolveError
from symkin.limits import listed
from symkin.runtime import driver
from symkin.runtime.dynamics.model import refuse_motion
from symkin.runtime.input_driven.inputs import refuse_inputs
from symkin.runtime.kernel import Kernel
from symkin.runtime.loads import forces
from symkin.runtime.outputs import redundant
from symkin.sweeps import parallel
from symkin.sweeps.batch import Chunk, empty_chunk, solve_chunk
from symkin.sweeps.result import SweepResult

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]

# Below this many time points in all (sets x grid points, about 0.1 s of C), processes would
# cost more to start than they save: workers=None then solves in this process.
MIN_PARALLEL_POINTS = 200_000
CHUNKS_PER_WORKER = 4
CHUNK_SECONDS = 0.05


def sweep(kernel: Kernel, params: Mapping[str, ArrayLike] | ArrayLike,
          t: ArrayLike | None = None, *, client: Any = None, workers: int | None = None,
          q0: ArrayLike | None = None, options: Options | None = None,
          progress: Progress | None = None) -> SweepResult:
    """Solve M parameter sets over one time grid.

    Args:
        kernel: a compiled kernel (``symkin.compile``); C solves each chunk in one call.
        params: an array (M, NP) in ``kernel.parameter_names`` order, or
            ``{name: array (M,)}`` (the other parameters nominal).
        t: the times, increasing; default: the file's grid.
        client: a ``dask.distributed.Client``: chunks run on its cluster.
        workers: local processes; default: the cores, but in this process when the sweep is
            too small for processes to pay (below MIN_PARALLEL_POINTS points); 1: here.
        q0: the first guess at t[0], one (N,) for all sets or one per set (M, N); default:
            the file's q0.
        options: Newton tolerances; default: suited to the kernel's real type.
        progress: called as progress(sets done, M).

    Returns:
        A SweepResult; ``status`` 0 marks the sets solved over the whole grid.

    Raises:
        SolveError: params, t or q0 that do not fit the mechanism.
    """
    refuse_motion(kernel, "symkin sweep")
    refuse_inputs(kernel, "a sweep")
    values = parameter_table(kernel, params)
    times = driver.time_points(kernel, t)
    problem = too_large(values.shape[0], times.size, len(kernel.coordinates))
    if problem:
        raise SolveError(problem)
    starts = _starts(kernel, q0, values.shape[0])
    m = values.shape[0]
    count = _workers(workers, m * times.size) if client is None else 0
    if m == 0:
        chunks = [empty_chunk(0, times, len(kernel.coordinates))]
    elif client is not None:
        parts = parallel.split(m, _cluster_size(client) * CHUNKS_PER_WORKER)
        chunks = parallel.on_dask(client, parallel.payload(kernel), values, times, starts,
                                  options, parts, progress)
    elif count > 1:
        parts = parallel.split(m, count * CHUNKS_PER_WORKER)
        chunks = parallel.in_processes(parallel.payload(kernel), values, times, starts,
                                       options, count, parts, progress)
    else:
        chunks = _here(kernel, values, times, starts, options, progress)
    return _result(kernel, times, values, _join(chunks))


def parameter_table(kernel: Kernel, params: Mapping[str, ArrayLike] | ArrayLike) -> Array:
    """params as an (M, NP) array in the kernel's parameter order (checked)."""
    names = list(kernel.parameter_names)
    if isinstance(params, Mapping):
        unknown = [n for n in params if n not in names]
        if unknown:
            raise SolveError(f"unknown parameter {unknown[0]!r}; the mechanism has: "
                             f"{listed(names) or 'none'}")
        columns = {n: np.atleast_1d(np.asarray(v, dtype=float)) for n, v in params.items()}
        sizes = {c.shape for c in columns.values()}
        if len(sizes) != 1 or len(next(iter(sizes))) != 1:
            raise SolveError("every parameter of params needs a 1-D array of the same length "
                             f"(got shapes {sorted(sizes)})")
        m = next(iter(columns.values())).size
        table = np.tile(kernel.p_values, (m, 1))
        for n, column in columns.items():
            table[:, names.index(n)] = column
        return table
    table = np.asarray(params, dtype=float)
    if table.ndim != 2 or table.shape[1] != len(names):
        raise SolveError(f"params must have shape (M, {len(names)}) in the order "
                         f"{listed(names) or '(none)'}, got {table.shape}")
    return np.ascontiguousarray(table)


def too_large(m: int, steps: int, size: int) -> str | None:
    """Why a sweep of m sets over ``steps`` time points is refused, or None: its results are
    bounded like one run's grid (limits.MAX_GRID_POINTS time points in all)."""
    if m * steps <= limits.MAX_GRID_POINTS:
        return None
    need = limits.result_bytes(m * steps, size) / 1e9
    return (f"the sweep has {m} sets x {steps} time points = {m * steps:.3g} points in all, "
            f"more than the {limits.MAX_GRID_POINTS:,} allowed (its results would need "
            f"{need:.3g} GB); sweep fewer sets at a time, or use a coarser time grid")


def _starts(kernel: Kernel, q0: ArrayLike | None, m: int) -> Array:
    size = len(kernel.coordinates)
    starts = np.asarray(kernel.q0 if q0 is None else q0, dtype=float)
    if starts.shape not in ((size,), (m, size)):
        raise SolveError(f"q0 must have shape ({size},) or ({m}, {size}), got {starts.shape}")
    return np.ascontiguousarray(starts)


def _workers(workers: int | None, points: int) -> int:
    if workers is not None:
        if workers < 1:
            raise SolveError(f"workers must be at least 1, got {workers}")
        return workers
    cores = os.cpu_count() or 1
    return cores if points >= MIN_PARALLEL_POINTS else 1


def _cluster_size(client: Any) -> int:
    try:
        return max(1, int(sum(client.nthreads().values())))
    except Exception:  # a client that cannot say: a few chunks still balance the load
        return 4


def _here(kernel: Kernel, values: Array, times: Array, starts: Array, options: Options | None,
          progress: Progress | None) -> list[Chunk]:
    """This process, in calls of about CHUNK_SECONDS each written straight into one result:
    Ctrl-C (seen between calls) and progress reports answer quickly, and no copying."""
    m = values.shape[0]
    full = empty_chunk(m, times, len(kernel.coordinates))
    # The first call: about 20000 time points (a few ms); then scaled to the time it took.
    size, start = max(1, min(m, 20_000 // times.size)), 0
    while start < m:
        part = slice(start, min(m, start + size))
        began = time.perf_counter()
        solve_chunk(kernel, values[part], times, starts[part] if starts.ndim == 2 else starts,
                    options, into=full.rows(part))
        took = time.perf_counter() - began
        size = int(max(1, size * min(4.0, CHUNK_SECONDS / took if took > 0 else 4.0)))
        start = part.stop
        if progress is not None:
            progress(start, m)
    return [full]


def _join(chunks: list[Chunk]) -> Chunk:
    if len(chunks) == 1:
        return chunks[0]
    arrays = {name: np.concatenate([getattr(c, name) for c in chunks])
              for name in ("q", "dq", "d2q", "status", "solved", "t_reached", "iterations")}
    return Chunk(**arrays, reasons=np.concatenate([c.reasons for c in chunks]),
                 messages=np.concatenate([c.messages for c in chunks]))


def _result(kernel: Kernel, times: Array, values: Array, chunk: Chunk) -> SweepResult:
    return SweepResult(
        t=times, q=chunk.q, dq=chunk.dq, d2q=chunk.d2q, status=chunk.status, params=values,
        parameter_names=tuple(kernel.parameter_names), coordinates=tuple(kernel.coordinates),
        reasons=tuple(chunk.reasons), messages=tuple(chunk.messages),
        t_reached=chunk.t_reached, solved=chunk.solved, iterations=chunk.iterations,
        points_named=tuple(kernel.points), local_vectors=kernel.point_vectors,
        removed=kernel.removed, removed_broken=_removed_broken(kernel, times, values, chunk),
        multipliers_grid=forces.grid(kernel) if kernel.has_dynamics else None,
        driver_names=kernel.driver_names, joint_names=kernel.joint_names,
        space=getattr(kernel, "space", "2d"))


def _removed_broken(kernel: Kernel, times: Array, values: Array, chunk: Chunk
                    ) -> NDArray[np.bool_] | None:
    """Per set, whether a row removed as redundant at t0 misses the position target somewhere
    on the rows solved (the check symkin.solve makes; None without removed rows)."""
    if not kernel.removed:
        return None
    target = driver.default_options(kernel).target_q
    broken = np.zeros(values.shape[0], dtype=bool)
    for m, p in enumerate(values):
        q = chunk.q[m, :int(chunk.solved[m])]
        residual = np.array([kernel.removed_phi(row, float(t), p) for t, row in zip(times, q)])
        broken[m] = bool(redundant.exceeded(residual.reshape(q.shape[0], -1), q, target).any())
    return broken
