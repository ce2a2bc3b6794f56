"""Scale-free solving: a mechanism drawn far from unit size is solved in a unit that brings it
there, so the same mechanism in metres, millimetres or micrometres solves alike.

Newton's tolerances, the singularity test and the error model's targets are absolute numbers
(symkin.contract.options); Phi_q mixes lengths and angles, so its condition grows with the
square of the unit (a crank-slider drawn in millimetres looked singular at t0, in
micrometres it could not be assembled; in nanometres every point was flagged). When the
mechanism's length scale L (runtime.start: the largest lever arm in Phi_q, at the first guess)
lies outside NATURAL, the driver solves it in the unit u = 10^k that brings L into [1, 10):
lengths (x, y of each body; the rows of Phi that are lengths) are divided by u, angles kept,
and the results are converted back. Inside NATURAL nothing changes (u = 1). The same
mechanism at 10^-9, 10^-3, 1, 10^3 or 10^6 times its size is then solved on numbers that
differ only by the rounding of that one conversion: the same flags, the motion scaled.

A kernel solved in a unit other than 1 runs the general grid loop in Python over the
kernel's functions (its generated C evaluates Phi, Phi_q, Phi_t and Gamma; its C grid loop is
not used, as its options are absolute): both backends then take the same path. Imports NumPy
only: part of the runtime.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.start import length_rows, length_scale, positions

Array = NDArray[np.float64]

NATURAL = (1e-2, 1e2)
"""Length scales solved as given (u = 1): mechanisms of centimetres to a hundred units."""


def unit_for(kernel: KinematicsKernel, q0: Array, t0: float, p: Array) -> float:
    """The unit u to solve in: 1 when L is in NATURAL (or cannot be told), else 10^floor(log10
    L)."""
    with np.errstate(all="ignore"):
        nz = np.asarray(kernel.phi_q_nz(q0, t0, p), dtype=np.float64)
    if not np.all(np.isfinite(nz)):
        return 1.0
    scale = length_scale(kernel, nz)
    if NATURAL[0] <= scale <= NATURAL[1]:
        return 1.0
    return float(10.0 ** math.floor(math.log10(scale)))


class ScaledKernel:
    """A kernel seen in the unit u: q~ = q / c (c = u for positions, 1 for angles), Phi~ =
    Phi / r (r = u for length rows, 1 for the others), so Phi~_q = Phi_q c / r. Parameters are
    the kernel's own. Everything else (names, rows, pattern, points) is the kernel's."""

    def __init__(self, kernel: KinematicsKernel, unit: float) -> None:
        self.kernel = kernel
        self.unit = unit
        self.column = np.where(positions(kernel), unit, 1.0)
        self.row = np.where(length_rows(kernel), unit, 1.0)
        rows = np.asarray(kernel.pattern_rows, dtype=np.intp)
        cols = np.asarray(kernel.pattern_cols, dtype=np.intp)
        self.nz_factor = self.column[cols] / self.row[rows]
        self.q0 = np.asarray(kernel.q0, dtype=float) / self.column

    def __getattr__(self, name: str) -> Any:
        return getattr(self.kernel, name)

    @property
    def has_grid_solver(self) -> bool:
        return False  # the generated C loop's options are absolute: see the module docstring

    def grid_solver(self, *args: Any) -> None:
        return None

    def to_length(self, q: ArrayLike) -> Array:
        """q~ -> q in the kernel's own unit."""
        return np.asarray(q, dtype=float) * self.column

    def phi(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        return np.asarray(self.kernel.phi(self.to_length(q), t, p), dtype=float) / self.row

    def phi_q(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        matrix = np.asarray(self.kernel.phi_q(self.to_length(q), t, p), dtype=float)
        return matrix * self.column[None, :] / self.row[:, None]

    def phi_q_nz(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        nz = np.asarray(self.kernel.phi_q_nz(self.to_length(q), t, p), dtype=float)
        return nz * self.nz_factor

    def phi_t(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array:
        return np.asarray(self.kernel.phi_t(self.to_length(q), t, p), dtype=float) / self.row

    def gamma(self, q: ArrayLike, dq: ArrayLike, t: float, p: ArrayLike | None = None
              ) -> Array:
        value = self.kernel.gamma(self.to_length(q), self.to_length(dq), t, p)
        return np.asarray(value, dtype=float) / self.row


def to_kernel_unit(scaled: ScaledKernel, q: Array, dq: Array, d2q: Array) -> None:
    """Convert solved rows from the unit u back to the kernel's own, in place."""
    for values in (q, dq, d2q):
        values *= scaled.column
