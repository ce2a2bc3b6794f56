"""The chapter's hand-written procedures, transcribed line by line from MATLAB to NumPy.

``Wiezy``, ``Jakobian``, ``Predkosc`` (its right-hand side Phi_t) and ``Przyspieszenie`` (its
right-hand side Gamma) of Example 2.8, with the data script ``Dane`` read from the parameter
vector ``p`` instead of being fixed, in the parameter order of
``examples/crank_slider_general.yaml``. The transcription is faithful, including the slip in
the printed ``Przyspieszenie``:

    gam(5:6,1)=Rot2*sA2*dfi2^2-Rot3*sB2*dfi2^2;

where Example 2.5 (d) has ``Rot3*sB3*dfi3^2``. At the printed dimensions sB2 = sB3 = [0; 0], so
both terms vanish and the program's results are right; check it with

    symkin verify examples/crank_slider_general.yaml --against examples/textbook_hand.py

which varies the parameters around the nominal design and names the entries and the joint.
``textbook_hand_corrected.py`` is the same file with that line fixed.

MATLAB indices are 1-based and inclusive, so ``F(3:4)`` becomes ``F[2:4]``.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

# The order `symkin show examples/crank_slider_general.yaml` prints; symkin verify checks it.
COORDINATES = ("crank.x", "crank.y", "crank.phi", "rod.x", "rod.y", "rod.phi",
               "slider.x", "slider.y", "slider.phi")
PARAMETERS = ("a", "b", "c", "sA0x", "sA0y", "sB1x", "sB1y", "sA1y", "sB2x", "sB2y", "sA2y",
              "sB3x", "sB3y", "f0", "v0x", "v0y", "sA3x", "sA3y", "sB0x")

OM = np.array([[0.0, -1.0], [1.0, 0.0]])  # Om=[0 -1;1 0];


def Rot(fi: float) -> np.ndarray:
    """R=Rot(fi): the planar rotation matrix."""
    return np.array([[np.cos(fi), -np.sin(fi)], [np.sin(fi), np.cos(fi)]])


def Dane(p: np.ndarray) -> SimpleNamespace:
    """Dane.m, with the numbers taken from p (a, b, c and the local vectors)."""
    (a, b, c, sA0x, sA0y, sB1x, sB1y, sA1y, sB2x, sB2y, sA2y, sB3x, sB3y,
     f0, v0x, v0y, sA3x, sA3y, sB0x) = p
    return SimpleNamespace(
        a=a, b=b, c=c,
        sA0=np.array([sA0x, sA0y]), sB1=np.array([sB1x, sB1y]),   # revolute pair 0-1
        sA1=np.array([a, sA1y]), sB2=np.array([sB2x, sB2y]),      # revolute pair 1-2
        sA2=np.array([b, sA2y]), sB3=np.array([sB3x, sB3y]),      # revolute pair 2-3
        f0=f0, v0=np.array([v0x, v0y]),                           # prismatic pair 3-0
        sA3=np.array([sA3x, sA3y]), sB0=np.array([sB0x, c]))


def _names(q: np.ndarray):
    # r1=q(1:2); fi1=q(3); r2=q(4:5); fi2=q(6); r3=q(7:8); fi3=q(9);
    return q[0:2], q[2], q[3:5], q[5], q[6:8], q[8]


def phi(q: np.ndarray, t: float, p: np.ndarray) -> np.ndarray:
    """F=Wiezy(q,t): the constraints, eq. (a) of Example 2.5."""
    d = Dane(p)
    r1, fi1, r2, fi2, r3, fi3 = _names(q)
    Rot1, Rot2, Rot3 = Rot(fi1), Rot(fi2), Rot(fi3)
    F = np.zeros(9)
    F[0:2] = d.sA0 - (r1 + Rot1 @ d.sB1)
    F[2:4] = r1 + Rot1 @ d.sA1 - (r2 + Rot2 @ d.sB2)
    F[4:6] = r2 + Rot2 @ d.sA2 - (r3 + Rot3 @ d.sB3)
    F[6] = fi3 - d.f0
    F[7] = d.v0 @ (d.sB0 - r3 - Rot3 @ d.sA3)
    F[8] = fi1 - t**2 - np.pi / 2
    return F


def phi_q(q: np.ndarray, t: float, p: np.ndarray) -> np.ndarray:
    """Fq=Jakobian(q): the Jacobian, eq. (b) of Example 2.5."""
    d = Dane(p)
    r1, fi1, r2, fi2, r3, fi3 = _names(q)
    Rot1, Rot2, Rot3 = Rot(fi1), Rot(fi2), Rot(fi3)
    Fq = np.zeros((9, 9))
    Fq[0:2, 0:2] = -np.eye(2)
    Fq[0:2, 2] = -OM @ Rot1 @ d.sB1

    Fq[2:4, 0:2] = np.eye(2)
    Fq[2:4, 2] = OM @ Rot1 @ d.sA1
    Fq[2:4, 3:5] = -np.eye(2)
    Fq[2:4, 5] = -OM @ Rot2 @ d.sB2

    Fq[4:6, 3:5] = np.eye(2)
    Fq[4:6, 5] = OM @ Rot2 @ d.sA2
    Fq[4:6, 6:8] = -np.eye(2)
    Fq[4:6, 8] = -OM @ Rot3 @ d.sB3

    Fq[6, 8] = 1

    Fq[7, 6:8] = -d.v0
    Fq[7, 8] = -d.v0 @ OM @ Rot3 @ d.sA3

    Fq[8, 2] = 1
    return Fq


def phi_t(q: np.ndarray, t: float, p: np.ndarray) -> np.ndarray:
    """Ft in Predkosc(q,t), eq. (c) of Example 2.5.

    The printed line reads ``Ft=zeros(8,1);-2*t];``, an opening bracket lost in print:
    ``Ft=[zeros(8,1);-2*t];``.
    """
    return np.concatenate([np.zeros(8), [-2 * t]])


def gamma(q: np.ndarray, dq: np.ndarray, t: float, p: np.ndarray) -> np.ndarray:
    """gam in Przyspieszenie(dq,q,t), eqs. (d), (h), (i) of Example 2.5 — as printed."""
    d = Dane(p)
    r1, fi1, r2, fi2, r3, fi3 = _names(q)
    Rot1, Rot2, Rot3 = Rot(fi1), Rot(fi2), Rot(fi3)
    dfi1, dfi2, dfi3 = dq[2], dq[5], dq[8]
    gam = np.zeros(9)
    gam[0:2] = -Rot1 @ d.sB1 * dfi1**2
    gam[2:4] = Rot1 @ d.sA1 * dfi1**2 - Rot2 @ d.sB2 * dfi2**2
    gam[4:6] = Rot2 @ d.sA2 * dfi2**2 - Rot3 @ d.sB2 * dfi2**2  # sic: the printed slip
    gam[6] = 0
    gam[7] = -d.v0 @ Rot3 @ d.sA3 * dfi3**2
    gam[8] = 2
    return gam
