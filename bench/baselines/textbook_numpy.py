"""A literal NumPy transliteration of the chapter's MATLAB program (Example 2.8).

Procedure for procedure: Rot, Dane, Wiezy, Jakobian, NewRaph, Predkosc, Przyspieszenie and
KorbWodz, with MATLAB's 1-based slices shifted to 0-based ones and `Fq\\F` as
numpy.linalg.solve. Kept as literal as possible on purpose, including `Dane` being re-read in
every call and NewRaph's loop shape; two printing slips of the book are mended as noted.
"""

from __future__ import annotations

import numpy as np


def Rot(fi: float) -> np.ndarray:
    return np.array([[np.cos(fi), -np.sin(fi)], [np.sin(fi), np.cos(fi)]])


def Dane() -> dict[str, object]:
    a, b, c = 1.0, 5.0, 4.0
    return {
        "a": a, "b": b, "c": c,
        "sA0": np.array([0.0, 0.0]), "sB1": np.array([0.0, 0.0]),  # revolute 0-1
        "sA1": np.array([a, 0.0]), "sB2": np.array([0.0, 0.0]),  # revolute 1-2
        "sA2": np.array([b, 0.0]), "sB3": np.array([0.0, 0.0]),  # revolute 2-3
        "f0": 0.0, "v0": np.array([0.0, 1.0]),  # prismatic 3-0
        "sA3": np.array([0.0, 0.0]), "sB0": np.array([0.0, c]),
    }


def Wiezy(q: np.ndarray, t: float) -> np.ndarray:
    d = Dane()
    r1, fi1, r2, fi2, r3, fi3 = q[0:2], q[2], q[3:5], q[5], q[6:8], q[8]
    Rot1, Rot2, Rot3 = Rot(fi1), Rot(fi2), Rot(fi3)
    F = np.zeros(9)
    F[0:2] = d["sA0"] - (r1 + Rot1 @ d["sB1"])
    F[2:4] = r1 + Rot1 @ d["sA1"] - (r2 + Rot2 @ d["sB2"])
    F[4:6] = r2 + Rot2 @ d["sA2"] - (r3 + Rot3 @ d["sB3"])
    F[6] = fi3 - d["f0"]
    F[7] = d["v0"] @ (d["sB0"] - r3 - Rot3 @ d["sA3"])
    F[8] = fi1 - t**2 - np.pi / 2
    return F


def Jakobian(q: np.ndarray) -> np.ndarray:
    d = Dane()
    Om = np.array([[0.0, -1.0], [1.0, 0.0]])
    fi1, fi2, fi3 = q[2], q[5], q[8]
    Rot1, Rot2, Rot3 = Rot(fi1), Rot(fi2), Rot(fi3)
    Fq = np.zeros((9, 9))
    Fq[0:2, 0:2] = -np.eye(2)
    Fq[0:2, 2] = -Om @ Rot1 @ d["sB1"]
    Fq[2:4, 0:2] = np.eye(2)
    Fq[2:4, 2] = Om @ Rot1 @ d["sA1"]
    Fq[2:4, 3:5] = -np.eye(2)
    Fq[2:4, 5] = -Om @ Rot2 @ d["sB2"]
    Fq[4:6, 3:5] = np.eye(2)
    Fq[4:6, 5] = Om @ Rot2 @ d["sA2"]
    Fq[4:6, 6:8] = -np.eye(2)
    Fq[4:6, 8] = -Om @ Rot3 @ d["sB3"]
    Fq[6, 8] = 1
    Fq[7, 6:8] = -d["v0"]
    Fq[7, 8] = -d["v0"] @ Om @ Rot3 @ d["sA3"]
    Fq[8, 2] = 1
    return Fq


def NewRaph(q0: np.ndarray, t: float) -> np.ndarray:
    q = q0
    F = Wiezy(q, t)
    iter_ = 1
    while np.linalg.norm(F) > 1e-10 and iter_ < 25:
        F = Wiezy(q, t)
        Fq = Jakobian(q)
        q = q - np.linalg.solve(Fq, F)
        iter_ = iter_ + 1
    if iter_ >= 25:
        print("ERROR: no Newton-Raphson convergence after 25 iterations")
        q = q0
    return q


def Predkosc(q: np.ndarray, t: float) -> np.ndarray:
    # The book prints `Ft=zeros(8,1);-2*t];`: the opening bracket is lost in print.
    Ft = np.concatenate([np.zeros(8), [-2 * t]])
    Fq = Jakobian(q)
    return -np.linalg.solve(Fq, Ft)


def Przyspieszenie(dq: np.ndarray, q: np.ndarray, t: float) -> np.ndarray:
    d = Dane()
    fi1, fi2, fi3 = q[2], q[5], q[8]
    Rot1, Rot2, Rot3 = Rot(fi1), Rot(fi2), Rot(fi3)
    dfi1, dfi2, dfi3 = dq[2], dq[5], dq[8]
    gam = np.zeros(9)
    gam[0:2] = -Rot1 @ d["sB1"] * dfi1**2
    gam[2:4] = Rot1 @ d["sA1"] * dfi1**2 - Rot2 @ d["sB2"] * dfi2**2
    # The book prints Rot3*sB2*dfi2^2 here; sB3*dfi3^2 is meant (both vectors are zero).
    gam[4:6] = Rot2 @ d["sA2"] * dfi2**2 - Rot3 @ d["sB3"] * dfi3**2
    gam[6] = 0
    gam[7] = -d["v0"] @ Rot3 @ d["sA3"] * dfi3**2
    gam[8] = 2
    Fq = Jakobian(q)
    return np.linalg.solve(Fq, gam)


def KorbWodz(dt: float = 0.05, steps: int | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The chapter's main loop; `steps` fixes the grid t = k dt, k = 0..steps, exactly."""
    q, dq, d2q = np.zeros(9), np.zeros(9), np.zeros(9)
    steps = round(1.5 / dt) if steps is None else steps
    T = np.zeros(steps + 1)
    Q, DQ, D2Q = (np.zeros((9, steps + 1)) for _ in range(3))
    for lroz in range(steps + 1):
        t = lroz * dt
        q0 = q + dq * dt + 0.5 * d2q * dt**2
        q = NewRaph(q0, t)
        dq = Predkosc(q, t)
        d2q = Przyspieszenie(dq, q, t)
        T[lroz] = t
        Q[:, lroz], DQ[:, lroz], D2Q[:, lroz] = q, dq, d2q
    return T, Q, DQ, D2Q
