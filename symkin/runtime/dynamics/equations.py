"""The accelerations and multipliers of one state of a mechanism its forces move.

Index-1 form of the equations of motion (REFERENCE.md, "forces"):

    [M    Φ_qᵀ] [q̈]   [Q - h]
    [Φ_q  0   ] [λ] = [Γ    ]

The matrix is regular when Φ_q has full row rank and M is positive definite on the
freedoms Φ_q leaves open (a body without mass in a free direction makes it singular); its
condition number is what flags a row, as Φ_q's does in kinematics.

Redundant constraints (a parallelogram's extra bar, Bricard's linkage) leave Φ_q short of
row rank by ``deficiency`` everywhere, and a singular configuration (a change point) near
a state makes it nearly so: q̈ is still unique, λ is not. Such states are solved through
the singular value decomposition of Φ_q (:func:`revealed`), its rank judged at every
call, which gives the unique q̈ and the minimum-norm λ (the reactions' determinacy:
runtime.dynamics.run); the condition number is taken over the rank Φ_q has at t0.
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
                  redundant: int = 0, revealing: bool = False) -> Accelerations:
    """Solve the equations of motion at (q, dq, t); :class:`Singular` where they have no
    unique q̈. ``redundant`` (rows of Φ_q dependent at t0) or ``revealing`` (a singular
    configuration near) take the rank-revealing solve (:func:`revealed`); otherwise an LU
    solve of the augmented matrix, falling back to the rank-revealing one where LU fails."""
    if redundant or revealing:
        d2q, lam = revealed(model, q, dq, t, p)
    else:
        matrix, rhs, _ = augmented(model, q, dq, t, p)
        try:
            solution = np.asarray(np.linalg.solve(matrix, rhs), dtype=np.float64)
        except np.linalg.LinAlgError:
            solution = np.concatenate(revealed(model, q, dq, t, p))
        d2q, lam = solution[:q.size], solution[q.size:]
    if not (np.all(np.isfinite(d2q)) and np.all(np.isfinite(lam))):
        raise Singular("the accelerations are not finite")
    # dW/dt: the non-conservative forces' power and the drivers' (λᵀ Φ_t, symbolic.motion)
    power = float(model.nonconservative(q, dq, t, p) @ dq + lam @ model.phi_t(q, t, p))
    return Accelerations(d2q, lam, power)


# The floor, as a share of Φ_q's largest singular value, below which the rank-revealing
# solve damps a direction of Φ_q rather than inverting it (Σ⁺ becomes sigma / (sigma² +
# floor²)), and which the projections leave out. The SVD solve is what passes the A02
# chain's change points at rtol 1e-8; with this floor and the projections' cut it also
# passes them at rtol = atol = 1e-10 (without, it stopped at t = 8.998). The size is from
# trials on that chain: 1e-9 to 3e-9 passed rtol 1e-6, 1e-8 and 1e-10 within 2e-8 of the
# crank's one-coordinate equation; 3e-10 and 1e-8 stopped at 1e-10; 3e-8 and above jumped
# to the other branch. At rtol 1e-10 with atol 1e-12 the chain still stops at t = 0.714.
TRUNCATION = 2e-9
# A dropped direction of Φ_q whose row of Γ is larger than this share of the kept rows'
# scale asks an acceleration Φ_q cannot give there: a lock-up, not a passage.
LOCKUP = 1e-2


def revealed(model: Model, q: Array, dq: Array, t: float, p: Array) -> tuple[Array, Array]:
    """q̈ and λ by the singular value decomposition Φ_q = U Σ Vᵀ, the directions of Φ_q
    below RANK_TOLERANCE (dependent rows) dropped, those below TRUNCATION damped.

    Why near a singular configuration: the augmented matrix's condition grows as
    1/sigma_min² there (its multiplier block is Φ_q M⁻¹ Φ_qᵀ), so an LU solve of it loses
    every digit at sigma_min = 1e-8, and that noise in q̈ drove the error control's steps
    down to 1e-11 s: the IFToMM A02 chain stopped at t = 6.54 (rtol 1e-8) with "the step
    size fell below its minimum". Through Φ_q's orthonormal bases the error grows as
    1/sigma_min only, and the chain passes (tests/motion/test_dynamics_singular.py).

    q̈ = Y Σ⁻¹ Uᵀ Γ + Z z, Y the kept right singular vectors, Z the rest (the freedoms, with
    the directions a singular configuration adds); (Zᵀ M Z) z = Zᵀ (Q - h - M Y Σ⁻¹ Uᵀ Γ)
    is the motion in the freedoms; λ = U Σ⁻¹ Yᵀ (Q - h - M q̈), the dropped left vectors'
    multipliers zero (the minimum-norm λ of redundant rows). Only pure-multiplier
    directions are dropped so: a dropped direction moves no q̈ unless it leaves Zᵀ M Z
    singular (a free direction without mass) or Γ has a row there Φ_q cannot meet (a
    lock-up): both raise :class:`Singular`."""
    jacobian = model.phi_q(q, t, p)
    mass, force = model.mass(q, p), model.applied(q, dq, t, p)
    gamma = model.gamma(q, dq, t, p)
    u, s, vt = np.linalg.svd(jacobian)
    kept = int(np.count_nonzero(s > RANK_TOLERANCE * s[0])) if s.size else 0
    sk = s[:kept]
    floor = TRUNCATION * (s[0] if s.size else 0.0)
    inverse = sk / (sk * sk + floor * floor)  # smooth: no jump in q̈ for the error control
    given = u[:, :kept].T @ gamma
    if kept < jacobian.shape[0]:
        scale = float(np.abs(given * inverse).max(initial=0.0)) * s[0] + float(
            np.abs(gamma).max())
        asked = float(np.abs(u[:, kept:].T @ gamma).max())
        if asked > LOCKUP * scale and asked > 0.0:
            raise Singular("a lock-up: the constraints ask an acceleration they cannot give")
    d2q = vt[:kept].T @ (given * inverse)
    free = vt[kept:].T
    try:
        d2q = d2q + free @ np.linalg.solve(free.T @ mass @ free,
                                           free.T @ (force - mass @ d2q))
    except np.linalg.LinAlgError:
        raise Singular("a free direction without mass") from None
    lam = u[:, :kept] @ (vt[:kept] @ (force - mass @ d2q) * inverse)
    return d2q, lam


def condition(model: Model, q: Array, dq: Array, t: float, p: Array,
              redundant: int = 0) -> float:
    """The 2-norm condition number of the augmented matrix over its rank less the
    ``redundant`` rows' (inf where singular)."""
    matrix, _, _ = augmented(model, q, dq, t, p)
    values = np.linalg.svd(matrix, compute_uv=False)
    smallest = values[values.size - 1 - redundant]
    return float(values[0] / smallest) if smallest > 0 else float("inf")
