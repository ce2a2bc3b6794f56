"""Linear algebra of the runtime: LU factors of Phi_q (dense LAPACK or sparse SuperLU), the
pivot ratio that tells a singular Phi_q, and the dependent rows behind a singularity."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving import accuracy

Array = NDArray[np.float64]


SPARSE_FROM = 100
"""Phi_q with this many coordinates or more is factored as a sparse matrix (SuperLU through
scipy.sparse.linalg.splu): a dense factorization costs O(N^3) and its N x N array O(N^2)
memory, while Phi_q has at most about six non-zeros a row (chapter section 2.7). Below it,
LAPACK on the dense matrix is faster than building a sparse one."""

EXACT_INVERSE_UP_TO = 32
"""Up to this many coordinates the condition at a solved point uses the exact ||Phi_q^-1||_1,
the column sums of the inverse from N solves with the factors (cheap at this size); the
generated C does the same for mechanisms whose inverse columns take few operations
(backends.c.inverse_code), so both backends flag the same points."""


@dataclass(frozen=True)
class Factors:
    """LU factors of Phi_q with partial pivoting, and the pivot-ratio singularity estimate."""

    lu: Array
    pivots: NDArray[np.int32]
    pivot_ratio: float
    getrs: Callable[..., Any]  # LAPACK's solve with these factors
    norm1: float = math.nan  # ||Phi_q||_1 of the matrix factored
    gecon: Callable[..., Any] | None = None  # LAPACK's condition estimate with these factors
    matrix: Array | None = None  # Phi_q itself (not a copy)

    @property
    def exact(self) -> bool:
        """Whether inverse_norm1 is exact rather than an estimate."""
        return bool(self.lu.shape[0] <= EXACT_INVERSE_UP_TO)

    def inverse_norm1(self) -> float:
        """||Phi_q^-1||_1: exact up to EXACT_INVERSE_UP_TO coordinates (as the generated C
        computes it for small mechanisms), above that LAPACK's xGECON (Hager-Higham, the
        estimator the C solver runs for large ones)."""
        n = self.lu.shape[0]
        if n <= EXACT_INVERSE_UP_TO:
            inverse = self.solve(np.eye(n))
            norm = float(np.abs(inverse).sum(axis=0).max(initial=0.0))
            return norm if math.isfinite(norm) else math.inf
        if self.gecon is None or not self.norm1 > 0:
            return accuracy.inverse_norm1(self.solve, self.solve_transposed, self.lu.shape[0])
        rcond, info = self.gecon(self.lu, self.norm1, norm="1")
        return 1.0 / (rcond * self.norm1) if rcond > 0 and info == 0 else math.inf

    def solve(self, b: Array) -> Array:
        x, _ = self.getrs(self.lu, self.pivots, b)
        return np.asarray(x, dtype=float)

    def solve_transposed(self, b: Array) -> Array:
        """Solve Phi_q^T x = b with the same factors (the condition estimate needs it)."""
        x, _ = self.getrs(self.lu, self.pivots, b, trans=1)
        return np.asarray(x, dtype=float)


@dataclass(frozen=True)
class SparseFactors:
    """Sparse LU factors of Phi_q (SuperLU, partial pivoting by rows, fill-reducing column
    order) with the same pivot-ratio estimate; ``lu`` is None when a pivot vanished."""

    lu: Any
    pivot_ratio: float
    norm1: float = math.nan  # ||Phi_q||_1 of the matrix factored
    matrix: Any = None  # Phi_q as a scipy.sparse matrix

    exact = False  # inverse_norm1 is an estimate (this size is above EXACT_INVERSE_UP_TO)

    def inverse_norm1(self) -> float:
        """Estimate of ||Phi_q^-1||_1 (Hager-Higham, as the C solver runs it)."""
        if self.lu is None:
            return math.inf
        return accuracy.inverse_norm1(self.solve, self.solve_transposed, self.lu.shape[0])

    def solve(self, b: Array) -> Array:
        return np.asarray(self.lu.solve(np.asarray(b, dtype=float)), dtype=float)

    def solve_transposed(self, b: Array) -> Array:
        """Solve Phi_q^T x = b with the same factors (the condition estimate needs it)."""
        return np.asarray(self.lu.solve(np.asarray(b, dtype=float), trans="T"), dtype=float)


def factor(jacobian: Array) -> Factors:
    """Factor P Phi_q = L U (LAPACK getrf, as the C runtime does it: largest pivot in the column).

    A zero pivot is not an error here: it gives ratio 0, which the caller judges.
    """
    from scipy.linalg import lapack  # imported on use: a warm C run never needs SciPy

    lu, pivots, _ = lapack.dgetrf(jacobian)
    norm = float(np.abs(jacobian).sum(axis=0).max(initial=0.0))
    return Factors(lu, pivots, _ratio(np.abs(np.diag(lu))), lapack.dgetrs, norm, lapack.dgecon,
                   jacobian)


def factor_sparse(n: int, rows: NDArray[np.intp], cols: NDArray[np.intp], values: Array
                  ) -> SparseFactors:
    """Factor Phi_q given as its structural non-zeros (pattern order), in O(non-zeros + fill)."""
    from scipy.sparse import csc_matrix
    from scipy.sparse.linalg import splu

    if not np.all(np.isfinite(values)):
        return SparseFactors(None, 0.0)
    matrix = csc_matrix((values, (rows, cols)), shape=(n, n))
    try:
        lu = splu(matrix)
    except RuntimeError:  # SuperLU: "Factor is exactly singular"
        return SparseFactors(None, 0.0)
    return SparseFactors(lu, _ratio(np.abs(lu.U.diagonal())), accuracy.norm1(values, cols, n),
                         matrix)


def distance1(first: Factors | SparseFactors, second: Factors | SparseFactors) -> float:
    """||A - B||_1 of the two matrices factored, dense or sparse alike (NaN when one is not
    kept)."""
    if first.matrix is None or second.matrix is None:
        return math.nan
    return float(abs(first.matrix - second.matrix).sum(axis=0).max())


def factor_at(kernel: KinematicsKernel, q: Array, t: float, p: Array) -> Factors | SparseFactors:
    """Factor Phi_q(q, t): dense below SPARSE_FROM coordinates, sparse from there on."""
    n = len(kernel.coordinates)
    if n < SPARSE_FROM:
        return factor(kernel.phi_q(q, t, p))
    return factor_sparse(n, kernel.pattern_rows, kernel.pattern_cols,
                         np.asarray(kernel.phi_q_nz(q, t, p), dtype=np.float64))


def _ratio(magnitudes: Array) -> float:
    """min |u_kk| / max |u_kk|; 0 when a pivot vanished or is not finite."""
    largest = magnitudes.max(initial=0.0)
    ratio = float(magnitudes.min() / largest) if largest > 0 else 0.0
    return ratio if math.isfinite(ratio) else 0.0




def dependencies(jacobian: Array, labels: Sequence[str], rcond: float = 1e-8
                 ) -> tuple[int, list[list[str]]]:
    """The rank loss of Phi_q and a minimal set of dependent rows for each lost rank.

    The left null space (left singular vectors with sigma <= rcond sigma_max; at least the
    weakest one) is brought to reduced row-echelon form, then each basis vector is made
    sparser by subtracting multiples of the others while that removes rows: each ends as the
    few rows of one dependency (a closed loop of aligned links, a redundant joint) rather
    than every row the null space touches.
    """
    if not np.all(np.isfinite(jacobian)):
        return 0, [list(labels)]
    u, sigma, _ = np.linalg.svd(jacobian)
    null = u[:, sigma <= rcond * max(sigma[0], 1e-300)]
    if null.shape[1] == 0:
        null = u[:, -1:]
    basis = null.T.copy()
    pivots: list[int] = []
    for row in range(basis.shape[0]):
        free = np.abs(basis[row:]).copy()
        free[:, np.array(pivots, dtype=np.intp)] = 0
        r, c = (int(i) for i in np.unravel_index(int(np.argmax(free)), free.shape))
        basis[[row, row + r]] = basis[[row + r, row]]
        basis[row] /= basis[row, c]
        for other in range(basis.shape[0]):
            if other != row:
                basis[other] -= basis[other, c] * basis[row]
        pivots.append(int(c))
    basis = _sparsest(basis)
    groups = sorted([[labels[int(i)] for i in np.flatnonzero(_support(vector))]
                     for vector in basis],
                    key=lambda group: [labels.index(row) for row in group])
    return int(null.shape[1]), groups


def _support(vector: Array) -> NDArray[np.bool_]:
    return np.asarray(np.abs(vector) > 1e-6 * np.abs(vector).max(initial=0.0))


def _sparsest(basis: Array) -> Array:
    """Replace basis vectors by combinations with fewer non-zeros while any pair allows it."""
    improved = True
    while improved:
        improved = False
        for i in range(basis.shape[0]):
            for j in range(basis.shape[0]):
                if i == j:
                    continue
                for m in np.flatnonzero(_support(basis[i]) & _support(basis[j])):
                    trial = basis[i] - basis[i, m] / basis[j, m] * basis[j]
                    if _support(trial).sum() < _support(basis[i]).sum():
                        basis[i], improved = trial / np.abs(trial).max(), True
                        break
    return basis
