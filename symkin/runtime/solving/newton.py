"""Positions at one time point: Newton-Raphson (2.72) with the condition estimate and the
error model at the converged point. The status codes are shared with the generated C solver
(symkin.contract.status); Levenberg-Marquardt, for assembly from a poor guess, is plain dense
numerics (symkin.contract.dense_solvers)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.contract.status import NO_CONVERGENCE, NOT_FINITE, OK, SINGULAR
from symkin.contract.tuning import REESTIMATE_SHIFT, TIGHTEN_STEPS, UNIT_ROUNDOFF
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving import accuracy
from symkin.runtime.solving.linalg import Factors, SparseFactors, distance1, factor_at

Array = NDArray[np.float64]

@dataclass
class Newton:
    """The outcome of Newton-Raphson at one time point; at a converged point also the estimate
    of ||Phi_q^-1||_1 and ||Phi_q||_1 and, where it was solved for, max |Phi_q^-1 Phi| at q
    (runtime.solving.accuracy)."""

    q: Array
    status: int
    iterations: int
    residual: float
    factors: Factors | SparseFactors | None
    inv_norm: float = math.nan
    norm_a: float = math.nan
    correction: float = math.nan

    @property
    def cond(self) -> float:
        """The estimated 1-norm condition number of Phi_q at q."""
        return self.inv_norm * self.norm_a


@dataclass
class Point:
    """One solved time point: coordinates, velocities, accelerations and their trust."""

    q: Array
    dq: Array
    ddq: Array
    cond: float
    flagged: bool


def newton(kernel: KinematicsKernel, q: Array, t: float, p: Array, options: Options,
           previous: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Newton:
    """Newton-Raphson that tests the residual of the current iterate (2.72).

    Converged when max |Phi(q_k)| <= tol_phi and the step that led to q_k was at most tol_dq
    (or no step was needed). The factors returned are those of Phi_q at the converged q, ready
    for the velocity and acceleration solves. ``previous``: max |q|, |dq| and |ddq| of the
    last point solved, for the error model (_converged; zeros at a first point).
    """
    q = np.array(q, dtype=float)
    step = math.inf
    for iteration in range(options.max_iterations + 1):
        phi = kernel.phi(q, t, p)
        residual = float(np.abs(phi).max(initial=0.0))
        if not math.isfinite(residual):  # singular at t (first iterate), or diverged
            return Newton(q, NOT_FINITE if iteration == 0 else NO_CONVERGENCE, iteration,
                          residual, None)
        factors = factor_at(kernel, q, t, p)
        if factors.pivot_ratio < options.min_pivot_ratio:
            return Newton(q, SINGULAR, iteration, residual, factors)
        if residual <= options.tol_phi and (iteration == 0 or step <= options.tol_dq):
            return _converged(kernel, Newton(q, OK, iteration, residual, factors), t, p,
                              options, phi, step, previous)
        if iteration == options.max_iterations:
            break
        delta = factors.solve(-phi)
        q += delta
        step = float(np.abs(delta).max(initial=0.0))
    return Newton(q, NO_CONVERGENCE, options.max_iterations, residual, None)


def _estimate(result: Newton) -> Newton:
    factors = result.factors
    assert factors is not None
    result.inv_norm, result.norm_a = factors.inverse_norm1(), factors.norm1
    return result


def _converged(kernel: KinematicsKernel, result: Newton, t: float, p: Array, options: Options,
               phi: Array, step: float, previous: tuple[float, float, float]) -> Newton:
    """Estimate the condition at a converged point. Where the error model would flag the
    point as Newton left it (with the last point's max |q|, |dq|, |ddq|: ``previous``), solve
    for the Newton correction: its size is the error of q the residual leaves (to first
    order), which judges the point instead of the model's bound from the residual
    (runtime.solving.accuracy). Where the point would still be flagged, iterate on until it would
    not (or the step stalls): a point is flagged only for what iterations cannot fix. Where the
    condition is above options.tighten_cond, iterate on while the step still shrinks (each at
    most half the one before: once it stalls it is rounding noise, which a nearly singular
    Phi_q would only amplify along its null direction): q as exact as rounding allows.
    tighten_cond = inf: neither. After a step, estimate again. Above options.max_cond the
    point counts as singular."""
    result = _estimate(result)
    unit = UNIT_ROUNDOFF[getattr(kernel, "real", "double")]
    ill = result.cond > options.tighten_cond

    def would_flag(residual: float, correction: float = math.nan) -> bool:
        return residual > unit * (1.0 + previous[0]) and accuracy.flagged_norms(
            result.inv_norm, result.norm_a, residual, result.q.size, *previous, options, unit,
            correction)

    if ill or (options.tighten_cond < math.inf and would_flag(result.residual)):
        q, residual, factors = result.q, result.residual, result.factors
        assert factors is not None
        correction = math.nan
        for _ in range(TIGHTEN_STEPS):
            delta = factors.solve(-phi)
            size = float(np.abs(delta).max(initial=0.0))
            correction = size if math.isfinite(size) else math.nan
            if not ill and not would_flag(residual, correction):
                break
            if not 0 < size <= step / 2:
                break
            q = q + delta
            phi = kernel.phi(q, t, p)
            residual, step, correction = float(np.abs(phi).max(initial=0.0)), size, math.nan
            factors = factor_at(kernel, q, t, p)
            if factors.pivot_ratio < options.min_pivot_ratio:
                return Newton(q, SINGULAR, result.iterations, residual, factors)
            if not ill and not would_flag(residual):
                break
        if factors is not result.factors:
            result = _estimate_again(result, Newton(q, OK, result.iterations, residual, factors))
        result.correction = correction
    if not result.cond <= options.max_cond:
        result.status = SINGULAR
    return result


def _estimate_again(before: Newton, after: Newton) -> Newton:
    """The estimate at ``after`` from the one at ``before`` where REESTIMATE_SHIFT allows it."""
    assert before.factors is not None and after.factors is not None
    if not after.factors.exact:
        theta = before.inv_norm * distance1(after.factors, before.factors)
        if theta <= REESTIMATE_SHIFT:
            after.inv_norm, after.norm_a = before.inv_norm / (1.0 - theta), after.factors.norm1
            return after
    return _estimate(after)


def kinematics(kernel: KinematicsKernel, result: Newton, t: float, p: Array, options: Options,
               solved: int = 2) -> Point | None:
    """Velocities (2.73) and accelerations (2.74) at a converged point, with its flag; None
    when they are not finite (Phi_t or Gamma singular at t). ``solved`` < 2: an input-driven
    point whose accelerations (< 1: also rates) were not given: those are not solved for,
    stand as zeros in the error model and are not judged by it (as the generated C
    solve_inputs, given NULL, does)."""
    factors = result.factors
    assert factors is not None  # newton returns the factors whenever it converges
    q = result.q
    zeros = np.zeros_like(q)
    dq = factors.solve(-kernel.phi_t(q, t, p)) if solved >= 1 else zeros  # (2.73)
    ddq = factors.solve(kernel.gamma(q, dq, t, p)) if solved >= 2 else zeros  # (2.74)
    if not (np.all(np.isfinite(dq)) and np.all(np.isfinite(ddq))):
        return None
    unit = UNIT_ROUNDOFF[getattr(kernel, "real", "double")]
    flag = accuracy.flagged(result.inv_norm, result.norm_a, result.residual, q, dq, ddq,
                            options, unit, result.correction,
                            _propagation(kernel, factors, (q, dq, ddq), t, p, unit), solved)
    return Point(q, dq, ddq, result.cond, flag)



def _propagation(kernel: KinematicsKernel, factors: Factors | SparseFactors,
                 solved: tuple[Array, Array, Array], t: float, p: Array, unit: float
                 ) -> accuracy.Propagate:
    """The errors of dq and ddq that a position error of a given size causes at the solved
    point, along the worst direction (runtime.solving.accuracy.propagated, forward differences of
    length sqrt(u) (1 + max |q|), as the generated C takes them)."""
    q, dq, ddq = solved
    rows, cols = (np.asarray(a, dtype=np.intp) for a in (kernel.pattern_rows, kernel.pattern_cols))

    def jacobian_times(moved: Array, v: Array) -> Array:
        nz = np.asarray(kernel.phi_q_nz(moved, t, p), dtype=float)
        return np.asarray(np.bincount(rows, nz * v[cols], minlength=q.size), dtype=np.float64)

    def velocity_rows(d: Array) -> Array:
        return jacobian_times(q + d, dq) + kernel.phi_t(q + d, t, p)

    def acceleration_rows(d: Array, v: Array) -> Array:
        return kernel.gamma(q + d, dq + v, t, p) - jacobian_times(q + d, ddq)

    def propagate(size: float) -> tuple[float, float]:
        direction = accuracy.worst_column(factors.solve, factors.solve_transposed, q.size)
        step = math.sqrt(unit) * (1.0 + float(np.abs(q).max(initial=0.0)))
        return accuracy.propagated(factors.solve, direction, step=step, size=size,
                                   velocity_rows=velocity_rows,
                                   acceleration_rows=acceleration_rows)

    return propagate
