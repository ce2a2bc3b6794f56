"""A hand derivation of the luffing boom in luffing.yaml, written from the chapter's formulas.

Revolute (2.18, 2.31-2.34, 2.42). Prismatic cylinder(i)-piston(j): phi_i - phi_j = 0 (2.19) and
Phi_perp = (R_j v)^T d with d = r_j + R_j s_B - r_i - R_i s_A (2.22); its Jacobian
Phi_ri = -(R_j v)^T, Phi_phii = -(R_j v)^T Om R_i s_A, Phi_rj = (R_j v)^T,
Phi_phij = -(R_j v)^T Om (r_j - r_i - R_i s_A) (2.49-2.52); its Gamma (2.59). The slide driver
(2.28) is the same with u and f(t): Phi_t = -f', Gamma gets + f''.
"""

import numpy as np

COORDINATES = ("boom.x", "boom.y", "boom.phi", "cylinder.x", "cylinder.y", "cylinder.phi",
               "piston.x", "piston.y", "piston.phi")
PARAMETERS = ("bx", "by", "gx", "gy", "ax", "ay", "cx", "cy", "s0", "v", "k")

OM = np.array([[0.0, -1.0], [1.0, 0.0]])
V = np.array([0.0, 1.0])   # prismatic: perpendicular to the slide, in the piston frame
U = np.array([1.0, 0.0])   # slide driver: along the slide, in the piston frame


def rot(fi):
    return np.array([[np.cos(fi), -np.sin(fi)], [np.sin(fi), np.cos(fi)]])


def split(q):
    return q[0:2], q[2], q[3:5], q[5], q[6:8], q[8]


def phi(q, t, p):
    bx, by, gx, gy, ax, ay, cx, cy, s0, v, k = p
    rb, fb, rc, fc, rp, fp = split(q)
    Rb, Rc, Rp = rot(fb), rot(fc), rot(fp)
    sA, sB = np.array([ax, ay]), np.array([cx, cy])
    d = rp + Rp @ sB - rc - Rc @ sA
    F = np.zeros(9)
    F[0:2] = -rb
    F[2:4] = np.array([gx, gy]) - rc
    F[4:6] = rp - (rb + Rb @ np.array([bx, by]))
    F[6] = fc - fp
    F[7] = (Rp @ V) @ d
    F[8] = (Rp @ U) @ d - (s0 + v * t + k * t**2)
    return F


def _sliding_rows(J, row, axis, q, p):
    """Jacobian row of (R_j a)^T d for the cylinder (i, cols 3-5) and piston (j, cols 6-8)."""
    ax, ay = p[4], p[5]
    _, _, rc, fc, rp, fp = split(q)
    Rc, Rp = rot(fc), rot(fp)
    sA = np.array([ax, ay])
    a = Rp @ axis
    J[row, 3:5] = -a
    J[row, 5] = -a @ OM @ Rc @ sA
    J[row, 6:8] = a
    J[row, 8] = -a @ OM @ (rp - rc - Rc @ sA)


def phi_q(q, t, p):
    bx, by = p[0], p[1]
    fb = q[2]
    J = np.zeros((9, 9))
    J[0:2, 0:2] = -np.eye(2)
    J[2:4, 3:5] = -np.eye(2)
    J[4:6, 6:8] = np.eye(2)
    J[4:6, 0:2] = -np.eye(2)
    J[4:6, 2] = -OM @ rot(fb) @ np.array([bx, by])
    J[6, 5] = 1.0
    J[6, 8] = -1.0
    _sliding_rows(J, 7, V, q, p)
    _sliding_rows(J, 8, U, q, p)
    return J


def phi_t(q, t, p):
    v, k = p[9], p[10]
    out = np.zeros(9)
    out[8] = -(v + 2 * k * t)
    return out


def _sliding_gamma(axis, q, dq, p):
    """(2.59): (R_j a)^T (2 Om (dr_j - dr_i) dphi_j + (r_j - r_i) dphi_j^2
    - R_i s_A (dphi_j - dphi_i)^2)."""
    ax, ay = p[4], p[5]
    _, _, rc, fc, rp, fp = split(q)
    drc, dfc, drp, dfp = dq[3:5], dq[5], dq[6:8], dq[8]
    Rc, Rp = rot(fc), rot(fp)
    sA = np.array([ax, ay])
    return (Rp @ axis) @ (2 * OM @ (drp - drc) * dfp + (rp - rc) * dfp**2
                          - Rc @ sA * (dfp - dfc)**2)


def gamma(q, dq, t, p):
    bx, by, k = p[0], p[1], p[10]
    fb, dfb = q[2], dq[2]
    g = np.zeros(9)
    g[4:6] = -rot(fb) @ np.array([bx, by]) * dfb**2
    g[7] = _sliding_gamma(V, q, dq, p)
    g[8] = _sliding_gamma(U, q, dq, p) + 2 * k
    return g
