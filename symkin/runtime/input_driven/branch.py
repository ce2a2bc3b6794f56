"""Branch jumps of an input-driven run: where Newton may have left the assembly it tracked.

A run driven by inputs solves each point from the last solution. Where the inputs jump, or the
path passes near a singular configuration, Newton can converge to another assembly (the other
branch of a crank-slider, another of a parallel robot's assembly modes) without any sign of
trouble: the residual is as small as anywhere. Two cheap tests over consecutive rows, made
with the kernel's own Phi and Phi_q (so every backend flags the same rows):

- the sign of det(Phi_q) changes: the two solutions lie on the two sides of a singular
  configuration, which no continuous motion of one assembly crosses without passing it;
- the solution is far from Newton's first step: from the last solution q_prev, the first
  step s = -Phi_q(q_prev)^-1 Phi(q_prev, u) is the linear prediction of the motion; while
  the start lies in Newton's region of quadratic convergence the converged q differs from
  q_prev + s by far less than s (to second order in the step). Where it differs by more than
  half of s, Newton wandered: the start was outside that region, and what it found may be
  another assembly.

The generated C solve_inputs makes the same two tests at each call (report.branch_jump), with
the same constants (contract.tuning). Imports NumPy only.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.contract import tuning

Array = NDArray[np.float64]

REGION = tuning.BRANCH_REGION
"""|q - (q_prev + s)| above this fraction of |s| (the first Newton step) flags the row."""

FLOOR = tuning.BRANCH_FLOOR
"""Remainders below FLOOR (1 + max |q|) are never a jump."""


def _sign(matrix: Array) -> float:
    """The sign of det(matrix): 0 where it is singular or not finite."""
    if not np.all(np.isfinite(matrix)):
        return 0.0
    sign, _ = np.linalg.slogdet(matrix)
    return float(sign)


def _wandered(kernel: Any, before: Array, after: Array, t: float, p: Array) -> bool:
    """Whether ``after`` is farther from Newton's first step from ``before`` than its region
    of quadratic convergence allows."""
    jacobian = kernel.phi_q(before, t, p)
    try:
        step = np.linalg.solve(jacobian, -np.asarray(kernel.phi(before, t, p), dtype=float))
    except np.linalg.LinAlgError:
        return False  # singular at the last solution: the sign test judges the row
    remainder = float(np.abs(after - before - step).max(initial=0.0))
    floor = FLOOR * (1.0 + float(np.abs(after).max(initial=0.0)))
    return remainder > max(REGION * float(np.abs(step).max(initial=0.0)), floor)


def jump_rows(kernel: Any, t: Array, q: Array, rows: Array) -> NDArray[np.bool_]:
    """Which rows may be on another assembly than the row before (the first never is).

    Args:
        kernel: the run's kernel (``phi`` and ``phi_q``, either backend).
        t: (T,) the times.
        q: (T, NQ) the solutions.
        rows: (T, NP + 3 NU) each row's p[] with its inputs.
    """
    jumped = np.zeros(t.shape, dtype=bool)
    sign = _sign(kernel.phi_q(q[0], float(t[0]), rows[0])) if t.size else 0.0
    for k in range(1, t.size):
        here = _sign(kernel.phi_q(q[k], float(t[k]), rows[k]))
        crossed = here != 0.0 and sign != 0.0 and here != sign
        jumped[k] = crossed or _wandered(kernel, q[k - 1], q[k], float(t[k]), rows[k])
        sign = here if here != 0.0 else sign
    return jumped


def message(t: Array, jumped: NDArray[np.bool_]) -> str:
    """One sentence naming the rows (and their times) that may have jumped."""
    where = [f"row {k} (t = {float(t[k]):.10g})" for k in np.flatnonzero(jumped)]
    shown = ", ".join(where[:5]) + (f" and {len(where) - 5} more" if len(where) > 5 else "")
    return (f"the solution may have jumped to another assembly at {shown}: Newton from the "
            "point before converged far from its first step, or det(Phi_q) changed sign "
            "(a singular configuration lies between the two points); give inputs closer "
            "together there, or check the assembly (Trajectory.branch_jumps)")
