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
  before t[k] + LIMIT_REACH grid steps;
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

LIMIT_REACH = 1.0
"""How many grid steps past the failing point t[k] the extrapolated fold may lie: the square
root law holds only near the fold, and a fold just past t[k] still stops the plain step."""


@dataclass(frozen=True)
class Limit:
    """A set stopped by a limit position between t[k-1] and t[k]."""

    reason: str
    message: str
    t: float  # the grid point t[k], as symkin.solve reports it


def limit_stop(kernel: KinematicsKernel, p: Array, t: Array, q: Array, solved: int,
               q0: Array, options: Options) -> Limit | None:
    """The limit position a set stopped on after ``solved`` rows ``q`` (T, N), or None when
    the rows do not show one for sure (the set is then re-run)."""
    if solved < 2 or solved >= t.size:
        return None
    if units.unit_for(kernel, q0, float(t[0]), p) != 1.0:
        return None
    with np.errstate(all="ignore"):
        before = _smallest(kernel, q[solved - 2], float(t[solved - 2]), p)
        last = _smallest(kernel, q[solved - 1], float(t[solved - 1]), p)
    if before is None or last is None:
        return None
    if not _fold_ahead(before[0], last[0], t, solved):
        return None
    drivers = np.array([label.startswith("drivers") for label in kernel.rows])
    if not drivers.any() or float(np.sum(last[1][drivers] ** 2)) < DRIVER_SHARE:
        return None
    if singular_start(kernel, q[0], float(t[0]), p, options) is not None:
        return None
    jacobian = np.asarray(kernel.phi_q(q[solved - 1], float(t[solved - 1]), p), dtype=float)
    aligned, held = limit_motion(kernel, jacobian)
    return Limit("limit position", _message(t, solved, aligned, held), float(t[solved]))


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


def _fold_ahead(before: float, last: float, t: Array, solved: int) -> bool:
    """sigma_min^2 (relative) falling from t[k-2] to t[k-1] and, extrapolated linearly,
    zero before t[k] + LIMIT_REACH grid steps."""
    if not last < before:
        return False
    t2, t1, failed = (float(t[solved - 2]), float(t[solved - 1]), float(t[solved]))
    zero = t1 + last**2 * (t1 - t2) / (before**2 - last**2)
    return zero <= failed + LIMIT_REACH * (failed - t1)


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
