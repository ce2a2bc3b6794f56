"""Stage 7 — results: point kinematics (2.14-2.16) and the outputs a run writes.

Imports only NumPy: it is part of the runtime.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

OMEGA = np.array([[0.0, -1.0], [1.0, 0.0]])


def rotation(phi: ArrayLike) -> NDArray[np.float64]:
    """R(phi) for one angle (2x2) or many (..., 2, 2)."""
    phi = np.asarray(phi, dtype=float)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def point_kinematics(q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, s: ArrayLike
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Position, velocity and acceleration of a point fixed in a body.

    Args:
        q, dq, ddq: the body's [x, y, phi] and its first and second time derivatives,
            shape (3,) or (T, 3).
        s: the point's local vector s^(i), shape (2,).

    Returns:
        r = r_i + R s (2.14), dr = dr_i + Omega R s dphi (2.15),
        ddr = ddr_i + Omega R s ddphi - R s dphi^2 (2.16); each shape (2,) or (T, 2).
    """
    q, dq, ddq = (np.asarray(a, dtype=float) for a in (q, dq, ddq))
    Rs = rotation(q[..., 2]) @ np.asarray(s, dtype=float)
    ORs = Rs @ OMEGA.T
    r = q[..., :2] + Rs
    dr = dq[..., :2] + ORs * dq[..., 2, None]
    ddr = ddq[..., :2] + ORs * ddq[..., 2, None] - Rs * dq[..., 2, None] ** 2
    return r, dr, ddr
