"""What the driver needs of a kernel, and of a backend's grid solver, as typed Protocols."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ChunkResult:
    """What one call of a grid solver reports.

    Attributes:
        solved: how many time points of the chunk were solved.
        status: contract.status OK, NO_CONVERGENCE or SINGULAR at the last point attempted.
        t: the time of that point.
        iterations, residual: Newton's count and max |Phi| there.
        fallbacks: the sparse LU's fall-backs to dense LU so far (0 for the dense LU).
    """

    solved: int
    status: int
    t: float
    iterations: int
    residual: float
    fallbacks: int


class GridSolver(Protocol):
    """One run of a backend's own grid loop (the generated C solver): it keeps its state
    between calls, so a grid runs in chunks exactly as in one call. A kernel hands one out
    per run (``Kernel.grid_solver``); the driver releases it after the run."""

    def start(self, options: Options, q: Array, p: Array, unit: float = 1.0) -> GridSolver:
        """Begin a new run from q with parameters p (decisions in the length unit ``unit``)."""
        ...

    def bind(self, times: Array, q_out: Array, dq_out: Array, d2q_out: Array,
             cond_out: Array, flagged_out: NDArray[np.bool_],
             forces_out: tuple[Array, Array] | None = None) -> None:
        """The run's grid and the C-contiguous rows :meth:`advance` writes (and, for a
        kernel with inverse dynamics, the multipliers and loads of each row)."""
        ...

    def advance(self, start: int, stop: int) -> int:
        """Solve the bound points start..stop-1; returns how many were solved."""
        ...

    @property
    def status(self) -> int:
        """The status at the last point attempted (symkin.contract.status codes)."""
        ...

    @property
    def fallbacks(self) -> int:
        """The sparse LU's fall-backs to dense LU since :meth:`start`."""
        ...

    def outcome(self, solved: int) -> ChunkResult:
        """The last call's report, with the count it returned."""
        ...

    def start_lever_arm(self, t: float) -> float | None:
        """The length scale (runtime.solving.start.lever_arm, raw: 0 where there is no lever
        arm, NaN where Phi_q is not finite) at the run's first guess and parameters at t;
        None where the solver cannot tell."""
        ...

    @property
    def first_lever_arm(self) -> float | None:
        """The same at the run's first row, as the solver found it there (NaN: no row);
        None where the solver does not report it."""
        ...

    def point_vectors(self, count: int, size: int = 2) -> Array:
        """The local vectors of the named points at the run's parameters, (count, size)."""
        ...

    def set_state(self, t: float, q: Array, dq: Array, ddq: Array) -> None:
        """Continue from a point solved elsewhere."""
        ...

    def last_q(self) -> Array:
        """The solver's current q."""
        ...

    def release(self) -> None:
        """Forget the run's arrays and hand the solver back."""
        ...


BatchStatus = tuple[NDArray[np.int32], NDArray[np.int32], NDArray[np.int32], Array, Array]
"""(status, iterations, solved, cond, start_cond) per parameter set of a batch solve; solved:
the rows written (a failed set stopped at the grid point t[solved]); cond, start_cond: the
condition estimate at the last row solved and at the first (NaN: none), in the set's unit."""


class BatchSolver(Protocol):
    """A backend's solve of many parameter sets in one call (the generated C batch): plain
    Newton from q0 at t[0] per set, decided in the length unit units[j], rows written into
    q, dq, d2q (m, T, N). ``scale_free``: whether it honours a unit other than 1."""

    scale_free: bool

    def __call__(self, params: Array, t: Array, q0: Array, options: Options,
                 q: Array, dq: Array, d2q: Array, units: Array) -> BatchStatus: ...

    def length_scales(self, params: Array, q: Array, t: float) -> Array:
        """Per set, the largest lever arm in Phi_q at (q, t) (runtime.solving.start.length_scale,
        raw: 0 where there is none, NaN where Phi_q is not finite); q (N,) or (m, N)."""
        ...



EDGE_REACHED, EDGE_PASSABLE, EDGE_STOPPED = 0, 1, 2
"""The outcomes of an EdgeSolver (the generated ``<PREFIX>_EDGE_*``)."""


@dataclass(frozen=True)
class EdgeFound:
    """What a backend's edge treatment found (runtime.solving.edges.resolve up to its decision):
    outcome (EDGE_*), the step that failed from the last point reached, that point's condition
    estimate, time, q, dq and ddq; the substeps taken (contract.tuning.EDGE_SUBSTEPS when that
    bound stopped the motion)."""

    outcome: int
    failed: float
    cond: float
    t: float
    q: Array
    dq: Array
    ddq: Array
    substeps: int = 0


class EdgeSolver(Protocol):
    """A backend's substeps from a solved point towards a grid point it could not reach (the
    generated ``<prefix>_solve_edge``): start = (t, q, dq, ddq) with its condition ``cond``,
    decided in the length unit ``unit`` (runtime.solving.units; the rows stay in the kernel's)."""

    def __call__(self, options: Options, p: Array, start: tuple[float, Array, Array, Array],
                 cond: float, t: float, h_min: float, delta: float, unit: float = 1.0
                 ) -> EdgeFound: ...


class KinematicsKernel(Protocol):
    """What the driver needs of a kernel: the compiled :class:`Kernel`, or any stand-in with
    the same attributes (a test's lambdify kernel, a hand-written model)."""

    name: str
    real: str
    coordinates: tuple[str, ...]
    parameter_names: tuple[str, ...]
    p_values: Array
    q0: Array
    time_grid: tuple[float, float, float]
    rows: tuple[str, ...]
    pattern_rows: NDArray[np.intp]
    pattern_cols: NDArray[np.intp]
    points: tuple[tuple[str, str], ...]

    @property
    def has_grid_solver(self) -> bool: ...


    def phi(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array: ...
    def phi_q(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array: ...
    def phi_q_nz(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array: ...
    def phi_t(self, q: ArrayLike, t: float, p: ArrayLike | None = None) -> Array: ...
    def gamma(self, q: ArrayLike, dq: ArrayLike, t: float,
              p: ArrayLike | None = None) -> Array: ...
    def point_vectors(self, p: ArrayLike | None = None) -> Array: ...
    def grid_solver(self, options: Options, q: Array, p: Array,
                    unit: float = 1.0) -> GridSolver | None: ...
