"""A set the C batch stopped on, told apart without re-running it: a limit position.

The C batch reports where a set stopped (the grid index k of the first point its plain step
could not solve) and has written the rows before it. A per-set ``symkin.solve`` would go on
from the same rows (the same generated grid loop) into ``runtime.edges``, which subdivides the
step down to about 1e-9 of it: about 1,400 Newton iterations in Python, some 700 times the
cost of a solved set. When those rows already show a limit position, that re-run can only end
as ``symkin.solve`` ends it (reason "limit position" at the grid point t[k], the k rows), so
the set is finished here from two SVDs of Phi_q.

A limit position (a fold of the driven motion) is recognised by what the two last solved
points show, all of it required:

- the smallest singular value of Phi_q falls from t[k-2] to t[k-1], and at a fold it falls as
  the square root of the distance to it: sigma_min^2, extrapolated linearly, reaches zero
  after t[k-1] and before t[k] (within FOLD_MARGIN grid steps of it, a few substeps towards
  t[k] and the same extrapolation from the last of them decide: none may reach t[k]);
- the drivers take part in the dependency: the left singular vector of sigma_min puts at least
  DRIVER_SHARE of its weight on the driver rows. At a singular configuration the motion can
  pass through (a parallelogram's change point), the constraints without the drivers are
  dependent and the drivers take no part: such a set, and every set this test is not sure of,
  is re-run through ``symkin.solve`` as before.

The start is left to ``symkin.solve`` too when it is singular (runtime.start) or when the
mechanism is solved in another unit (runtime.units): the rows there are not the batch's.
Imports NumPy and the runtime only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.runtime import units
from symkin.runtime.edges import limit_motion
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.start import singular_start

Array = NDArray[np.float64]

DRIVER_SHARE = 0.02
"""The least weight (sum of squares, of 1) of the near-null left singular vector on the driver
rows for a stop to be a limit position (the crank-slider near its limit: 0.13); at a passable
singular configuration it tends to 0 (the parallelogram a grid step before it: 6e-4)."""

FOLD_MARGIN = 0.05
"""How far (in grid steps) before the failing point t[k] the extrapolated fold must lie. A fold
past t[k] is reached by ``symkin.solve``'s substeps, which then stop at a later grid point, so
a fold near t[k] is left to the re-run. The extrapolation from two points is off by 0.002 ..
0.02 of a grid step on the crank-slider's 31-point grid (0.2 .. 0.3 late on an 11-point grid,
0.01 early on a 151-point one). A fold extrapolated nearer t[k] than this is looked at closer
(_closer_fold_before)."""

CLOSER_STEPS = (1 / 16, 1 / 256, 1 / 4096)
"""The closer look's substeps go down to these fractions of the grid step in turn, the next
only while the fold is not yet placed."""

CLOSER_ITERATIONS = 8
"""Newton iterations per substep of the closer look: from the predictor a substep converges in
a few; one that fails only makes the look stop short, and the set is then re-run."""


@dataclass(frozen=True)
class Limit:
    """A set stopped by a limit position between t[k-1] and t[k]."""

    reason: str
    message: str
    t: float  # the grid point t[k], as symkin.solve reports it


def limit_stop(kernel: KinematicsKernel, p: Array, t: Array, rows: tuple[Array, Array, Array],
               solved: int, q0: Array, options: Options) -> Limit | None:
    """The limit position a set stopped on after ``solved`` rows (q, dq, ddq, each (T, N)), or
    None when the rows do not show one for sure (the set is then re-run)."""
    if solved < 2 or solved >= t.size:
        return None
    if units.unit_for(kernel, q0, float(t[0]), p) != 1.0:
        return None
    q = rows[0]
    t2, t1, failed = (float(t[solved - 2]), float(t[solved - 1]), float(t[solved]))
    with np.errstate(all="ignore"):
        before = _smallest(kernel, q[solved - 2], t2, p)
        last = _smallest(kernel, q[solved - 1], t1, p)
        if before is None or last is None:
            return None
        zero = _fold_time(t2, before[0], t1, last[0])
        if not t1 < zero <= failed + (failed - t1):
            return None
        drivers = np.array([label.startswith("drivers") for label in kernel.rows])
        if not drivers.any() or float(np.sum(last[1][drivers] ** 2)) < DRIVER_SHARE:
            return None
        if zero > failed - FOLD_MARGIN * (failed - t1) and \
                not _closer_fold_before(kernel, p, options, rows, solved, t, last[0]):
            return None
        if singular_start(kernel, q[0], float(t[0]), p, options) is not None:
            return None
        jacobian = np.asarray(kernel.phi_q(q[solved - 1], t1, p), dtype=float)
    aligned, held = limit_motion(kernel, jacobian)
    return Limit("limit position", _message(t, solved, aligned, held), failed)


def _closer_fold_before(kernel: KinematicsKernel, p: Array, options: Options,
                        rows: tuple[Array, Array, Array], solved: int, t: Array,
                        sigma: float) -> bool:
    """For a fold extrapolated near t[k]: substeps towards t[k] (_march, down to each of
    CLOSER_STEPS of the grid step in turn), and the fold extrapolated again from the last two
    points reached, each pair nearer to it. True when that places it before t[k] for sure;
    False (re-run) when the substeps reach t[k]."""
    t1, failed = float(t[solved - 1]), float(t[solved])
    h = failed - t1
    q, dq, ddq = (np.array(r[solved - 1], dtype=float) for r in rows)
    state, previous = (t1, q, dq, ddq), (t1, sigma)
    for fraction in CLOSER_STEPS:
        reached = _march(kernel, p, options, state, failed, h, h * fraction)
        if reached is None:
            return False
        near = _smallest(kernel, reached[1], reached[0], p) if reached[0] > state[0] else None
        if near is None:
            return False
        zero = _fold_time(previous[0], previous[1], reached[0], near[0])
        if reached[0] <= zero <= failed - FOLD_MARGIN * (reached[0] - previous[0]):
            return True
        state, previous = reached, (reached[0], near[0])
    return False


Motion = tuple[float, Array, Array, Array]  # t, q, dq, ddq


def _march(kernel: KinematicsKernel, p: Array, options: Options, state: Motion,
           target: float, h0: float, h_min: float) -> Motion | None:
    """Substeps from state towards target as runtime.edges.march takes them (halved on
    failure, doubled on success) but with plain Newton and no condition estimates (they
    would cost more than the whole sweep): the last point reached before a step of h_min
    failed, or None when target was reached."""
    h = h0
    while state[0] < target:
        step = min(h, target - state[0])
        following = _step(kernel, p, options, state, state[0] + step)
        if following is None:
            if step <= h_min:
                return state
            h = step / 2
        else:
            state, h = following, min(2 * step, h0)
    return None


def _step(kernel: KinematicsKernel, p: Array, options: Options, state: Motion, t: float
          ) -> Motion | None:
    """Predict (2.76), plain Newton at t, velocities and accelerations; None on failure."""
    h = t - state[0]
    q = state[1] + state[2] * h + state[3] * (h * h / 2)
    for _ in range(CLOSER_ITERATIONS):
        jacobian = np.asarray(kernel.phi_q(q, t, p), dtype=float)
        phi = np.asarray(kernel.phi(q, t, p), dtype=float)
        if not (np.all(np.isfinite(jacobian)) and np.all(np.isfinite(phi))):
            return None
        try:
            delta = np.linalg.solve(jacobian, -phi)
        except np.linalg.LinAlgError:
            return None
        q = q + delta
        if np.abs(delta).max(initial=0.0) <= options.tol_dq and \
                np.abs(kernel.phi(q, t, p)).max(initial=0.0) <= options.tol_phi:
            dq = np.linalg.solve(jacobian, -np.asarray(kernel.phi_t(q, t, p), dtype=float))
            ddq = np.linalg.solve(jacobian, np.asarray(kernel.gamma(q, dq, t, p), dtype=float))
            return (t, q, dq, ddq) if np.all(np.isfinite(ddq)) else None
    return None


def _fold_time(t2: float, before: float, t1: float, last: float) -> float:
    """Where sigma_min^2 (relative), falling from t2 to t1, reaches zero if extrapolated
    linearly (a fold: sigma_min ~ sqrt of the distance); inf when it does not fall."""
    if not last < before:
        return math.inf
    return t1 + last**2 * (t1 - t2) / (before**2 - last**2)


def _smallest(kernel: KinematicsKernel, q: Array, t: float, p: Array
              ) -> tuple[float, Array] | None:
    """sigma_min / sigma_max of Phi_q at (q, t) and its left singular vector (None if not
    finite)."""
    jacobian = np.asarray(kernel.phi_q(q, t, p), dtype=float)
    if not np.all(np.isfinite(jacobian)):
        return None
    u, sigma, _ = np.linalg.svd(jacobian)
    if sigma[0] <= 0:
        return None
    return float(sigma[-1] / sigma[0]), u[:, -1]


def _message(t: Array, solved: int, aligned: tuple[str, ...], held: tuple[str, ...]) -> str:
    """The reason as symkin.solve words it, with the grid interval in place of the bisected
    one (the sweep does not bisect)."""
    last, failed = float(t[solved - 1]), float(t[solved])
    return (f"the driven motion reaches a limit position between t = {last:.10g} and the grid "
            f"point t = {failed:.10g} (not bisected in a sweep: symkin.solve of this set "
            f"gives its time): {', '.join(aligned) or 'no joint'} become aligned, and "
            f"{' and '.join(held) or 'no driver'} cannot be followed beyond it. The motion "
            "can go on only by reversing the driver from this time (the mechanism then moves "
            "back on its other branch), or by driving one of the aligned joints instead, "
            "which passes through this position smoothly; or end the time grid before it.")
