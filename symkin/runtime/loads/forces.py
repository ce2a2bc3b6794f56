"""Efforts and reactions along a solved trajectory (inverse dynamics), from the kernel's
generated ``multipliers``: Φ_qᵀ λ = Q - M q̈ - h at every solved row.

``effort`` (T, n_driver_equations): -λ of each driver row, the generalized force its actuator
applies along the driver's function (an ``angle`` driver: the torque on body i, -effort on
j; a ``slide``: the force on body j along u). ``reaction`` (T, n_joints, 3): [Fx, Fy]
(global) and M that body i exerts on body j, M about the joint's point on body i (0 for a
revolute; a prismatic pair: about A, carried by i). A spatial mechanism's ``reaction`` is
(T, n_joints, 6): [Fx, Fy, Fz, Mx, My, Mz], the same, in global components
(:mod:`symkin.contract.loads`). Rows where Φ_q is exactly singular are NaN.

Where rows were removed as redundant, the loads are those of the minimum-norm multipliers of
every row the file writes, and ``determinate`` says which are unique (runtime.loads.indeterminate).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.contract.loads import load_count, reaction_parts
from symkin.runtime.loads import indeterminate

Array = NDArray[np.float64]
REACTION_PARTS = reaction_parts("2d")


@dataclass(frozen=True)
class Forces:
    """The inverse dynamics of a trajectory's rows."""

    multipliers: Array  # (T, N): lambda
    effort: Array  # (T, n_driver_equations)
    reaction: Array  # (T, n_joints, 3): Fx, Fy, M (spatial: 6, Fx ... Mz)
    driver_names: tuple[str, ...]
    joint_names: tuple[str, ...]
    parts: tuple[str, ...] = REACTION_PARTS
    """The components of a reaction (contract.loads)."""
    determinate: NDArray[np.bool_] | None = None
    """(NLOADS,) where rows were removed as redundant: True for an effort or reaction
    component that is the same whatever the split among the redundant rows; the others are
    the minimum-norm solution's. None for every other file (all determinate)."""
    removed_multipliers: Array | None = None
    """(T, R) the removed rows' multipliers of the minimum-norm solution, or None."""

    @property
    def effort_determinate(self) -> NDArray[np.bool_] | None:
        """(n_driver_equations,) bool, or None where no row was removed."""
        if self.determinate is None:
            return None
        return self.determinate[:len(self.driver_names)]

    @property
    def reaction_determinate(self) -> NDArray[np.bool_] | None:
        """(n_joints, 3) bool (Fx, Fy, M; spatial: 6, Fx ... Mz), or None where no row was
        removed."""
        if self.determinate is None:
            return None
        return self.determinate[len(self.driver_names):].reshape(len(self.joint_names),
                                                                  len(self.parts))

    def indeterminate(self) -> list[str]:
        """The :meth:`columns` names of the loads that are not determinate."""
        if self.determinate is None:
            return []
        return [name for name, fixed in zip(self.columns(), self.determinate) if not fixed]

    def columns(self) -> list[str]:
        """The CSV columns: ``DRIVER.effort``, then ``JOINT.Fx``, ``JOINT.Fy``, ``JOINT.M``
        (spatial: ``JOINT.Fx`` ... ``JOINT.Mz``)."""
        return [f"{name}.effort" for name in self.driver_names] + [
            f"{name}.{part}" for name in self.joint_names for part in self.parts]

    def not_finite(self) -> NDArray[np.bool_]:
        """(T,) True where an effort or a reaction is inf or NaN: a load of the file that is
        infinite or undefined there (a force 1/(t - 0.5) at t = 0.5), or Phi_q singular."""
        return np.asarray(~np.isfinite(self.table()).all(axis=1))

    def not_finite_columns(self, rows: NDArray[np.bool_]) -> list[str]:
        """The :meth:`columns` that are inf or NaN in any of ``rows`` ((T,) bool)."""
        bad = np.asarray(~np.isfinite(self.table()[rows]).all(axis=0))
        return [name for name, flag in zip(self.columns(), bad) if flag]

    def table(self) -> Array:
        """The values of :meth:`columns`, (T, n_driver_equations + 3 n_joints)."""
        rows = self.effort.shape[0]
        return np.column_stack([self.effort, self.reaction.reshape(rows, -1)])


def allocate(kernel: Any, size: int) -> tuple[Array, Array] | None:
    """NaN-filled (lam, loads) rows for a grid loop that computes them as it goes (the
    generated C solver); None for a kernel without dynamics."""
    if not getattr(kernel, "has_dynamics", False):
        return None
    n_loads = load_count(len(kernel.driver_names), len(kernel.joint_names), kernel.space)
    return np.full((size, len(kernel.coordinates)), np.nan), np.full((size, n_loads), np.nan)


def grid(kernel: Any) -> Any:
    """The kernel's ``multipliers_grid`` (t, q, dq, d2q, p) -> (lam, loads); where rows were
    removed as redundant, the minimum-norm ones (as :func:`compute` gives a run)."""
    if not getattr(kernel, "removed", ()):
        return kernel.multipliers_grid

    def minimum_norm(t: Array, q: Array, dq: Array, d2q: Array, p: Array
                     ) -> tuple[Array, Array]:
        found = compute(kernel, t, q, dq, d2q, p)
        if found is None:  # a kernel without dynamics: there is nothing to complete
            raise ValueError(f"{kernel.name} has no masses or forces")
        return found.multipliers, found.table()
    return minimum_norm


def compute(kernel: Any, t: Array, q: Array, dq: Array, d2q: Array, p: Array,
            given: tuple[Array, ...] | None = None) -> Forces | None:
    """The efforts and reactions of solved rows; None for a kernel without dynamics.

    ``given``: (lam, loads) the grid loop already wrote; only the rows it did not (NaN: points
    the runtime's edge treatment solved) are computed here. ``p``: the kernel's p[] of every
    row, or (T, NP + 3 NU) each row's own (a run driven by inputs).
    """
    if not getattr(kernel, "has_dynamics", False):
        return None
    with np.errstate(all="ignore"):  # a singular row is NaN, said in the docstring
        if given is None:
            lam, loads = _grid(kernel, t, q, dq, d2q, p)
        else:
            lam, loads = given[0].copy(), given[1].copy()
            missing = np.flatnonzero(np.isnan(lam).any(axis=1))
            if missing.size:
                lam[missing], loads[missing] = kernel.multipliers_grid(
                    t[missing], q[missing], dq[missing], d2q[missing], p)
    determinate, removed = None, None
    if getattr(kernel, "removed", ()):  # rows removed as redundant: not unique
        with np.errstate(all="ignore"):
            found = indeterminate.complete(kernel, t, q, p, lam, loads)
        lam, loads = found.multipliers, found.loads
        determinate, removed = found.determinate, found.removed_multipliers
    n_efforts, n_joints = len(kernel.driver_names), len(kernel.joint_names)
    parts = reaction_parts(kernel.space)
    return Forces(lam, loads[:, :n_efforts],
                  loads[:, n_efforts:].reshape(t.size, n_joints, len(parts)),
                  tuple(kernel.driver_names), tuple(kernel.joint_names), parts, determinate,
                  removed)


def _grid(kernel: Any, t: Array, q: Array, dq: Array, d2q: Array,
          p: Array) -> tuple[Array, Array]:
    """The kernel's multipliers_grid, row by row where each row has its own p[]."""
    if p.ndim == 1 or t.size == 0:
        lam, loads = kernel.multipliers_grid(t, q, dq, d2q, p if p.ndim == 1 else kernel.p_values)
        return lam, loads
    rows = [kernel.multipliers_grid(t[k:k + 1], q[k:k + 1], dq[k:k + 1], d2q[k:k + 1], p[k])
            for k in range(t.size)]
    return np.concatenate([lam for lam, _ in rows]), np.concatenate([out for _, out in rows])
