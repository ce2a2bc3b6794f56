"""Accuracy you can see: the condition of Phi_q at a solved point and whether q, dq, ddq there
can be trusted to the accuracy targets.

The estimate of ||Phi_q^-1||_1 is Hager's method with Higham's refinements (the algorithm of
LAPACK's xLACN2): a few solves with the factors already made, never a new factorization. The
generated C solver (templates/c/solver.c.j2) runs the same steps and the same error model, so
both backends flag the same points.

The error model, with u the unit roundoff and s = ||Phi_q^-1||_1 / sqrt(N) (max norms of
vectors; near a singularity the 1-norm sums the null vector over about N entries, where one
coordinate's error sees only its share):
    e_q   = max(c, s u (1 + |q|))                  the residual's share, or the rounding of Phi
    e_dq  = s (u |dq| + e_q max(1, |dq|))          the solve's rounding, and Phi_q moved by e_q
    e_ddq = s (u |ddq| + e_q (|ddq| + |dq|^2) + 2 e_dq max(1, |dq|))
each times SAFETY; a point is flagged when one of them exceeds its target times max(1, |x|).
SAFETY, u and the estimator's steps are symkin.contract.tuning's, which the C solver shares.
Only the coordinates that enter Phi_q or Phi_t (kernel.nonlinear: angles, Euler parameters,
a prismatic pair's positions) move Phi_q and Phi_t. Where the model above flags a point, a
refined one decides: with s_n = ||P Phi_q^-1||_1 / sqrt(N), P the rows of those coordinates,
and their max norms ndq_n, nddq_n,
    e_n   = max(min(c, s_n r), s_n u (1 + |q|))       their error
    e_dq  = s (u |dq| + e_n max(1, ndq_n))
    e_dqn = s_n (u |dq| + e_n max(1, ndq_n))          their velocities' error
    e_ddq = s (u |ddq| + e_n (nddq_n + ndq_n^2) + 2 e_dqn max(1, ndq_n))
(e_q as above). On lazy tongs the positions of the far bars are a hundred times more
sensitive than the angles, which alone move Phi_q.
c is the error of q the residual r leaves: max |Phi_q^-1 Phi|, the size of the Newton
correction, where it was solved for (runtime.newton does so before it iterates on to avoid a
flag), else the bound s r. The correction is the actual error where the bound is the worst
case: on the 301-body chain of loops of bench/scaling_limit.py it is a tenth of s r (median).
The errors of a nearly singular Phi_q lie along its null direction and are amplified by s at
each stage (position into velocity, velocity into acceleration), which is what the chain of
parallelogram four-bars shows near its singular configuration (tests/runtime/test_edges_*.py).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.contract.tuning import ESTIMATOR_STEPS, SAFETY

Array = NDArray[np.float64]
Solve = Callable[[Array], Array]
RowsNorm = Callable[[NDArray[np.bool_]], float]


def inverse_norm1(solve: Solve, solve_transposed: Solve, n: int,
                  rows: NDArray[np.bool_] | None = None) -> float:
    """An estimate (never above the true value, usually equal) of ||A^-1||_1 from solves, or
    of ||P A^-1||_1 with P the rows of A^-1 where ``rows`` is True.

    Hager's method (1984) as refined by Higham (1988): ascend the convex function ||A^-1 x||_1
    over the unit ball of the 1-norm, then compare with an alternating-sign test vector.
    """
    keep = np.ones(n) if rows is None else rows.astype(float)

    def rows_solve(x: Array) -> Array:
        return solve(x) * keep  # 0 * inf is NaN: still not finite

    x = np.full(n, 1.0 / n)
    estimate = 0.0
    for step in range(ESTIMATOR_STEPS):
        y = rows_solve(x)
        norm = float(np.abs(y).sum())
        if not math.isfinite(norm):
            return math.inf
        if step > 0 and norm <= estimate:
            break
        estimate = norm
        z = solve_transposed(np.where(y >= 0, 1.0, -1.0) * keep)
        j = int(np.argmax(np.abs(z)))
        if step > 0 and abs(z[j]) <= float(z @ x):
            break
        x = np.zeros(n)
        x[j] = 1.0
    signs = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    alternating = signs * (1.0 + np.arange(n) / max(n - 1, 1))
    extra = 2.0 * float(np.abs(rows_solve(alternating)).sum()) / (3.0 * n)
    return max(estimate, extra) if math.isfinite(extra) else math.inf


def norm1(nz: Array, cols: NDArray[np.intp], n: int) -> float:
    """||Phi_q||_1, the largest column sum of |entries|, from the structural non-zeros."""
    sums = np.zeros(n)
    np.add.at(sums, cols, np.abs(nz))
    return float(sums.max(initial=0.0))


Nonlinear = tuple[float, float, float]
"""(||P Phi_q^-1||_1, max |dq_k|, max |ddq_k|) over the coordinates k that enter Phi_q or
Phi_t (P: their rows of Phi_q^-1), for the refined model of errors."""


def errors(inv_norm: float, residual: float, n: int, nq: float, ndq: float, nddq: float,
           unit: float, correction: float = math.nan, nonlinear: Nonlinear | None = None
           ) -> tuple[float, float, float]:
    """The estimated errors of q, dq and ddq at a solved point (the model of the docstring),
    from the max norms nq, ndq, nddq of q, dq, ddq (N of them each); ``correction``: max
    |Phi_q^-1 Phi| where it was solved for, NaN where not. With ``nonlinear``, only the
    coordinates that enter Phi_q or Phi_t move them: their error e_n and velocities carry the
    error of q into dq and ddq (without it, every coordinate counts as one of them)."""
    s = inv_norm / math.sqrt(n)
    left = correction if correction >= 0 else s * residual
    e_q = max(left, s * unit * (1.0 + nq))
    s_n, ndq_n, nddq_n, e_n = s, ndq, nddq, e_q
    if nonlinear is not None:
        s_n = nonlinear[0] / math.sqrt(n)
        ndq_n, nddq_n = nonlinear[1], nonlinear[2]
        e_n = max(min(left, s_n * residual), s_n * unit * (1.0 + nq))
    e_dq = s * (unit * ndq + e_n * max(1.0, ndq_n))
    e_dq_n = s_n * (unit * ndq + e_n * max(1.0, ndq_n))
    e_ddq = s * (unit * nddq + e_n * (nddq_n + ndq_n * ndq_n) + 2.0 * e_dq_n * max(1.0, ndq_n))
    return SAFETY * e_q, SAFETY * e_dq, SAFETY * e_ddq


def flagged(inv_norm: float, norm_a: float, residual: float, q: Array, dq: Array, ddq: Array,
            options: Options, unit: float, correction: float = math.nan,
            rows_inverse_norm: RowsNorm | None = None,
            nonlinear: NDArray[np.bool_] | None = None) -> bool:
    """True when the estimated error of q, dq or ddq misses its target (options.target_*).

    Where the model of every coordinate flags the point and ``nonlinear`` (the coordinates
    that enter Phi_q or Phi_t) is a part of them, the refined model decides, with
    ``rows_inverse_norm(nonlinear)`` the estimate of ||P Phi_q^-1||_1 (made only then)."""
    nq, ndq, nddq = (float(np.abs(v).max(initial=0.0)) for v in (q, dq, ddq))
    if not flagged_norms(inv_norm, norm_a, residual, q.size, nq, ndq, nddq, options, unit,
                         correction):
        return False
    if nonlinear is None or rows_inverse_norm is None or nonlinear.all():
        return True
    inv_nl = rows_inverse_norm(nonlinear)
    if not math.isfinite(inv_nl):
        return True
    refined = (inv_nl, float(np.abs(dq[nonlinear]).max(initial=0.0)),
               float(np.abs(ddq[nonlinear]).max(initial=0.0)))
    return _misses(errors(inv_norm, residual, q.size, nq, ndq, nddq, unit, correction,
                          refined), nq, ndq, nddq, options)


def flagged_norms(inv_norm: float, norm_a: float, residual: float, n: int, nq: float, ndq: float,
                  nddq: float, options: Options, unit: float,
                  correction: float = math.nan) -> bool:
    """flagged by the model of every coordinate, from the max norms of q, dq and ddq."""
    if not math.isfinite(inv_norm * norm_a):
        return True
    return _misses(errors(inv_norm, residual, n, nq, ndq, nddq, unit, correction), nq, ndq,
                   nddq, options)


def _misses(estimates: tuple[float, float, float], nq: float, ndq: float, nddq: float,
            options: Options) -> bool:
    e_q, e_dq, e_ddq = estimates
    return (e_q > options.target_q * max(1.0, nq) or e_dq > options.target_dq * max(1.0, ndq)
            or e_ddq > options.target_ddq * max(1.0, nddq))
