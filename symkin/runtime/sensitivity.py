"""Design sensitivities of a solved trajectory: q_p = dq/dp at every time point.

Along a solution Phi(q(p), t, p) = 0; differentiating with respect to the parameters gives

    Phi_q q_p = -Phi_p,   and in time   Phi_q dq_p = -(d Phi_q/dt) q_p - d Phi_p/dt

with Phi_p derived symbolically (symbolic.derivation) and generated like Phi_q, so q_p is exact
up to rounding, not a finite-difference estimate. The Jacobians of every time point are solved
in one batched LAPACK call. Imports only NumPy: it is part of the runtime.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from symkin.errors import SolveError
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.results import Trajectory

Array = NDArray[np.float64]


def position_sensitivities(kernel: KinematicsKernel, t: Array, q: Array, p: Array) -> Array:
    """dq/dp at every solved point, shape (T, N, NP).

    Raises:
        SolveError: the kernel has no Phi_p, or Phi_q is singular at some point.
    """
    phi_p = getattr(kernel, "phi_p", None)
    if phi_p is None or not getattr(kernel, "has_phi_p", True):
        raise SolveError(f"the kernel of {kernel.name} has no Phi_p, so no sensitivities; "
                         "rebuild it with symkin.compile")
    size, count = len(kernel.coordinates), p.size
    if t.size == 0 or count == 0:
        return np.zeros((t.size, size, count))
    jacobians = np.stack([kernel.phi_q(q[k], float(t[k]), p) for k in range(t.size)])
    rhs = np.stack([-phi_p(q[k], float(t[k]), p) for k in range(t.size)])
    try:
        q_p: Array = np.linalg.solve(jacobians, rhs)
    except np.linalg.LinAlgError:
        raise SolveError("Phi_q is singular at a solved point, so the sensitivities q_p are "
                         "undefined there") from None
    return q_p


def velocity_sensitivities(kernel: KinematicsKernel, trajectory: Trajectory, q_p: Array
                           ) -> Array | None:
    """d dq/dp, shape (T, N, NP), from the time derivative of Phi_q q_p = -Phi_p:

        Phi_q dq_p = -(d Phi_q/dt) q_p - d Phi_p/dt

    with both time derivatives generated; None for a kernel without them."""
    phi_dots = getattr(kernel, "phi_dots", None)
    if phi_dots is None or trajectory.t.size == 0 or q_p.shape[2] == 0:
        return None if phi_dots is None else np.zeros_like(q_p)
    t, q, dq, p = trajectory.t, trajectory.q, trajectory.dq, trajectory.params
    jacobians = np.stack([kernel.phi_q(q[k], float(t[k]), p) for k in range(t.size)])
    dots = [phi_dots(q[k], dq[k], float(t[k]), p) for k in range(t.size)]
    rhs = -(np.stack([d[0] for d in dots]) @ q_p) - np.stack([d[1] for d in dots])
    dq_p: Array = np.linalg.solve(jacobians, rhs)
    return dq_p


def with_sensitivities(kernel: KinematicsKernel, trajectory: Trajectory) -> Trajectory:
    """The trajectory with ``q_p`` and ``dq_p`` (T, N, NP) filled in."""
    q_p = position_sensitivities(kernel, trajectory.t, trajectory.q, trajectory.params)
    dq_p = velocity_sensitivities(kernel, trajectory, q_p)
    return dataclasses.replace(trajectory, q_p=q_p, dq_p=dq_p)
