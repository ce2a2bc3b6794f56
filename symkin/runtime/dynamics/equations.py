"""The accelerations and multipliers of one state of a mechanism its forces move.

Index-1 form of the equations of motion (REFERENCE.md, "forces"):

    [M    Φ_qᵀ] [q̈]   [Q - h]
    [Φ_q  0   ] [λ] = [Γ    ]

The matrix is regular when Φ_q has full row rank and M is positive definite on the
freedoms Φ_q leaves open (a body without mass in a free direction makes it singular); its
condition number is what flags a row, as Φ_q's does in kinematics.

Redundant constraints (a parallelogram's extra bar, Bricard's linkage) leave Φ_q short of
row rank by ``deficiency`` everywhere: q̈ is still unique, λ is not. Such a mechanism is
solved by least squares, which gives the unique q̈ and the minimum-norm λ (the reactions'
determinacy: runtime.dynamics.run), and its condition number is taken over the rank it has.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.dynamics.model import Model

Array = NDArray[np.float64]

# Above this condition number of the augmented matrix a row's accelerations may miss the
# accuracy target: flagged (a lock-up or a limit position near).
FLAG_CONDITION = 1e10


class Singular(Exception):
    """The augmented matrix is singular at this state (no unique q̈, λ)."""


@dataclass(frozen=True)
class Accelerations:
    """q̈ and λ of one state, and the power of the non-conservative forces and drivers."""

    d2q: Array
    lam: Array
    power: float


def augmented(model: Model, q: Array, dq: Array, t: float, p: Array
              ) -> tuple[Array, Array, Array]:
    """[M Φ_qᵀ; Φ_q 0], its right-hand side [Q - h; Γ], and Φ_q."""
    jacobian = model.phi_q(q, t, p)
    m, n = jacobian.shape
    matrix = np.zeros((n + m, n + m))
    matrix[:n, :n] = model.mass(q, p)
    matrix[:n, n:] = jacobian.T
    matrix[n:, :n] = jacobian
    rhs = np.concatenate([model.applied(q, dq, t, p), model.gamma(q, dq, t, p)])
    return matrix, rhs, jacobian


# Singular values below this share of the largest count as zero (the rank of Φ_q at t0).
RANK_TOLERANCE = 1e-10


def deficiency(model: Model, q: Array, t: float, p: Array) -> int:
    """How many rows of Φ_q at (q, t) depend on the others (0 for most mechanisms)."""
    jacobian = model.phi_q(q, t, p)
    if jacobian.size == 0:
        return 0
    values = np.linalg.svd(jacobian, compute_uv=False)
    return int(jacobian.shape[0] - np.count_nonzero(values > RANK_TOLERANCE * values[0]))


def accelerations(model: Model, q: Array, dq: Array, t: float, p: Array,
                  redundant: int = 0) -> Accelerations:
    """Solve the equations of motion at (q, dq, t); :class:`Singular` where they have no
    unique solution. ``redundant``: the rows of Φ_q that depend on the others (module
    docstring)."""
    matrix, rhs, _ = augmented(model, q, dq, t, p)
    n = q.size
    try:
        if redundant:
            found = np.linalg.lstsq(matrix, rhs, rcond=RANK_TOLERANCE)
            if found[2] < matrix.shape[0] - redundant:
                raise Singular  # short of rank by more than the redundant rows
            solution = np.asarray(found[0], dtype=np.float64)
        else:
            solution = np.asarray(np.linalg.solve(matrix, rhs), dtype=np.float64)
    except np.linalg.LinAlgError:
        raise Singular from None
    if not np.all(np.isfinite(solution)):
        raise Singular
    lam = solution[n:]
    # dW/dt: the non-conservative forces' power and the drivers' (λᵀ Φ_t, symbolic.motion)
    power = float(model.nonconservative(q, dq, t, p) @ dq + lam @ model.phi_t(q, t, p))
    return Accelerations(solution[:n], lam, power)


def condition(model: Model, q: Array, dq: Array, t: float, p: Array,
              redundant: int = 0) -> float:
    """The 2-norm condition number of the augmented matrix over its rank less the
    ``redundant`` rows' (inf where singular)."""
    matrix, _, _ = augmented(model, q, dq, t, p)
    values = np.linalg.svd(matrix, compute_uv=False)
    smallest = values[values.size - 1 - redundant]
    return float(values[0] / smallest) if smallest > 0 else float("inf")
