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
    rows = np.flatnonzero(np.isfinite(lam).all(axis=1))
    null = _null_spaces(kernel, t[rows], q[rows], p)
    for k, basis in zip(rows, null):
        if basis is None:  # the kept rows' Phi_q is singular here: no unique completion
            continue
        # the loads of each null vector: linear in lam, so the solution's loads follow too
        change = np.array([kernel.loads_full(q[k], basis[:, r], t[k], p)
                           for r in range(count)])
        start = np.concatenate([lam[k], np.zeros(count)])
        along = basis.T @ start
        whole[k] = start - basis @ along
        out[k] = loads[k] - along @ change
        varies |= _varying(change)
    return Completion(whole[:, :n], whole[:, n:], out, ~varies)


def _null_spaces(kernel: Any, t: Array, q: Array, p: Array) -> list[Array | None]:
    """Per row, an orthonormal basis (N + R, R) of the null space of Phi_full_q^T, all rows
    in one batched solve and QR; None where the kept rows' Phi_q is singular."""
    kept = np.array([kernel.phi_q(q[k], t[k], p).T for k in range(t.size)])
    removed = np.array([kernel.removed_q(q[k], t[k], p).T for k in range(t.size)])
    if t.size == 0:
        return []
    try:
        combination = np.linalg.solve(kept, removed)
    except np.linalg.LinAlgError:  # some row is singular: those alone go without
        return [_null_space(a, b) for a, b in zip(kept, removed)]
    count = removed.shape[2]
    identity = np.broadcast_to(np.eye(count), (t.size, count, count))
    orthonormal, _ = np.linalg.qr(np.concatenate([-combination, identity], axis=1))
    return list(orthonormal)


def _null_space(kept_t: Array, removed_t: Array) -> Array | None:
    """One row's basis (:func:`_null_spaces`) from Phi_q^T and the removed rows' Jacobian^T."""
    try:
        combination = np.linalg.solve(kept_t, removed_t)
    except np.linalg.LinAlgError:
        return None
    orthonormal, _ = np.linalg.qr(np.vstack([-combination, np.eye(removed_t.shape[1])]))
    return np.asarray(orthonormal, dtype=float)


def _varying(change: Array) -> NDArray[np.bool_]:
    """(NLOADS,) the loads that change along the null space at a point, from the loads of
    its orthonormal null vectors (R, NLOADS)."""
    size = np.abs(change)
    largest = float(size.max(initial=0.0))
    return np.asarray((size > DETERMINATE_TOLERANCE * largest).any(axis=0))
