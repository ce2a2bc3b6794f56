"""A pair's own coordinate leaving the range its file gives (a contact running past the end of
a curve or cam profile written for s in [a, b]): beyond it the curve's formula still has
values (a piecewise profile's first or last piece, extended), so the solve would go on and
report a motion on a curve the file does not describe. The first point past the range ends the
motion as a failure naming the pair, with the rows before it kept.

Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from symkin.runtime.outputs.results import Trajectory

SLACK = 1e-9
"""How far past a bound (relative to the range's length) still counts as on it."""


def first_outside(kernel: Any, trajectory: Trajectory) -> tuple[int, str] | None:
    """The first solved point where a coordinate is outside its range, and what to say; None
    when every point is inside (or the kernel has no ranges)."""
    found: tuple[int, str] | None = None
    for name, low, high, owner in getattr(kernel, "ranges", ()):
        column = trajectory.q[:, list(trajectory.coordinates).index(name)]
        slack = SLACK * (high - low)
        outside = np.flatnonzero((column < low - slack) | (column > high + slack))
        if outside.size and (found is None or outside[0] < found[0]):
            k = int(outside[0])
            found = (k, f"{name} = {column[k]:.6g} left its range [{low:g}, {high:g}] "
                        f"({owner}) at t = {trajectory.t[k]:.6g}: the contact ran past the end "
                        "of the curve as the file gives it. Extend the curve and its range, or "
                        "end the time grid before it")
    return found


PER_POINT = ("t", "q", "dq", "d2q", "flagged", "cond", "q_p", "dq_p", "removed_residual")
"""The Trajectory's arrays with a row per solved point."""


def head(trajectory: Trajectory, rows: int) -> Trajectory:
    """The first ``rows`` points of a trajectory."""
    cut = {name: getattr(trajectory, name)[:rows] for name in PER_POINT
           if getattr(trajectory, name) is not None}
    return dataclasses.replace(trajectory, **cut)
