"""A SymPy-lambdify driver: symkin's derived System turned into NumPy callables by lambdify.

This is what a user gets without code generation: lambdify System.phi, phi_q, phi_t and gamma
and run the chapter's loop (predictor 2.76, Newton, velocity 2.73, acceleration 2.74) in Python.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import sympy as sp

from symkin.symbolic import derivation

TOLERANCE = 1e-10
MAX_ITERATIONS = 25


def lambdified(system: derivation.System) -> dict[str, Callable[..., np.ndarray]]:
    """phi(q, t), phi_q(q, t), phi_t(q, t), gamma(q, dq, t) at the nominal parameters."""
    values = dict(zip(system.p, system.p_values))
    q, dq, t = sp.Matrix(system.q), sp.Matrix(system.dq), system.t

    def make(args: list, expr: sp.MatrixBase) -> Callable[..., np.ndarray]:
        return sp.lambdify(args, sp.Matrix(expr).subs(values), "numpy")

    return {"phi": make([q, t], system.phi), "phi_q": make([q, t], sp.Matrix(system.phi_q)),
            "phi_t": make([q, t], system.phi_t), "gamma": make([q, dq, t], system.gamma)}


def solve_grid(functions: dict[str, Callable[..., np.ndarray]], times: np.ndarray,
               q0: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The chapter's loop over the grid; raises RuntimeError when Newton does not converge."""
    n = len(q0)
    phi, phi_q, phi_t, gamma = (functions[k] for k in ("phi", "phi_q", "phi_t", "gamma"))
    q, dq, d2q = np.array(q0, dtype=float), np.zeros(n), np.zeros(n)
    out = np.zeros((3, len(times), n))
    previous = times[0]
    for k, t in enumerate(times):
        h = t - previous
        previous = t
        q = q + dq * h + 0.5 * d2q * h * h
        for _ in range(MAX_ITERATIONS):
            residual = phi(q, t).ravel()
            if np.linalg.norm(residual) <= TOLERANCE:
                break
            q = q - np.linalg.solve(phi_q(q, t), residual)
        else:
            raise RuntimeError(f"Newton did not converge at t = {t}")
        jacobian = phi_q(q, t)
        dq = np.linalg.solve(jacobian, -phi_t(q, t).ravel())
        d2q = np.linalg.solve(jacobian, gamma(q, dq, t).ravel())
        out[:, k] = q, dq, d2q
    return out[0], out[1], out[2]


def derive(path: str | Path) -> dict[str, Callable[..., np.ndarray]]:
    return lambdified(derivation.derive(path))
