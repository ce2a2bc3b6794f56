"""Scale-free solving: a mechanism drawn far from unit size is solved in a unit that brings it
there, so the same mechanism in metres, millimetres or micrometres solves alike.

Newton's tolerances, the singularity test and the error model's targets are absolute numbers
(symkin.contract.options); Phi_q mixes lengths and angles, so its condition grows with the
square of the unit (a crank-slider drawn in millimetres looked singular at t0, in
micrometres it could not be assembled; in nanometres every point was flagged). When the
mechanism's length scale L (runtime.solving.start: the largest lever arm in Phi_q, at the first
guess) lies outside NATURAL, the driver solves it in the unit u = 10^k that brings L into [1, 10):
lengths (x, y of each body; the rows of Phi that are lengths) are divided by u, angles kept,
and the results are converted back. Inside NATURAL nothing changes (u = 1). The same
mechanism at 10^-9, 10^-3, 1, 10^3 or 10^6 times its size is then solved on numbers that
differ only by the rounding of that one conversion: the same flags, the motion scaled.

A C kernel runs its generated grid loop in that unit too (the C options' ``unit``: the
generated solver scales Phi, Phi_q and the solutions as ScaledKernel does, while its q, dq and
ddq stay in the kernel's own unit); ScaledGridSolver shows that loop to the driver in the unit
u, so the driver's treatment of the points it stops at is the same whichever backend solved
the rest. Both backends take the same decisions at C speed on C. A kernel whose generated C
cannot rescale (``CKernel.scale_free`` false: a literal lever arm folded into the code, or a
kernel built before the option) runs the general loop in Python over its functions instead.
Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options
from symkin.runtime.protocol import ChunkResult, GridSolver, KinematicsKernel
from symkin.runtime.solving.newton import Newton, Point
from symkin.runtime.solving.start import length_rows, lever_arm, positions

Array = NDArray[np.float64]

NATURAL = (1e-2, 1e2)
"""Length scales solved as given (u = 1): mechanisms of centimetres to a hundred units."""


def unit_for(kernel: KinematicsKernel, q0: Array, t0: float, p: Array) -> float:
    """The unit u to solve in: 1 when L is in NATURAL (or cannot be told), else 10^floor(log10
    L)."""
    return unit_of(lever_arm(kernel, q0, t0, p))


def unit_of(scale: float) -> float:
    """unit_for from the length scale L (runtime.solving.start.lever_arm)."""
    if not math.isfinite(scale):  # Phi_q not finite at q0
        return 1.0
    if NATURAL[0] <= scale <= NATURAL[1]:
        return 1.0
    return float(10.0 ** math.floor(math.log10(scale)))


def units_for(scales: ArrayLike) -> Array:
    """unit_for of many sets from their raw length scales (BatchSolver.length_scales: 0 where
    there is none, NaN where it cannot be told; unit 1 for both, as length_scale decides)."""
    found = np.asarray(scales, dtype=np.float64)
    units = np.ones(found.shape)
    with np.errstate(invalid="ignore"):
        outside = np.isfinite(found) & (found > 0) & ((found < NATURAL[0]) | (found > NATURAL[1]))
    for j in np.flatnonzero(outside):  # a few; math.log10 as unit_for takes it
        units[j] = 10.0 ** math.floor(math.log10(float(found[j])))
    return units


class ScaledKernel:
    """A kernel seen in the unit u: q~ = q / c (c = u for positions, 1 for angles), Phi~ =
    Phi / r (r = u for length rows, 1 for the others), so Phi~_q = Phi_q c / r. Parameters are
    the kernel's own. Everything else (names, rows, pattern, points) is the kernel's."""

    def __init__(self, kernel: KinematicsKernel, unit: float) -> None:
        self.kernel = kernel
        self.unit = unit
        # Not the kernel's batch solver: it works in the kernel's unit, not in this view's
        # (runtime.solving.start.lever_arm would read its L in the wrong unit).
        self.batch_solver = None
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
        return bool(self.kernel.has_grid_solver)

    def grid_solver(self, options: Options, q: Array, p: Array, unit: float = 1.0
                    ) -> ScaledGridSolver | None:
        """The kernel's grid loop deciding in this unit, seen in it (None where the kernel has
        none, or one that cannot rescale: the driver then loops in Python)."""
        del unit  # q is in this view's unit already
        inner = self.kernel.grid_solver(options, self.to_length(q), p, self.unit)
        return None if inner is None else ScaledGridSolver(inner, self)

    def input_stepper(self) -> ScaledInputStepper | None:
        """The kernel's generated input solve deciding in this unit, seen in it (None where
        the kernel has none, or one that cannot rescale, as grid_solver: the runtime's Newton
        then solves this view)."""
        # (an input kernel's, runtime.input_driven.inputs)
        make = getattr(self.kernel, "input_stepper", None)
        if make is None or not getattr(self.kernel, "scale_free", True):
            return None
        inner = make()
        return None if inner is None else ScaledInputStepper(inner, self)

    def multipliers_grid(self, t: Array, q: Array, dq: Array, d2q: Array, p: Array
                         ) -> tuple[Array, Array]:
        """The kernel's multipliers and loads of rows given in this unit (in its own unit)."""
        kernel: Any = self.kernel  # a kernel with dynamics (runtime.loads.forces asks only those)
        result: tuple[Array, Array] = kernel.multipliers_grid(
            t, self.to_length(q), self.to_length(dq), self.to_length(d2q), p)
        return result

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


class ScaledGridSolver:
    """A kernel's grid solver run in the unit u (its options' ``unit``), shown to the driver in
    that unit like ScaledKernel: the rows it writes in the kernel's unit are divided by the
    column scales as they come, and a state handed to it is multiplied back."""

    def __init__(self, solver: GridSolver, scaled: ScaledKernel) -> None:
        self.solver = solver
        self.scaled = scaled
        self.rows: tuple[Array, ...] = ()

    def start(self, options: Options, q: Array, p: Array, unit: float = 1.0
              ) -> ScaledGridSolver:
        del unit
        self.solver.start(options, self.scaled.to_length(q), p, self.scaled.unit)
        return self

    def bind(self, times: Array, q_out: Array, dq_out: Array, d2q_out: Array,
             cond_out: Array, flagged_out: NDArray[np.bool_],
             forces_out: tuple[Array, Array] | None = None) -> None:
        self.rows = (q_out, dq_out, d2q_out)
        self.solver.bind(times, q_out, dq_out, d2q_out, cond_out, flagged_out, forces_out)

    def advance(self, start: int, stop: int) -> int:
        solved = self.solver.advance(start, stop)
        for values in self.rows:
            values[start:start + solved] /= self.scaled.column
        return solved

    @property
    def status(self) -> int:
        return self.solver.status

    @property
    def fallbacks(self) -> int:
        return self.solver.fallbacks

    def outcome(self, solved: int) -> ChunkResult:
        return self.solver.outcome(solved)

    def point_vectors(self, count: int, size: int = 2) -> Array:
        return self.solver.point_vectors(count, size)

    def start_lever_arm(self, t: float) -> float | None:
        """None: the kernel's solver reports lever arms in the kernel's unit, not this view's
        (start.lever_arm of this view is worked out from its own Phi_q)."""
        del t
        return None

    @property
    def first_lever_arm(self) -> float | None:
        return None

    def set_state(self, t: float, q: Array, dq: Array, ddq: Array) -> None:
        length = self.scaled.to_length
        self.solver.set_state(t, length(q), length(dq), length(ddq))

    def last_q(self) -> Array:
        return np.asarray(self.solver.last_q(), dtype=float) / self.scaled.column

    def release(self) -> None:
        self.rows = ()
        self.solver.release()


class ScaledInputStepper:
    """A kernel's generated input solve (runtime.input_driven.inputs.InputStepper) run in the unit
    u, shown in that unit like ScaledKernel: q handed to it is multiplied back, the q, dq, ddq it
    returns (in the kernel's unit) are divided by the column scales."""

    def __init__(self, stepper: Any, scaled: ScaledKernel) -> None:
        self.stepper = stepper
        self.scaled = scaled

    @property
    def fallbacks(self) -> int:
        return int(self.stepper.fallbacks)

    @property
    def branch_jump(self) -> bool:
        return bool(self.stepper.branch_jump)

    def start(self, options: Options, q: Array, unit: float = 1.0) -> None:
        del unit  # q is in this view's unit already
        self.stepper.start(options, self.scaled.to_length(q), self.scaled.unit)

    def step(self, t: float, pu: Array, rates: int) -> Point | Newton:
        outcome: Point | Newton = self.stepper.step(t, pu, rates)
        column = self.scaled.column
        if isinstance(outcome, Point):
            return dataclasses.replace(outcome, q=outcome.q / column, dq=outcome.dq / column,
                                       ddq=outcome.ddq / column)
        return dataclasses.replace(outcome, q=outcome.q / column)
