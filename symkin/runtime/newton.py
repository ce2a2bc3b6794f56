"""Positions at one time point: Newton-Raphson (2.72) and, for assembly from a poor guess,
Levenberg-Marquardt. The status codes are shared with the generated C solver."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.linalg import Factors, SparseFactors, factor_at
from symkin.runtime.options import NO_CONVERGENCE, NOT_FINITE, OK, SINGULAR, Options
from symkin.runtime.protocol import KinematicsKernel

Array = NDArray[np.float64]

@dataclass
class Newton:
    """The outcome of Newton-Raphson at one time point."""

    q: Array
    status: int
    iterations: int
    residual: float
    factors: Factors | SparseFactors | None


def newton(kernel: KinematicsKernel, q: Array, t: float, p: Array, options: Options) -> Newton:
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
        if not math.isfinite(residual):  # singular at t (first iterate), or diverged
            return Newton(q, NOT_FINITE if iteration == 0 else NO_CONVERGENCE, iteration,
                          residual, None)
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


def levenberg_marquardt(kernel: KinematicsKernel, q: Array, t: float, p: Array, options: Options,
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


def assemble(kernel: KinematicsKernel, q0: Array, t0: float, p: Array, options: Options) -> Newton:
    """Assemble the mechanism at t0 from q0: Newton, else Levenberg-Marquardt then Newton."""
    result = newton(kernel, q0, t0, p, options)
    if result.status == OK:
        return result
    q, _ = levenberg_marquardt(kernel, q0, t0, p, options)
    polished = newton(kernel, q, t0, p, options)
    polished.iterations += result.iterations
    return polished
