"""Newton-Raphson and Levenberg-Marquardt on dense Jacobians: plain NumPy/SciPy numerics for
any Phi(q, t, p) and Phi_q(q, t, p), with the tolerances of :class:`Options`. The runtime's
assembly and scan use :func:`levenberg_marquardt` from a poor guess; the generation-time
sample (codegen.sample) assembles a mechanism with both, before any kernel is compiled."""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options

Array = NDArray[np.float64]


class Equations(Protocol):
    """The constraint equations and their dense Jacobian at (q, t) with parameters p."""

    def phi(self, q: Array, t: float, p: ArrayLike | None = None) -> Array: ...
    def phi_q(self, q: Array, t: float, p: ArrayLike | None = None) -> Array: ...


def newton(equations: Equations, q: Array, t: float, p: Array, options: Options
           ) -> Array | None:
    """Newton-Raphson testing the residual of the iterate: the converged q, or None when it
    fails or Phi_q is singular (pivot ratio of the LU factors below options.min_pivot_ratio)."""
    import scipy.linalg

    q = np.array(q, dtype=float)
    step = math.inf
    for iteration in range(options.max_iterations + 1):
        phi = equations.phi(q, t, p)
        residual = float(np.abs(phi).max(initial=0.0))
        if not math.isfinite(residual):
            return None
        lu, pivots = scipy.linalg.lu_factor(equations.phi_q(q, t, p), check_finite=False)
        diagonal = np.abs(np.diag(lu))
        largest = diagonal.max(initial=0.0)
        if largest == 0.0 or diagonal.min() / largest < options.min_pivot_ratio:
            return None
        if residual <= options.tol_phi and (iteration == 0 or step <= options.tol_dq):
            return q
        delta = scipy.linalg.lu_solve((lu, pivots), -phi, check_finite=False)
        q = q + delta
        step = float(np.abs(delta).max(initial=0.0))
    return None


def levenberg_marquardt(equations: Equations, q: Array, t: float, p: Array, options: Options,
                        max_iterations: int = 200) -> tuple[Array, float]:
    """Minimise |Phi(q, t)|^2 from a poor guess; returns the best q and its max |Phi|.

    Each step solves (J^T J + mu I) dq = -J^T Phi; mu shrinks after a step that lowers the
    residual and grows otherwise, so the method moves like Newton near a solution and like
    gradient descent far from one. It works where Phi_q is singular (e.g. q = 0).
    """
    q = np.array(q, dtype=float)
    phi = equations.phi(q, t, p)
    cost = float(phi @ phi)
    mu = 1e-3
    for _ in range(max_iterations):
        if math.sqrt(cost) <= options.tol_phi:
            break
        jacobian = equations.phi_q(q, t, p)
        normal = jacobian.T @ jacobian
        gradient = jacobian.T @ phi
        scale = mu * max(float(np.max(np.diag(normal))), 1.0)
        delta = np.linalg.solve(normal + scale * np.eye(q.size), -gradient)
        trial = q + delta
        trial_phi = equations.phi(trial, t, p)
        trial_cost = float(trial_phi @ trial_phi)
        if math.isfinite(trial_cost) and trial_cost < cost:
            q, phi, cost, mu = trial, trial_phi, trial_cost, max(mu / 10, 1e-12)
        else:
            mu *= 10
            if mu > 1e12:
                break
    return q, float(np.abs(phi).max(initial=0.0))
