"""Positions at one time point: Newton-Raphson (2.72) and, for assembly from a poor guess,
Levenberg-Marquardt. The status codes are shared with the generated C solver."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.linalg import Factors, SparseFactors, factor_at

Array = NDArray[np.float64]

# Status codes shared with the generated C solver (templates/c/solver.h.j2).
OK, NO_CONVERGENCE, SINGULAR = 0, 1, 2


@dataclass(frozen=True)
class Options:
    """Newton tolerances and the singularity test.

    Args:
        tol_phi: converged when max |Phi| of the current iterate is at most this...
        tol_dq: ...and the last Newton step max |dq| is at most this.
        max_iterations: Newton iterations allowed per time point.
        min_pivot_ratio: Phi_q counts as singular when min |u_kk| / max |u_kk| of its LU
            factors falls below this (a cheap estimate of the reciprocal condition number).
    """

    tol_phi: float = 1e-10
    tol_dq: float = 1e-9
    max_iterations: int = 25
    min_pivot_ratio: float = 1e-10


# The defaults per real type, defined once: the generated C's <prefix>_default_options is
# rendered from this table (codegen.render), so Python and C can never disagree.
DEFAULTS = {
    "double": Options(),
    "float": Options(tol_phi=1e-5, tol_dq=1e-4, min_pivot_ratio=1e-6),
}


def defaults(real: str) -> Options:
    """The Newton options for a kernel computing in ``real`` ("double" or "float")."""
    return DEFAULTS[real]


@dataclass
class Newton:
    """The outcome of Newton-Raphson at one time point."""

    q: Array
    status: int
    iterations: int
    residual: float
    factors: Factors | SparseFactors | None


def newton(kernel: Any, q: Array, t: float, p: Array, options: Options) -> Newton:
    """Newton-Raphson that tests the residual of the current iterate (2.72).

    Converged when max |Phi(q_k)| <= tol_phi and the step that led to q_k was at most tol_dq
    (or no step was needed). The factors returned are those of Phi_q at the converged q, ready
    for the velocity and acceleration solves.
    """
    q = np.array(q, dtype=float)
    step = math.inf
    for iteration in range(options.max_iterations + 1):
        phi = kernel.phi(q, t, p)
        residual = float(np.abs(phi).max(initial=0.0))
        if not math.isfinite(residual):
            return Newton(q, NO_CONVERGENCE, iteration, residual, None)
        factors = factor_at(kernel, q, t, p)
        if factors.pivot_ratio < options.min_pivot_ratio:
            return Newton(q, SINGULAR, iteration, residual, factors)
        if residual <= options.tol_phi and (iteration == 0 or step <= options.tol_dq):
            return Newton(q, OK, iteration, residual, factors)
        if iteration == options.max_iterations:
            break
        delta = factors.solve(-phi)
        q += delta
        step = float(np.abs(delta).max(initial=0.0))
    return Newton(q, NO_CONVERGENCE, options.max_iterations, residual, None)


def levenberg_marquardt(kernel: Any, q: Array, t: float, p: Array, options: Options,
                        max_iterations: int = 200) -> tuple[Array, float]:
    """Minimise |Phi(q, t)|^2 from a poor guess; returns the best q and its max |Phi|.

    Each step solves (J^T J + mu I) dq = -J^T Phi; mu shrinks after a step that lowers the
    residual and grows otherwise, so the method moves like Newton near a solution and like
    gradient descent far from one. It works where Phi_q is singular (e.g. q = 0).
    """
    q = np.array(q, dtype=float)
    phi = kernel.phi(q, t, p)
    cost = float(phi @ phi)
    mu = 1e-3
    for _ in range(max_iterations):
        if math.sqrt(cost) <= options.tol_phi:
            break
        jacobian = kernel.phi_q(q, t, p)
        normal = jacobian.T @ jacobian
        gradient = jacobian.T @ phi
        scale = mu * max(float(np.max(np.diag(normal))), 1.0)
        delta = np.linalg.solve(normal + scale * np.eye(q.size), -gradient)
        trial = q + delta
        trial_phi = kernel.phi(trial, t, p)
        trial_cost = float(trial_phi @ trial_phi)
        if math.isfinite(trial_cost) and trial_cost < cost:
            q, phi, cost, mu = trial, trial_phi, trial_cost, max(mu / 10, 1e-12)
        else:
            mu *= 10
            if mu > 1e12:
                break
    return q, float(np.abs(phi).max(initial=0.0))


def assemble(kernel: Any, q0: Array, t0: float, p: Array, options: Options) -> Newton:
    """Assemble the mechanism at t0 from q0: Newton, else Levenberg-Marquardt then Newton."""
    result = newton(kernel, q0, t0, p, options)
    if result.status == OK:
        return result
    q, _ = levenberg_marquardt(kernel, q0, t0, p, options)
    polished = newton(kernel, q, t0, p, options)
    polished.iterations += result.iterations
    return polished
