"""Example 2.7's closed form of the textbook crank-slider, with its first two time derivatives.

q = [x1, y1, phi1, x2, y2, phi2, x3, y3, phi3] with a = 1, b = 5, c = 4 and
phi1 = t^2 + pi/2, x2 = a cos phi1, y2 = a sin phi1, phi2 = asin((c - y2)/b),
x3 = x2 + b cos phi2, y3 = c, phi3 = 0. The derivatives follow by the chain rule.
"""

from __future__ import annotations

import numpy as np

A, B, C = 1.0, 5.0, 4.0
T1 = 1.5
LONG_STEPS = 20000
LONG_DT = T1 / LONG_STEPS


def grid(steps: int = LONG_STEPS) -> np.ndarray:
    """t = k dt, k = 0..steps, dt = 1.5 / steps (the chapter's loop `for t = 0:dt:1.5`)."""
    return np.arange(steps + 1) * (T1 / steps)


def closed_form(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, dq, d2q), each of shape (len(t), 9)."""
    t = np.asarray(t, dtype=float)
    f1, w1, e1 = t**2 + np.pi / 2, 2 * t, 2.0 + 0 * t
    x2, y2 = A * np.cos(f1), A * np.sin(f1)
    dx2, dy2 = -A * np.sin(f1) * w1, A * np.cos(f1) * w1
    ddx2 = -A * np.cos(f1) * w1**2 - A * np.sin(f1) * e1
    ddy2 = -A * np.sin(f1) * w1**2 + A * np.cos(f1) * e1
    f2 = np.arcsin((C - y2) / B)
    w2 = -dy2 / (B * np.cos(f2))
    e2 = (-ddy2 / B + np.sin(f2) * w2**2) / np.cos(f2)
    x3 = x2 + B * np.cos(f2)
    dx3 = dx2 - B * np.sin(f2) * w2
    ddx3 = ddx2 - B * np.cos(f2) * w2**2 - B * np.sin(f2) * e2
    zero = 0 * t
    q = np.stack([zero, zero, f1, x2, y2, f2, x3, zero + C, zero], axis=1)
    dq = np.stack([zero, zero, w1, dx2, dy2, w2, dx3, zero, zero], axis=1)
    d2q = np.stack([zero, zero, e1, ddx2, ddy2, e2, ddx3, zero, zero], axis=1)
    return q, dq, d2q


def errors(t: np.ndarray, q: np.ndarray, dq: np.ndarray, d2q: np.ndarray
           ) -> tuple[float, float, float]:
    """Largest absolute deviation from the closed form of q, dq and d2q over the grid."""
    exact = closed_form(t)
    return tuple(float(np.abs(got - want).max()) for got, want in zip((q, dq, d2q), exact))
