"""The grid points where the plain step fails: a step too large, a singular configuration the
motion passes through, or a limit position the driven motion cannot pass.

At such a point the step from the last solved point is subdivided (halved on failure, doubled
on success; the chapter allows a variable step h_i) until it reaches the point or the failing
step is below ``h_min``. Then:

- reached: the step was only too large; the point is solved as any other.
- blocked at t_b, but a step over t_b (from t_b - delta to t_b + delta) converges: the motion
  passes through a singular configuration at t_b on the branch the predictor follows. A grid
  point within that step gets q, dq, ddq from the quintic Hermite interpolant of the two
  solved points on either side (accurate to O(delta^4) in ddq), its position then corrected
  once in the minimum-norm least-squares sense, and it is flagged.
- blocked and no step over it converges: a limit position when Phi_q becomes singular as
  t_b is approached (its condition grows without bound), else a plain failure to converge.

Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.contract.status import OK
from symkin.contract.tuning import EDGE_SUBSTEPS
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving.linalg import dependencies
from symkin.runtime.solving.newton import Point, kinematics, newton

Array = NDArray[np.float64]

DELTA_FRACTION = 1.0 / 64
"""The step over a singular configuration spans 2 delta, delta = this times the grid step."""

LIMIT_COND = 1e5
"""A failure where Phi_q's condition at the last point reached exceeds this (or a tenth of
options.max_cond, if lower) is a limit position (sigma_min -> 0 as t_b is approached), not a
Newton failure."""

LIMIT_GROWTH = 100.0
"""... and so is one where the condition grew by this factor between the last grid point and
the last point the substeps reached. At a fold sigma_min shrinks like the square root of the
distance to it, so substeps that close in by 1e9 raise the condition some 3e4-fold even where
the mechanism is not badly conditioned in absolute terms; a failure for another reason (a
driver that is not smooth) shows no such growth."""


@dataclass
class State:
    """A solved point (the predictor's state)."""

    t: float
    point: Point


@dataclass
class Passage:
    """A singular configuration passed through near t, and what was singular there."""

    t: float
    rank_loss: int
    groups: list[list[str]]


@dataclass
class Resolution:
    """What happened at a grid point the plain step could not solve.

    point: the solved point (None when the motion stops); passage: a singular configuration
    passed on the way; limit: True when the stop is a limit position; reached, failed_at:
    the last time solved and the first that failed; groups: the dependent rows there.
    """

    point: Point | None
    passage: Passage | None = None
    limit: bool = False
    reached: State | None = None
    failed_at: float = math.nan
    groups: tuple[tuple[str, ...], ...] = ()
    aligned: tuple[str, ...] = ()
    drivers: tuple[str, ...] = ()
    substeps: int = 0
    """Substeps taken; EDGE_SUBSTEPS when the bound on them stopped the motion."""


@dataclass
class Work:
    """The substeps one grid point's edge treatment has left (contract.tuning.EDGE_SUBSTEPS)."""

    left: int = EDGE_SUBSTEPS

    @property
    def spent(self) -> bool:
        return self.left <= 0

    @property
    def taken(self) -> int:
        return EDGE_SUBSTEPS - self.left


def _step(kernel: KinematicsKernel, p: Array, options: Options, state: State, t: float
          ) -> State | None:
    """Predict from state (2.76), Newton at t, velocities and accelerations; None on failure."""
    h = t - state.t
    point = state.point
    guess = point.q + point.dq * h + point.ddq * (h * h / 2)
    result = newton(kernel, guess, t, p, options)
    if result.status != OK:
        return None
    solved = kinematics(kernel, result, t, p, options)
    return None if solved is None else State(t, solved)


def march(kernel: KinematicsKernel, p: Array, options: Options, state: State, target: float,
          h0: float, h_min: float, work: Work | None = None) -> tuple[State, float]:
    """Advance from state to target by substeps; returns the last state reached and the step
    that failed from it (0 when target was reached). Each substep spends one of ``work``'s:
    when none is left the next step counts as failed (``work.spent`` tells the two apart)."""
    work = Work() if work is None else work
    h = h0
    while state.t < target:
        step = min(h, target - state.t)
        if work.spent:
            return state, step
        work.left -= 1
        following = _step(kernel, p, options, state, target if step == target - state.t
                          else state.t + step)
        if following is None:
            if step <= h_min:
                return state, step
            h = step / 2
        else:
            state, h = following, min(2 * step, h0)
    return state, 0.0


def hermite(a: State, b: State, t: float) -> tuple[Array, Array, Array]:
    """q, dq, ddq at t from the quintic Hermite interpolant of q, dq, ddq at a.t and b.t."""
    mid, half = (a.t + b.t) / 2, (b.t - a.t) / 2
    s = (t - mid) / half

    def rows(x: float) -> list[list[float]]:
        value = [x**k for k in range(6)]
        first = [k * x ** (k - 1) if k else 0.0 for k in range(6)]
        second = [k * (k - 1) * x ** (k - 2) if k > 1 else 0.0 for k in range(6)]
        return [value, first, second]

    matrix = np.array(rows(-1.0) + rows(1.0))
    scale = np.array([1.0, half, half * half])
    data = np.vstack([np.vstack([a.point.q, a.point.dq, a.point.ddq]) * scale[:, None],
                      np.vstack([b.point.q, b.point.dq, b.point.ddq]) * scale[:, None]])
    coefficients = np.linalg.solve(matrix, data)
    at = np.array(rows(s)) @ coefficients
    return at[0], at[1] / half, at[2] / (half * half)


def _through(kernel: KinematicsKernel, p: Array, options: Options, before: State,
             after: State, t: float) -> Point:
    """The flagged point at t between the two sides of a singular configuration."""
    q, dq, ddq = hermite(before, after, t)
    jacobian = kernel.phi_q(q, t, p)
    q = q + _minimum_norm_correction(jacobian, kernel.phi(q, t, p))
    cond = float(np.linalg.cond(jacobian, 1)) if np.all(np.isfinite(jacobian)) else math.inf
    return Point(q, dq, ddq, cond, True)


def _minimum_norm_correction(jacobian: Array, phi: Array) -> Array:
    """The minimum-norm step against phi, the nearly singular directions cut off: it moves
    nothing along them. LAPACK's least-squares driver may fail to converge at an exactly
    singular Phi_q (the chain of parallelograms on a grid point at its change point) where
    the SVD converges; where both fail, no step (the point is flagged anyway)."""
    try:
        return np.asarray(np.linalg.pinv(jacobian, rcond=1e-6) @ -phi)
    except np.linalg.LinAlgError:
        return np.zeros_like(phi)


def substeps(previous: float, t: float) -> tuple[float, float, float]:
    """The first substep h0 from the last time solved to the failing grid point t, the least
    substep h_min (about 1e-9 of h0: the bisection's resolution) and the half-width delta of
    the step over a blocked time (also used by the generated C's ``<prefix>_solve_edge``)."""
    h0 = t - previous
    return h0, max(1e-9 * h0, 1e-13 * (1.0 + abs(t))), DELTA_FRACTION * h0


def resolve(kernel: KinematicsKernel, p: Array, options: Options, previous: State,
            t: float) -> Resolution:
    """Solve the grid point t that the plain step from ``previous`` could not."""
    h0, h_min, delta = substeps(previous.t, t)
    work = Work()
    state, failed = march(kernel, p, options, previous, t, h0, h_min, work)
    if not failed:
        return Resolution(state.point, substeps=work.taken)
    if work.spent:
        return _exhausted(state, failed)
    blocked = state.t + failed
    before, early = march(kernel, p, options, previous, blocked - delta, h0, h_min, work) \
        if blocked - delta > previous.t else (previous, 0.0)
    after = None if early else _over(kernel, p, options, before, blocked, delta, h0)
    if work.spent:
        return _exhausted(state, failed)
    if after is None:
        return _stopped(kernel, p, options, state, failed, previous)
    passage = _passage(kernel, p, before, after)
    if t <= after.t:
        return Resolution(_through(kernel, p, options, before, after, t), passage)
    rest, failed = march(kernel, p, options, after, t, h0, h_min, work)
    if work.spent:
        stop = _exhausted(rest, failed)
        stop.passage = passage
        return stop
    if failed:
        stop = _stopped(kernel, p, options, rest, failed, after)
        stop.passage = passage
        return stop
    return Resolution(rest.point, passage)


def _exhausted(state: State, failed: float) -> Resolution:
    """The stop of a grid point whose substeps used up the bound on them."""
    return Resolution(None, reached=state, failed_at=state.t + failed, substeps=EDGE_SUBSTEPS)


def _over(kernel: KinematicsKernel, p: Array, options: Options, before: State, blocked: float,
          delta: float, h0: float) -> State | None:
    """One step from before to past the blocked time: delta past it, or twice, four times ...
    as far (up to a grid step) when Phi_q is still too ill-conditioned there."""
    reach = delta
    while reach <= h0:
        after = _step(kernel, p, options, before, blocked + reach)
        if after is not None:
            return after
        reach *= 2
    return None


def _passage(kernel: KinematicsKernel, p: Array, before: State, after: State) -> Passage:
    """Where between the two sides Phi_q is most nearly singular (sigma_min / sigma_max
    minimised along the interpolated motion), and what is singular there."""
    from scipy.optimize import minimize_scalar

    def ratio(t: float) -> float:
        sigma = np.linalg.svd(kernel.phi_q(hermite(before, after, t)[0], t, p),
                              compute_uv=False)
        return float(sigma[-1] / sigma[0])

    found = minimize_scalar(ratio, bounds=(before.t, after.t), method="bounded",
                            options={"xatol": 1e-13 * (1.0 + abs(after.t))})
    t = float(found.x)
    q, _, _ = hermite(before, after, t)
    rank_loss, groups = dependencies(kernel.phi_q(q, t, p), list(kernel.rows), rcond=1e-7)
    return Passage(t, rank_loss, groups)


def _stopped(kernel: KinematicsKernel, p: Array, options: Options, state: State,
             failed: float, start: State) -> Resolution:
    """The motion cannot go on past state.t (reached by substeps from start): a limit
    position, or no convergence."""
    stop = stopped_at(kernel, p, options, state, failed, start.point.cond)
    if stop.limit:
        jacobian = kernel.phi_q(state.point.q, state.t, p)
        threshold = limit_threshold(options)
        _, found = dependencies(jacobian, list(kernel.rows), rcond=1.0 / threshold)
        stop.groups = tuple(tuple(group) for group in found)
    return stop


def limit_threshold(options: Options) -> float:
    """The condition above which a stop is a limit position (LIMIT_COND)."""
    return min(LIMIT_COND, options.max_cond / 10)


def stopped_at(kernel: KinematicsKernel, p: Array, options: Options, state: State,
               failed: float, start_cond: float, named: bool = True) -> Resolution:
    """The stop at state.t (a step of ``failed`` from it failed; start_cond: the condition at
    the grid point the substeps began from), told a limit position or no convergence, with
    the aligned joints and held drivers of a limit (not its dependent rows: ``_stopped``;
    ``named`` False: not those either, for a caller that names many stops at once with
    limit_motions)."""
    cond = state.point.cond
    limit = cond > limit_threshold(options) or cond > LIMIT_GROWTH * start_cond
    stop = Resolution(None, limit=limit, reached=state, failed_at=state.t + failed)
    if limit and named:
        stop.aligned, stop.drivers = limit_motion(kernel, kernel.phi_q(state.point.q, state.t,
                                                                        p))
    return stop


def limit_motion(kernel: KinematicsKernel, jacobian: Array
                 ) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The joints that become aligned at a limit position, and the drivers that hold.

    The right null vector of Phi_q is the motion the constraints allow with every driver held:
    the bodies it moves are the aligned links, and the joints on them are the aligned joints;
    the drivers are the rows that the dependent set holds besides."""
    return limit_motions(kernel, jacobian[None])[0]


def limit_motions(kernel: KinematicsKernel, jacobians: Array
                  ) -> list[tuple[tuple[str, ...], tuple[str, ...]]]:
    """limit_motion of each of the stacked Jacobians (k, N, N): one SVD call for all, and the
    names looked up once per distinct set of moving bodies."""
    _, _, vt = np.linalg.svd(jacobians)
    motions = np.abs(vt[:, -1])
    moving = motions > 1e-3 * motions.max(axis=1, keepdims=True)
    names = _names(tuple(kernel.coordinates), tuple(kernel.rows),
                   tuple(np.asarray(kernel.pattern_rows).tolist()),
                   tuple(np.asarray(kernel.pattern_cols).tolist()))
    return [names.aligned(tuple(np.flatnonzero(row).tolist())) for row in moving]


class _Names:
    """The joints on each set of bodies and the drivers of one mechanism (limit_motions)."""

    def __init__(self, coordinates: tuple[str, ...], rows: tuple[str, ...],
                 pattern: list[tuple[int, int]]) -> None:
        self.body = [name.rsplit(".", 1)[0] for name in coordinates]
        self.pattern = pattern
        self.rows = rows
        self.drivers = tuple(dict.fromkeys(label.rsplit(" (", 1)[0] for label in rows
                                           if label.startswith("drivers")))
        self.found: dict[tuple[int, ...], tuple[tuple[str, ...], tuple[str, ...]]] = {}

    def aligned(self, columns: tuple[int, ...]) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """The joints on the bodies of the moving columns, and the drivers."""
        if columns not in self.found:
            bodies = {self.body[c] for c in columns}
            rows = sorted({r for r, c in self.pattern if self.body[c] in bodies})
            labels = [self.rows[r].rsplit(" (", 1)[0] for r in rows]
            joints = tuple(dict.fromkeys(n for n in labels if n.startswith("joints")))
            self.found[columns] = (joints, self.drivers)
        return self.found[columns]


@functools.lru_cache(maxsize=64)
def _names(coordinates: tuple[str, ...], rows: tuple[str, ...], pattern_rows: tuple[int, ...],
           pattern_cols: tuple[int, ...]) -> _Names:
    """_Names once per mechanism: a sweep names every set that stops at a limit."""
    return _Names(coordinates, rows, list(zip(pattern_rows, pattern_cols)))
