"""A hand derivation of the four-bar in four_bar.yaml, written from the chapter's formulas.

Revolute pair i-j: Phi = r_i + R_i s_A - (r_j + R_j s_B) (2.18), Phi_ri = I,
Phi_phii = Om R_i s_A, Phi_rj = -I, Phi_phij = -Om R_j s_B (2.31-2.34),
Gamma = R_i s_A dphi_i^2 - R_j s_B dphi_j^2 (2.42). Driver phi_1 - theta(t) (2.27).
"""

import numpy as np

COORDINATES = ("crank.x", "crank.y", "crank.phi", "coupler.x", "coupler.y", "coupler.phi",
               "rocker.x", "rocker.y", "rocker.phi")
PARAMETERS = ("l1", "l2", "l3", "dx", "dy", "h", "w")

OM = np.array([[0.0, -1.0], [1.0, 0.0]])


def rot(fi):
    return np.array([[np.cos(fi), -np.sin(fi)], [np.sin(fi), np.cos(fi)]])


def vectors(p):
    l1, l2, l3, dx, dy, h = p[:6]
    return {"sA0": np.array([0.0, 0.0]), "sB1": np.array([-l1 / 2, 0.0]),
            "sA1": np.array([l1 / 2, 0.0]), "sB2": np.array([-l2 / 2, h]),
            "sA2": np.array([l2 / 2, h]), "sB3": np.array([l3 / 2, 0.0]),
            "sA3": np.array([-l3 / 2, 0.0]), "sB0": np.array([dx, dy])}


def phi(q, t, p):
    s = vectors(p)
    w = p[6]
    r1, f1, r2, f2, r3, f3 = q[0:2], q[2], q[3:5], q[5], q[6:8], q[8]
    R1, R2, R3 = rot(f1), rot(f2), rot(f3)
    F = np.zeros(9)
    F[0:2] = s["sA0"] - (r1 + R1 @ s["sB1"])
    F[2:4] = r1 + R1 @ s["sA1"] - (r2 + R2 @ s["sB2"])
    F[4:6] = r2 + R2 @ s["sA2"] - (r3 + R3 @ s["sB3"])
    F[6:8] = r3 + R3 @ s["sA3"] - s["sB0"]
    F[8] = f1 - (np.pi / 3 + w * t + t**2 / 2)
    return F


def phi_q(q, t, p):
    s = vectors(p)
    f1, f2, f3 = q[2], q[5], q[8]
    R1, R2, R3 = rot(f1), rot(f2), rot(f3)
    I = np.eye(2)
    J = np.zeros((9, 9))
    J[0:2, 0:2] = -I
    J[0:2, 2] = -OM @ R1 @ s["sB1"]
    J[2:4, 0:2] = I
    J[2:4, 2] = OM @ R1 @ s["sA1"]
    J[2:4, 3:5] = -I
    J[2:4, 5] = -OM @ R2 @ s["sB2"]
    J[4:6, 3:5] = I
    J[4:6, 5] = OM @ R2 @ s["sA2"]
    J[4:6, 6:8] = -I
    J[4:6, 8] = -OM @ R3 @ s["sB3"]
    J[6:8, 6:8] = I
    J[6:8, 8] = OM @ R3 @ s["sA3"]
    J[8, 2] = 1.0
    return J


def phi_t(q, t, p):
    w = p[6]
    out = np.zeros(9)
    out[8] = -(w + t)
    return out


def gamma(q, dq, t, p):
    s = vectors(p)
    f1, f2, f3 = q[2], q[5], q[8]
    d1, d2, d3 = dq[2], dq[5], dq[8]
    R1, R2, R3 = rot(f1), rot(f2), rot(f3)
    g = np.zeros(9)
    g[0:2] = -R1 @ s["sB1"] * d1**2
    g[2:4] = R1 @ s["sA1"] * d1**2 - R2 @ s["sB2"] * d2**2
    g[4:6] = R2 @ s["sA2"] * d2**2 - R3 @ s["sB3"] * d3**2
    g[6:8] = R3 @ s["sA3"] * d3**2
    g[8] = 1.0
    return g
