"""Point and body kinematics of a spatial mechanism from its solved coordinates (NumPy only).

A body's coordinates are its position r and Euler parameters e = [e0, e1, e2, e3] (e0 the
scalar part). The rotation matrix A(e) is quadratic in e, A(e) = B(e, e) with B bilinear and
symmetric, so its derivatives are exact without differentiating by hand:

    dA = 2 B(e, de),   ddA = 2 B(de, de) + 2 B(e, dde),   B(a, b) = (A(a + b) - A(a - b)) / 4

and a point s fixed in the body moves as r + A s, dr + dA s, ddr + ddA s. The global angular
velocity and acceleration are omega = 2 E de and alpha = 2 E dde with E = [-e, e~ + e0 I]
(E de = 0 along a motion that keeps e normalised, so dE de = 0 too).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


def rotation(e: ArrayLike) -> Array:
    """A(e) for Euler parameters of shape (..., 4): (..., 3, 3)."""
    e = np.asarray(e, dtype=float)
    e0, e1, e2, e3 = e[..., 0], e[..., 1], e[..., 2], e[..., 3]
    rows = [[e0*e0 + e1*e1 - e2*e2 - e3*e3, 2*(e1*e2 - e0*e3), 2*(e1*e3 + e0*e2)],
            [2*(e1*e2 + e0*e3), e0*e0 - e1*e1 + e2*e2 - e3*e3, 2*(e2*e3 - e0*e1)],
            [2*(e1*e3 - e0*e2), 2*(e2*e3 + e0*e1), e0*e0 - e1*e1 - e2*e2 + e3*e3]]
    return np.stack([np.stack(row, -1) for row in rows], -2)


def _bilinear(a: Array, b: Array) -> Array:
    """B(a, b), the symmetric bilinear form whose diagonal is A."""
    return (rotation(a + b) - rotation(a - b)) / 4.0


def point_kinematics(q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, s: ArrayLike
                     ) -> tuple[Array, Array, Array]:
    """r, dr, ddr of a point with local vector s (3,) of a body whose [x, y, z, e0..e3] and
    derivatives are q, dq, ddq, shape (7,) or (..., 7); each result (3,) or (..., 3)."""
    q, dq, ddq = (np.asarray(a, dtype=float) for a in (q, dq, ddq))
    s = np.asarray(s, dtype=float)
    e, de, dde = q[..., 3:], dq[..., 3:], ddq[..., 3:]
    def times_s(matrix: Array) -> Array:  # broadcasts s of shape (..., 3) too
        return np.asarray(np.einsum("...ij,...j->...i", matrix, s), dtype=np.float64)

    r = q[..., :3] + times_s(rotation(e))
    dr = dq[..., :3] + 2.0 * times_s(_bilinear(e, de))
    ddr = ddq[..., :3] + times_s(2.0 * rotation(de) + 2.0 * _bilinear(e, dde))
    return r, dr, ddr


def _e_matrix(e: Array) -> Array:
    """E = [-e, e~ + e0 I], shape (..., 3, 4)."""
    e0, e1, e2, e3 = e[..., 0], e[..., 1], e[..., 2], e[..., 3]
    rows = [[-e1, e0, -e3, e2], [-e2, e3, e0, -e1], [-e3, -e2, e1, e0]]
    return np.stack([np.stack(row, -1) for row in rows], -2)


def angular(q: ArrayLike, dq: ArrayLike, ddq: ArrayLike) -> tuple[Array, Array]:
    """omega = 2 E de and alpha = 2 E dde (global), each (3,) or (T, 3)."""
    q, dq, ddq = (np.asarray(a, dtype=float) for a in (q, dq, ddq))
    E = _e_matrix(q[..., 3:])
    return 2.0 * (E @ dq[..., 3:, None])[..., 0], 2.0 * (E @ ddq[..., 3:, None])[..., 0]
