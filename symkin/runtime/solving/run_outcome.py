"""What a run hands back or raises: the Trajectory of the rows it solved (with their efforts
and reactions), and SolveInterrupted and SolveFailure, which carry those rows. Shared by the
loop over a time grid (runtime.driver) and the loop over input rows
(runtime.input_driven.input_runs). Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.errors import SolveError
from symkin.runtime.loads import forces
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving import failures
from symkin.runtime.solving.assembly import Assembly, reversed_senses
from symkin.runtime.solving.newton import Newton
from symkin.runtime.solving.result_arrays import Run as _Run

Array = NDArray[np.float64]


class SolveInterrupted(SolveError):
    """The solve was interrupted (SIGINT, Ctrl-C); carries the rows solved before it.

    Attributes:
        trajectory: the time points solved before the interrupt.
        t: the first time point not solved (the last one when all were).
        during: the work after the loop that was interrupted ("" within the loop): every
            time point was solved, what ``during`` would have added is missing.
    """

    def __init__(self, trajectory: Trajectory, t: float, during: str = "") -> None:
        where = f"while {during}, " if during else f"at t = {t:g} "
        super().__init__(f"interrupted {where}after {trajectory.t.size} time points")
        self.trajectory = trajectory
        self.t = t
        self.during = during


class SolveFailure(SolveError):
    """A solve stopped early; carries what is needed to act on it and the rows solved so far.

    Attributes:
        trajectory: the time points solved before the failure.
        t: the time at which it failed.
        residual: max |Phi| of the last iterate.
        iterations: Newton iterations spent at t.
        rows: labels of the dependent equations when Phi_q was singular, else ().
        reason: "singular", "no convergence", "no assembly", "not finite" or
            "limit position", "too many substeps" (the bound on one grid point's substeps,
            contract.tuning.EDGE_SUBSTEPS).
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


def _trajectory(kernel: KinematicsKernel, run: _Run, p: Array,
                point_vectors: Array | None = None, loads_p: Array | None = None) -> Trajectory:
    """The Trajectory of the rows done, over the run's own arrays (p: owned by the run).
    A run of a kernel with input drivers has efforts and reactions only given ``loads_p``,
    each row's p[] with its inputs (T, NP + 3 NU); elsewhere they are not computed."""
    done = run.done
    arrays: tuple[NDArray[Any], ...] = (run.t, run.q, run.dq, run.d2q, run.flagged, run.cond)
    if done < run.t.size:  # a partial result: the caller's rows viewed, the run's copied
        arrays = tuple(a[:done] if run.caller_owned else a[:done].copy() for a in arrays)
    t, q, dq, d2q, flagged, cond = arrays
    if point_vectors is None:
        point_vectors = np.asarray(kernel.point_vectors(p), dtype=float).reshape(
            -1, _point_size(kernel))
    singular = tuple((s.t, s.rank_loss, tuple(map(tuple, s.groups)))
                     for s in run.passages) if run.passages else ()
    trajectory = Trajectory.solved(t, q, dq, d2q, tuple(kernel.coordinates),
                                   tuple(kernel.points), point_vectors, p, run.fallbacks,
                                   flagged, cond, singular, space=_space(kernel))
    # inverse dynamics (a kernel with masses or forces): efforts and reactions of the rows
    given = None if run.forces_out is None else tuple(a[:done] for a in run.forces_out)
    if getattr(kernel, "nu", 0):
        attach_forces(trajectory, lambda: None if loads_p is None else
                      forces.compute(kernel, t, q, dq, d2q, loads_p))
    else:
        attach_forces(trajectory, lambda: forces.compute(kernel, t, q, dq, d2q, p, given))
    return trajectory


@contextmanager
def rows_kept(trajectory: Trajectory, during: str) -> Iterator[None]:
    """Work after the loop on rows all solved (efforts, removed rows, ranges): a Ctrl-C in
    it hands on ``trajectory`` (SolveInterrupted, ``during`` saying what was cut short), so
    that the rows solved are written as after an interrupt in the loop, never lost to a bare
    KeyboardInterrupt."""
    try:
        yield
    except KeyboardInterrupt:
        last = float(trajectory.t[-1]) if trajectory.t.size else math.nan
        raise SolveInterrupted(trajectory, last, during) from None


def attach_forces(trajectory: Trajectory, compute: Callable[[], forces.Forces | None]) -> None:
    """The efforts and reactions ``compute()`` gives, on the trajectory, their non-finite
    rows flagged; none (and SolveInterrupted) where a Ctrl-C cuts their computation short."""
    trajectory.__dict__["forces"] = None
    with rows_kept(trajectory, "the efforts and reactions were computed"):
        trajectory.__dict__["forces"] = compute()
    flag_not_finite(trajectory)


def flag_not_finite(trajectory: Trajectory) -> None:
    """Rows whose efforts or reactions are inf or NaN are flagged (never a silent number)."""
    found = trajectory.forces
    if found is not None and trajectory.t.size:
        bad = found.not_finite()
        if bad.any():
            trajectory.flagged[bad] = True


def _space(kernel: KinematicsKernel) -> str:
    """``3d`` for a spatial kernel (a stand-in kernel without the attribute is planar)."""
    return str(getattr(kernel, "space", "2d"))


def _point_size(kernel: KinematicsKernel) -> int:
    return 3 if _space(kernel) == "3d" else 2


def refuse_reversed(kernel: KinematicsKernel, run: _Run, q: Array, t: float, p: Array,
                    params: Array | None = None) -> None:
    """Raise SolveFailure (reason "no assembly", no row kept) when q, a solution of Phi = 0
    at the first time point t, has a sense of the kernel not positive (runtime.solving.assembly): a
    spatial revolute's axes reversed, an angle driver half a turn away. Every run checks its
    first row so (p: the kernel's p[] at t; params: the parameters, when p holds inputs)."""
    wrong = reversed_senses(kernel, q, t, p)
    if not wrong:
        return
    run.done = 0  # a solution of Phi = 0 that is no assembly: no row of it is kept
    raise SolveFailure(failures.explain_reversed(wrong, t),
                       _trajectory(kernel, run, p if params is None else params), t,
                       math.nan, 0, wrong, "no assembly")


def _fail(kernel: KinematicsKernel, run: _Run, p: Array, result: Newton, t: float,
          assembling: bool, assembly: Assembly | None = None,
          params: Array | None = None) -> None:
    """Raise SolveFailure with a message that says where, why and what to try (p: the
    kernel's p[] at t; params: the parameters, when p also holds inputs)."""
    last = None if run.done == 0 else (float(run.t[run.done - 1]), run.q[run.done - 1])
    message, reason, rows = failures.explain(kernel, p, result, t, assembling, assembly, last)
    params = p if params is None else params
    raise SolveFailure(message, _trajectory(kernel, run, params), t, result.residual,
                       result.iterations, rows, reason)
