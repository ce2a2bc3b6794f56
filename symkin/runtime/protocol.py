"""What the driver needs of a kernel, as a typed Protocol."""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options
from symkin.runtime.csolver import GridSolver

Array = NDArray[np.float64]


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
    def grid_solver(self, options: Options, q: Array, p: Array) -> GridSolver | None: ...
