"""Efforts and reactions where rows were removed as redundant: which are determinate, and the
minimum-norm multipliers for the rest.

The generated ``multipliers`` solve Phi_q^T lam = rhs with the kept rows only, which is one
solution of the file's whole system Phi_full_q^T lam_full = rhs (the removed rows' multipliers
taken as zero). Phi_full_q has rank N with N + R rows, so the solutions are

    lam_full = lam0 + Z a,    Z = [-C; I_R],   Phi_q^T C = Phi_removed_q^T

(column r of Z: removed row r as the combination C[:, r] of the kept rows, less itself: a
self-stress, constraint forces that balance each other and do no work). A load is linear in
lam_full, load = loads_full(lam_full), so it is *determinate* where loads_full(Z) is zero —
the same for every solution — and otherwise it depends on how the redundant rows share
the load. The minimum 2-norm solution is lam0 less its projection on the span of Z; its
loads are reported, those that are not determinate marked so. For revolute joints lam is
the reaction force itself (the driver rows': minus the effort), so the norm is that of the
bearing forces and motor efforts.

The generated code evaluates the removed rows' Jacobian (``removed_q``) and the loads of a
whole lam_full (``loads_full``); the small dense algebra here is NumPy, per solved row. Part
of the runtime: imports NumPy only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

DETERMINATE_TOLERANCE = 1e-8
"""A load is taken as changing over the solutions where loads_full of an orthonormal null
vector exceeds this much of the largest such value at that point: a determinate one is
rounding (about 1e-16 of it), an indeterminate one of the order of the geometry."""


@dataclass(frozen=True)
class Completion:
    """The minimum-norm multipliers of a trajectory's rows and which loads are determinate.

    Attributes:
        multipliers: (T, N) the kept rows' multipliers of the minimum-norm solution.
        removed_multipliers: (T, R) the removed rows' multipliers of that solution.
        loads: (T, NLOADS) the efforts, then Fx, Fy, M of each joint, from that solution.
        determinate: (NLOADS,) True for a load that is the same for every solution at every
            solved point (NaN rows, where Phi_q is singular, do not count).
    """

    multipliers: Array
    removed_multipliers: Array
    loads: Array
    determinate: NDArray[np.bool_]


def complete(kernel: Any, t: Array, q: Array, p: Array, lam: Array, loads: Array
             ) -> Completion:
    """The minimum-norm completion of the kept rows' multipliers ``lam`` (T, N) and their
    ``loads`` (T, NLOADS), along the solved rows t, q at parameters p."""
    n, count = lam.shape[1], len(kernel.removed)
    whole = np.full((t.size, n + count), np.nan)
    out = np.full(loads.shape, np.nan)
    varies = np.zeros(loads.shape[1], dtype=bool)
    for k in range(t.size):
        if not np.isfinite(lam[k]).all():
            continue
        null = _null_space(kernel, q[k], float(t[k]), p)
        if null is None:
            continue
        start = np.concatenate([lam[k], np.zeros(count)])
        whole[k] = start - null @ (null.T @ start)
        out[k] = kernel.loads_full(q[k], whole[k], t[k], p)
        varies |= _varying(kernel, q[k], float(t[k]), p, null)
    return Completion(whole[:, :n], whole[:, n:], out, ~varies)


def _null_space(kernel: Any, q: Array, t: float, p: Array) -> Array | None:
    """An orthonormal basis (N + R, R) of the null space of Phi_full_q^T; None where the kept
    rows' Phi_q is singular."""
    kept = kernel.phi_q(q, t, p)
    removed = kernel.removed_q(q, t, p)
    try:
        combination = np.linalg.solve(kept.T, removed.T)
    except np.linalg.LinAlgError:
        return None
    basis = np.vstack([-combination, np.eye(removed.shape[0])])
    orthonormal, _ = np.linalg.qr(basis)
    return np.asarray(orthonormal, dtype=float)


def _varying(kernel: Any, q: Array, t: float, p: Array, null: Array) -> NDArray[np.bool_]:
    """(NLOADS,) the loads that change along the null space at this point."""
    change = np.abs(np.array([kernel.loads_full(q, null[:, r], t, p)
                              for r in range(null.shape[1])]))
    largest = float(change.max(initial=0.0))
    return np.asarray((change > DETERMINATE_TOLERANCE * largest).any(axis=0))
