"""Accuracy you can see: the condition of Phi_q at a solved point and whether q, dq, ddq there
can be trusted to the accuracy targets.

The estimate of ||Phi_q^-1||_1 is Hager's method with Higham's refinements (the algorithm of
LAPACK's xLACN2): a few solves with the factors already made, never a new factorization. The
generated C solver (the C backend's solver.c.j2) runs the same steps and the same error model, so
both backends flag the same points.

The error model has two stages. The norm bound, with u the unit roundoff and
s = ||Phi_q^-1||_1 / sqrt(N) (max norms of vectors; near a singularity the 1-norm sums the null
vector over about N entries, where one coordinate's error sees only its share):
    e_q   = max(c, s u (1 + |q|))                  the residual's share, or the rounding of Phi
    e_dq  = s (u |dq| + e_q max(1, |dq|))          the solve's rounding, and Phi_q moved by e_q
    e_ddq = s (u |ddq| + e_q (|ddq| + |dq|^2) + 2 e_dq max(1, |dq|))
each times SAFETY; a point is flagged when one of them exceeds its target times max(1, |x|).
It multiplies three norm bounds, each above the actual amplification: near a singular
configuration, where the actual error of ddq grows as cond^3, it stands a hundred times above
it. Where it flags a point, the propagated model decides (flagged): the position error is
e_q (without SAFETY) along the worst direction w, the column of Phi_q^-1 of largest 1-norm
that Hager's ascent finds (worst_column; near a singularity every column lies along the null
direction, where the rounding of Phi moves q), and the errors of dq and ddq are what that
error causes, carried through the velocity and acceleration solves to first order
(propagated):
    e      = e_q w / max |w|
    d_dq   = -Phi_q^-1 D(Phi_q dq + Phi_t)[e]
    d_ddq  =  Phi_q^-1 (D Gamma[e, d_dq] - D(Phi_q)[e] ddq)
    flagged where e_q, max |d_dq| + s u |dq| or max |d_ddq| + s u |ddq| misses its target,
the directional derivatives D forward differences of length sqrt(u) (1 + |q|). The
derivatives see only the coordinates that move Phi_q, Phi_t and Gamma (on lazy tongs the
angles, not the far bars' positions, a hundred times more sensitive). On the chain of
parallelogram four-bars crossing its singular configuration these estimates stand 3 to 11
times above the actual errors (tests/runtime/test_flag_model.py), and the propagation of the
actual position error gives the actual errors of dq and ddq: the errors there are the
position error carried through the solves.
SAFETY, u and the estimator's steps are symkin.contract.tuning's, which the C solver shares.
c is the error of q the residual r leaves: max |Phi_q^-1 Phi|, the size of the Newton
correction, where it was solved for (runtime.solving.newton does so before it iterates on to avoid a
flag), else the bound s r. The correction is the actual error where the bound is the worst
case: on the 301-body chain of loops of bench/scaling_limit.py it is a tenth of s r (median).
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


def errors(inv_norm: float, residual: float, n: int, nq: float, ndq: float, nddq: float,
           unit: float, correction: float = math.nan) -> tuple[float, float, float]:
    """The bounds of the errors of q, dq and ddq at a solved point (the norm bound of the
    docstring), from the max norms nq, ndq, nddq of q, dq, ddq (N of them each);
    ``correction``: max |Phi_q^-1 Phi| where it was solved for, NaN where not."""
    s = inv_norm / math.sqrt(n)
    e_q = position_error(inv_norm, residual, n, nq, unit, correction)
    e_dq = s * (unit * ndq + e_q * max(1.0, ndq))
    e_ddq = s * (unit * nddq + e_q * (nddq + ndq * ndq) + 2.0 * e_dq * max(1.0, ndq))
    return SAFETY * e_q, SAFETY * e_dq, SAFETY * e_ddq


def position_error(inv_norm: float, residual: float, n: int, nq: float, unit: float,
                   correction: float = math.nan) -> float:
    """e_q of the docstring: the error of q the residual leaves, or the rounding of Phi."""
    s = inv_norm / math.sqrt(n)
    left = correction if correction >= 0 else s * residual
    return max(left, s * unit * (1.0 + nq))


def worst_column(solve: Solve, solve_transposed: Solve, n: int) -> Array:
    """The column of Phi_q^-1 of largest 1-norm that Hager's ascent finds (the solve of
    x = 1/n first, then of the unit vectors it moves to): near a singularity every column lies
    along the null direction, the one in which the rounding of Phi moves q. Not finite where a
    solve is not. The generated C (the C backend's _error_model.c.j2) takes the same steps."""
    at = -1  # x = 1/n until the ascent moves to the unit vector e_at
    y = solve(np.full(n, 1.0 / n))
    norm = float(np.abs(y).sum())
    for _ in range(ESTIMATOR_STEPS - 1):
        if not math.isfinite(norm):
            break
        z = solve_transposed(np.where(y >= 0, 1.0, -1.0))
        j = int(np.argmax(np.abs(z)))
        along = float(z.sum()) / n if at < 0 else float(z[at])  # z . x
        if not abs(z[j]) > along:
            break
        unit_vector = np.zeros(n)
        unit_vector[j] = 1.0
        candidate = solve(unit_vector)
        candidate_norm = float(np.abs(candidate).sum())
        if not candidate_norm > norm:
            break
        at, y, norm = j, candidate, candidate_norm
    return y


VelocityRows = Callable[[Array], Array]
"""Phi_q(q + d) dq + Phi_t(q + d) at the solved q, dq: the velocity equations' rows with q
moved by d (zero at d = 0, up to rounding)."""
AccelerationRows = Callable[[Array, Array], Array]
"""Gamma(q + d, dq + v) - Phi_q(q + d) ddq: the acceleration equations' rows with q moved by d
and dq by v."""


def propagated(solve: Solve, direction: Array, size: float, step: float,
               velocity_rows: VelocityRows, acceleration_rows: AccelerationRows
               ) -> tuple[float, float]:
    """max |error of dq| and max |error of ddq| that the position error
    e = size * direction / max |direction| causes, to first order: the velocity and
    acceleration equations at q + e, Phi_q(q+e) (dq + d_dq) = -Phi_t(q+e) and
    Phi_q(q+e) (ddq + d_ddq) = Gamma(q+e, dq+d_dq), less those at q, give
        d_dq  = -Phi_q^-1 D(Phi_q dq + Phi_t)[e]
        d_ddq =  Phi_q^-1 (D Gamma[e, d_dq] - D(Phi_q)[e] ddq)
    with the directional derivatives D as forward differences of length ``step``."""
    largest = float(np.abs(direction).max(initial=0.0))
    if not (math.isfinite(largest) and largest > 0 and size > 0):
        return (0.0, 0.0) if largest == 0 or size == 0 else (math.inf, math.inf)
    moved = direction * (step / largest)
    d_dq = solve(velocity_rows(moved)) * (-size / step)
    d_ddq = solve(acceleration_rows(moved, d_dq * (step / size))) * (size / step)
    return float(np.abs(d_dq).max()), float(np.abs(d_ddq).max())


Propagate = Callable[[float], tuple[float, float]]
"""The errors of dq and ddq (max norms) a position error of this max norm causes along the
worst direction (worst_column and propagated at a solved point)."""


def flagged(inv_norm: float, norm_a: float, residual: float, q: Array, dq: Array, ddq: Array,
            options: Options, unit: float, correction: float = math.nan,
            propagate: Propagate | None = None, judged: int = 2) -> bool:
    """True when the estimated error of q, dq or ddq misses its target (options.target_*).

    Where the norm bound flags the point and ``propagate`` is given, the propagated model
    decides (the docstring): e_q, and the errors of dq and ddq it causes along the worst
    direction plus the rounding of their solves. ``judged`` < 2: an input-driven point whose
    accelerations (< 1: also rates) were not given and not solved for: their errors are not
    judged (they stand as zeros in the estimates of the others)."""
    nq, ndq, nddq = (float(np.abs(v).max(initial=0.0)) for v in (q, dq, ddq))
    if not flagged_norms(inv_norm, norm_a, residual, q.size, nq, ndq, nddq, options, unit,
                         correction, judged):
        return False
    if propagate is None:
        return True
    e_q = position_error(inv_norm, residual, q.size, nq, unit, correction)
    e_dq, e_ddq = propagate(e_q)
    s = inv_norm / math.sqrt(q.size)
    estimates = (e_q, e_dq + s * unit * ndq, e_ddq + s * unit * nddq)[:judged + 1]
    return (not all(map(math.isfinite, estimates))
            or _misses(estimates, nq, ndq, nddq, options))


def flagged_norms(inv_norm: float, norm_a: float, residual: float, n: int, nq: float, ndq: float,
                  nddq: float, options: Options, unit: float,
                  correction: float = math.nan, judged: int = 2) -> bool:
    """flagged by the norm bound, from the max norms of q, dq and ddq (of q and the first
    ``judged`` of dq, ddq)."""
    if not math.isfinite(inv_norm * norm_a):
        return True
    estimates = errors(inv_norm, residual, n, nq, ndq, nddq, unit, correction)
    return _misses(estimates[:judged + 1], nq, ndq, nddq, options)


def _misses(estimates: tuple[float, ...], nq: float, ndq: float, nddq: float,
            options: Options) -> bool:
    """Whether one of the estimates given (of q, then dq, then ddq) misses its target."""
    targets = (options.target_q * max(1.0, nq), options.target_dq * max(1.0, ndq),
               options.target_ddq * max(1.0, nddq))
    return any(e > target for e, target in zip(estimates, targets))
