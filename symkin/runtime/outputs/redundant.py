"""The rows of an over-constrained file removed at t0 (symbolic.redundancy), checked along the
motion: they were dependent on the kept rows at t0, and stay satisfied wherever the file's
joints really repeat each other; where they do not (an extra bar whose length is slightly
off, two drivers that agree at t0 only), the solved motion breaks them, and those points are
flagged.

A removed row's residual is compared with the position accuracy target, as the flag model of
runtime.solving.accuracy compares the estimated error of q: |Phi_removed| > target_q max(1, max
|q|). Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.protocol import KinematicsKernel


def check(kernel: KinematicsKernel, trajectory: Trajectory, options: Options) -> Trajectory:
    """The trajectory with the removed rows' residuals (``removed_residual``, (T, R)) and
    their labels (``removed``); points where one exceeds the target are added to ``flagged``
    (in place: the flags are this run's). A kernel without removed rows changes nothing."""
    labels = tuple(getattr(kernel, "removed", ()))
    if not labels:
        return trajectory
    residual = residuals(kernel, trajectory)
    broken = exceeded(residual, trajectory.q, options.target_q)
    trajectory.flagged[:] = trajectory.flagged | broken.any(axis=1)
    return dataclasses.replace(trajectory, removed=labels, removed_residual=residual)


def residuals(kernel: KinematicsKernel, trajectory: Trajectory) -> NDArray[np.float64]:
    """Phi of the removed rows at every solved point, shape (T, R)."""
    rows = [kernel.removed_phi(q, float(t), trajectory.params)  # type: ignore[attr-defined]
            for t, q in zip(trajectory.t, trajectory.q)]
    count = len(getattr(kernel, "removed", ()))
    return np.array(rows, dtype=float).reshape(trajectory.t.size, count)


def exceeded(residual: NDArray[np.float64], q: NDArray[np.float64], target: float
             ) -> NDArray[np.bool_]:
    """(T, R): where a removed row misses the position target (NaN counts as missing)."""
    scale = np.maximum(1.0, np.abs(q).max(axis=1, initial=0.0)) if q.size else np.ones(0)
    with np.errstate(invalid="ignore"):
        within = np.abs(residual) <= target * scale[:, None]
    return ~within


def holds(kernel: KinematicsKernel, q: NDArray[np.float64], t: float,
          p: NDArray[np.float64], target: float) -> bool:
    """Whether the removed rows (if any) meet the position target at one configuration."""
    if not getattr(kernel, "removed", ()):
        return True
    residual = kernel.removed_phi(q, t, p)  # type: ignore[attr-defined]
    return not bool(exceeded(np.reshape(residual, (1, -1)), np.reshape(q, (1, -1)),
                             target).any())


def violated(trajectory: Trajectory, target: float) -> tuple[str, ...]:
    """The labels of the removed rows that miss the target somewhere along the trajectory."""
    if trajectory.removed_residual is None or not trajectory.removed:
        return ()
    broken = np.asarray(exceeded(trajectory.removed_residual, trajectory.q, target).any(axis=0))
    return tuple(label for k, label in enumerate(trajectory.removed) if bool(broken[k]))
