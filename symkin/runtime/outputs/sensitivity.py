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
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.protocol import KinematicsKernel

Array = NDArray[np.float64]

# The half-step of the central differences in time for the velocity sensitivities (scaled by
# max(1, |t|) and by 1 / max(1, max|dq|)): truncation ~ h^2 and rounding ~ 1e-16 / h balance
# near 1e-10.
TIME_STEP = 1e-5


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
                           ) -> Array:
    """d dq/dp, shape (T, N, NP), from the time derivative of Phi_q q_p = -Phi_p:

        Phi_q dq_p = -(d Phi_q/dt) q_p - d Phi_p/dt

    The two time derivatives along the motion are central differences of the generated Phi_q
    and Phi_p over (q -/+ h dq, t -/+ h), so no further routine is generated (generation time
    and code size stay as they are); for smooth motions the result agrees with differences of
    whole solves to about 1e-9, see tests/runtime/test_sensitivities.py.
    """
    t, q, dq, p = trajectory.t, trajectory.q, trajectory.dq, trajectory.params
    if t.size == 0 or q_p.shape[2] == 0:
        return np.zeros_like(q_p)
    phi_p = kernel.phi_p  # type: ignore[attr-defined]  # checked by position_sensitivities
    jacobians, rates = [], []
    for k in range(t.size):
        # a step short against the time scale and against the motion (fast mechanisms)
        h = TIME_STEP * max(1.0, abs(float(t[k]))) / max(1.0, float(np.abs(dq[k]).max()))
        ahead, behind = (q[k] + h * dq[k], float(t[k]) + h), (q[k] - h * dq[k], float(t[k]) - h)
        phi_q_rate = (kernel.phi_q(*ahead, p) - kernel.phi_q(*behind, p)) / (2 * h)
        phi_p_rate = (phi_p(*ahead, p) - phi_p(*behind, p)) / (2 * h)
        jacobians.append(kernel.phi_q(q[k], float(t[k]), p))
        rates.append(-(phi_q_rate @ q_p[k]) - phi_p_rate)
    dq_p: Array = np.linalg.solve(np.stack(jacobians), np.stack(rates))
    return dq_p


def with_sensitivities(kernel: KinematicsKernel, trajectory: Trajectory) -> Trajectory:
    """The trajectory with ``q_p`` and ``dq_p`` (T, N, NP) filled in."""
    q_p = position_sensitivities(kernel, trajectory.t, trajectory.q, trajectory.params)
    dq_p = velocity_sensitivities(kernel, trajectory, q_p)
    return dataclasses.replace(trajectory, q_p=q_p, dq_p=dq_p)
