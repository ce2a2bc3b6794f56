"""Stage 6 — driver: position, velocity and acceleration analysis over a time grid.

The chapter's algorithm (Example 2.6, section 2.7) on any compiled kernel:

    q   = q + dq h + ddq h^2 / 2                 Taylor predictor                (2.76)
    Newton-Raphson on Phi(q, t) = 0              test the residual of the iterate (2.72)
    Phi_q dq  = -Phi_t                           velocity                         (2.73)
    Phi_q ddq = Gamma                            acceleration                     (2.74)

One LU factorization (partial pivoting) of the converged Phi_q serves both linear solves, and
the condition estimate of each point (runtime.accuracy) that decides whether it is flagged.
The first point is assembled from the file's q0, which may be poor (the chapter starts from
q = 0): plain Newton first, then damped Newton from several starts (runtime.assembly). Where
several assemblies exist, the one reached from q0 is taken. A grid point the plain step cannot
solve goes to runtime.edges: a too-large step is subdivided, a singular configuration is
passed on the predicted branch, a limit position is bisected and reported.

With a C kernel that carries the generated solver, the grid loop runs in C: one call per
trajectory. Imports NumPy and SciPy only: it is part of the runtime.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin import limits
from symkin.errors import SolveError
from symkin.runtime import failures
from symkin.runtime.assembly import Assembly, assemble
from symkin.runtime.csolver import GridSolver
from symkin.runtime.edges import Passage, Resolution, State, resolve
from symkin.runtime.linalg import factor_at
from symkin.runtime.newton import Newton, Point, kinematics, newton
from symkin.runtime.options import NOT_FINITE, OK, SINGULAR, Options
from symkin.runtime.options import defaults as newton_defaults
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.results import Trajectory

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]

class SolveInterrupted(SolveError):
    """The solve was interrupted (SIGINT, Ctrl-C); carries the rows solved before it.

    Attributes:
        trajectory: the time points solved before the interrupt.
        t: the first time point not solved.
    """

    def __init__(self, trajectory: Trajectory, t: float) -> None:
        super().__init__(f"interrupted at t = {t:g} after {trajectory.t.size} time points")
        self.trajectory = trajectory
        self.t = t


class SolveFailure(SolveError):
    """A solve stopped early; carries what is needed to act on it and the rows solved so far.

    Attributes:
        trajectory: the time points solved before the failure.
        t: the time at which it failed.
        residual: max |Phi| of the last iterate.
        iterations: Newton iterations spent at t.
        rows: labels of the dependent equations when Phi_q was singular, else ().
        reason: "singular", "no convergence", "no assembly", "not finite" or
            "limit position".
        reached: where the step subdivision stopped (the limit time of a limit position: the
            last time solved, bisected to within about 1e-9 of the grid step), else NaN.
        aligned, drivers: at a limit position, the joints that become aligned and the drivers
            that cannot be followed beyond it; else ().
    """

    def __init__(self, message: str, trajectory: Trajectory, t: float, residual: float,
                 iterations: int, rows: Sequence[str] = (), reason: str = "",
                 reached: float = math.nan, aligned: Sequence[str] = (),
                 drivers: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.trajectory = trajectory
        self.t = t
        self.residual = residual
        self.iterations = iterations
        self.rows = tuple(rows)
        self.reason = reason
        self.reached = reached
        self.aligned = tuple(aligned)
        self.drivers = tuple(drivers)


# ----- the time grid -------------------------------------------------------------------------

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
    """The times to solve at: the file's grid (t None), or t checked (finite, increasing)."""
    if t is None:
        return grid(*kernel.time_grid)
    times = np.atleast_1d(np.asarray(t, dtype=float))
    if times.ndim != 1 or times.size == 0 or not math.isfinite(times[0] + times[-1]):
        raise SolveError("t must be a non-empty 1-D sequence of finite times")
    # Strictly increasing steps between finite ends: then every time is finite (a NaN fails
    # the comparison). One pass, where diff and isfinite would take three.
    if times.size > 1 and not bool((times[1:] > times[:-1]).all()):
        if not np.all(np.isfinite(times)):
            raise SolveError("t must be a non-empty 1-D sequence of finite times")
        raise SolveError("t must be strictly increasing")
    return times


def parameter_values(kernel: KinematicsKernel,
                     params: Mapping[str, float] | ArrayLike | None) -> Array:
    """Nominal parameter values, overridden by name (a mapping) or replaced (a sequence)."""
    values = np.array(kernel.p_values, dtype=float)
    if params is None:
        return values
    if isinstance(params, Mapping):
        names = list(kernel.parameter_names)
        for name, value in params.items():
            if name not in names:
                known = ", ".join(names) or "none"
                raise SolveError(f"unknown parameter {name!r}; the mechanism has: {known}")
            values[names.index(name)] = float(value)
        return values
    given = np.asarray(params, dtype=float)
    if given.shape != values.shape:
        raise SolveError(f"params has {given.size} values; the mechanism has {values.size}")
    return given


# ----- the time loop -------------------------------------------------------------------------

@dataclass
class _Run:
    """Arrays filled point by point; ``done`` points are valid."""

    t: Array
    q: Array
    dq: Array
    d2q: Array
    cond: Array
    flagged: NDArray[np.bool_]
    done: int = 0
    fallbacks: int = 0  # the generated sparse LU's fall-backs to dense LU (C solver)
    passages: list[Passage] = field(default_factory=list)

    def store(self, k: int, point: Point) -> None:
        self.q[k], self.dq[k], self.d2q[k] = point.q, point.dq, point.ddq
        self.cond[k], self.flagged[k] = point.cond, point.flagged
        self.done = k + 1

    def state(self, k: int) -> State:
        """Point k as the predictor's state."""
        return State(float(self.t[k]), Point(self.q[k], self.dq[k], self.d2q[k],
                                             float(self.cond[k]), bool(self.flagged[k])))


def _python_loop(kernel: KinematicsKernel, run: _Run, q: Array, p: Array, options: Options,
                 progress: Progress | None) -> Newton:
    """The grid loop in Python from point run.done (q: the first guess when it is the first
    point); returns the Newton outcome at the last point attempted."""
    result = Newton(q, OK, 0, 0.0, None)
    for k in range(run.done, run.t.size):
        t = float(run.t[k])
        if k > 0:
            h = t - run.t[k - 1]
            q = run.q[k - 1] + run.dq[k - 1] * h + run.d2q[k - 1] * (h * h / 2)  # (2.76)
        result = newton(kernel, q, t, p, options)
        if result.status != OK:
            return result
        point = kinematics(kernel, result, t, p, options)
        if point is None:
            return Newton(result.q, NOT_FINITE, result.iterations, result.residual, None)
        run.store(k, point)
        if progress is not None:
            progress(k + 1, run.t.size)
    return result


def default_options(kernel: KinematicsKernel) -> Options:
    """Options() for double precision; looser ones for a C kernel computing in float."""
    return newton_defaults(getattr(kernel, "real", "double"))


class _Chunks:
    """How many grid points one call of the C grid loop solves: about CHUNK_SECONDS of work,
    so that Ctrl-C (handled between calls) and progress reports answer quickly, while the
    Python between calls stays negligible."""

    CHUNK_SECONDS = 0.05

    def __init__(self, total: int, reporting: bool) -> None:
        self.limit = max(1, total // 100) if reporting else total
        self.size = min(256, self.limit)

    def took(self, seconds: float) -> None:
        """Scale the next chunk to the time this one took (at most 4x larger at once)."""
        grow = 4.0 if seconds <= 0 else min(4.0, self.CHUNK_SECONDS / seconds)
        self.size = int(min(self.limit, max(1, self.size * grow)))


def _c_loop(kernel: KinematicsKernel, run: _Run, solver: GridSolver, p: Array,
            progress: Progress | None) -> Newton:
    """The grid loop in the generated C solver from point run.done: one call per chunk (one
    chunk unless a progress callback wants to hear in between)."""
    chunks = _Chunks(run.t.size, progress is not None)
    result = None
    start = run.done
    while start < run.t.size:
        stop = min(start + chunks.size, run.t.size)
        began = time.perf_counter()
        result = solver.solve(run.t[start:stop], run.q[start:stop], run.dq[start:stop],
                              run.d2q[start:stop], run.cond[start:stop],
                              run.flagged[start:stop])
        chunks.took(time.perf_counter() - began)
        run.done = start + result.solved
        run.fallbacks = result.fallbacks
        if result.status != OK:
            last = solver.last_q()
            factors = factor_at(kernel, last, result.t, p) if result.status == SINGULAR \
                else None
            return Newton(last, result.status, result.iterations, result.residual, factors)
        if progress is not None:
            progress(run.done, run.t.size)
        start = stop
    # The last row written is the solver's q: no need to read it back from C.
    q = run.q[run.done - 1] if run.done else solver.last_q()
    return Newton(q, OK, 0 if result is None else result.iterations,
                  0.0 if result is None else result.residual, None)


def solve(kernel: KinematicsKernel, t: ArrayLike | None = None, q0: ArrayLike | None = None,
          params: Mapping[str, float] | ArrayLike | None = None, *,
          options: Options | None = None, progress: Progress | None = None,
          use_c_solver: bool = True, stop_at_singular: bool = False,
          sensitivities: bool = False) -> Trajectory:
    """Positions, velocities and accelerations of a mechanism over a time grid.

    Args:
        kernel: a compiled kernel (``symkin.compile``), NumPy or C.
        t: the times to solve at, increasing; default: the file's grid t0 + k dt, t1 included.
        q0: the first guess at t[0]; default: the file's q0.
        params: parameter values by name (a mapping, others nominal) or all of them in order.
        options: Newton tolerances and the singularity threshold; default: suited to the
            kernel's real type (looser for a C kernel generated with float).
        progress: called as progress(done, total) while the grid is solved.
        use_c_solver: run the grid loop in the generated C solver when the kernel has one.
        stop_at_singular: stop at the first singular point (SolveFailure) instead of passing
            through it, and do not subdivide a step that fails (the behaviour of old).
        sensitivities: also compute ``q_p`` = dq/dp (T, N, NP) from Phi_q q_p = -Phi_p.

    Returns:
        The Trajectory.

    Raises:
        SolveFailure (a SolveError) with the partial trajectory when the mechanism cannot be
        assembled at t[0], Newton does not converge, or Phi_q is singular.
    """
    # An expression singular at some t gives inf/NaN there; that is reported as a failure
    # (status NOT_FINITE), so NumPy's floating-point warnings would only repeat it.
    options = options or default_options(kernel)
    if stop_at_singular:
        options = dataclasses.replace(options, stop_at_singular=True)
    with np.errstate(all="ignore"):
        trajectory = _solve(kernel, t, q0, params, options, progress, use_c_solver)
    if sensitivities:
        from symkin.runtime.sensitivity import with_sensitivities

        return with_sensitivities(kernel, trajectory)
    return trajectory


def _solve(kernel: KinematicsKernel, t: ArrayLike | None, q0: ArrayLike | None,
           params: Mapping[str, float] | ArrayLike | None, options: Options,
           progress: Progress | None, use_c_solver: bool) -> Trajectory:
    times = time_points(kernel, t)
    p = parameter_values(kernel, params)
    q = np.array(kernel.q0 if q0 is None else q0, dtype=float)
    if q.shape != (len(kernel.coordinates),):
        raise SolveError(f"q0 has {q.size} values; the mechanism has "
                         f"{len(kernel.coordinates)} coordinates")
    shape = (times.size, q.size)
    # Rows past run.done are never exposed, so the arrays need no zero-filling.
    run = _Run(times, np.empty(shape), np.empty(shape), np.empty(shape),
               np.full(times.size, math.nan), np.zeros(times.size, dtype=bool))
    in_c = use_c_solver and kernel.has_grid_solver
    try:
        result = _run(kernel, run, q, p, options, progress, in_c)
    except KeyboardInterrupt:
        # The rows done so far are whole (run.done counts only finished rows): hand them on.
        stop = float(times[min(run.done, times.size - 1)])
        raise SolveInterrupted(_trajectory(kernel, run, p), stop) from None
    if isinstance(result, Resolution):
        _fail_edge(kernel, run, p, result, float(times[run.done]))
    elif result.status != OK:
        _fail(kernel, run, p, result, float(times[run.done]), assembling=run.done == 0)
    return _trajectory(kernel, run, p)


def _run(kernel: KinematicsKernel, run: _Run, q: Array, p: Array, options: Options,
         progress: Progress | None, in_c: bool) -> Newton | Resolution:
    """Assemble at t[0], then solve the grid; a point the plain step cannot solve goes to
    edges.resolve and the loop resumes after it. Returns the outcome that stopped the run
    (status OK when the grid is done)."""
    solver = kernel.grid_solver(options, q, p) if in_c else None
    try:
        return _grid(kernel, run, solver, q, p, options, progress)
    finally:
        if solver is not None:
            solver.release()  # back to the kernel's pool for the next run


def _grid(kernel: KinematicsKernel, run: _Run, solver: GridSolver | None, q: Array, p: Array,
          options: Options, progress: Progress | None) -> Newton | Resolution:
    # The C solver assembles t[0] itself by plain Newton from q0; only when that fails does
    # the damped assembly in Python take over (and the grid is run again from its result).
    result = _c_loop(kernel, run, solver, p, progress) if solver is not None else None
    if result is None or (result.status != OK and run.done == 0):
        assembly = assemble(kernel, q, float(run.t[0]), p, options)
        start = assembly.result
        if start.status != OK:
            _fail(kernel, run, p, start, float(run.t[0]), assembling=True, assembly=assembly)
        if solver is not None:
            solver.start(options, start.q, p)
        result = _resume(kernel, run, solver, start.q, p, options, progress)
    while result.status not in (OK, NOT_FINITE) and run.done > 0 \
            and not options.stop_at_singular:
        k = run.done
        resolution = resolve(kernel, p, options, run.state(k - 1), float(run.t[k]))
        if resolution.passage is not None:
            run.passages.append(resolution.passage)
        if resolution.point is None:
            return resolution
        run.store(k, resolution.point)
        if solver is not None:
            solver.set_state(float(run.t[k]), run.q[k], run.dq[k], run.d2q[k])
        if progress is not None:
            progress(run.done, run.t.size)
        result = _resume(kernel, run, solver, resolution.point.q, p, options, progress)
    return result


def _resume(kernel: KinematicsKernel, run: _Run, solver: GridSolver | None, q: Array, p: Array,
            options: Options, progress: Progress | None) -> Newton:
    if solver is not None:
        return _c_loop(kernel, run, solver, p, progress)
    return _python_loop(kernel, run, q, p, options, progress)


def _trajectory(kernel: KinematicsKernel, run: _Run, p: Array) -> Trajectory:
    done = run.done

    def solved(a: Array) -> Array:  # the run's own arrays (never the caller's): no copy
        return a if done == a.shape[0] else a[:done].copy()

    return Trajectory(t=run.t[:done].copy(), q=solved(run.q), dq=solved(run.dq),
                      d2q=solved(run.d2q), coordinates=tuple(kernel.coordinates),
                      points=tuple(kernel.points),
                      point_vectors=np.asarray(kernel.point_vectors(p), dtype=float).reshape(-1, 2),
                      params=p.copy(), lu_fallbacks=run.fallbacks,
                      flagged=run.flagged[:done].copy(), cond=run.cond[:done].copy(),
                      singular=tuple((s.t, s.rank_loss, tuple(map(tuple, s.groups)))
                                     for s in run.passages))


def _fail(kernel: KinematicsKernel, run: _Run, p: Array, result: Newton, t: float,
          assembling: bool, assembly: Assembly | None = None) -> None:
    """Raise SolveFailure with a message that says where, why and what to try."""
    last = None if run.done == 0 else (float(run.t[run.done - 1]), run.q[run.done - 1])
    message, reason, rows = failures.explain(kernel, p, result, t, assembling, assembly, last)
    raise SolveFailure(message, _trajectory(kernel, run, p), t, result.residual,
                       result.iterations, rows, reason)


def _fail_edge(kernel: KinematicsKernel, run: _Run, p: Array, stop: Resolution,
               t: float) -> None:
    """Raise SolveFailure for a grid point that could not be reached even by substeps."""
    message, reason = failures.explain_stop(stop, t)
    reached = math.nan if stop.reached is None else stop.reached.t
    raise SolveFailure(message, _trajectory(kernel, run, p), t, math.nan, 0,
                       [row for group in stop.groups for row in group], reason, reached,
                       stop.aligned, stop.drivers)
