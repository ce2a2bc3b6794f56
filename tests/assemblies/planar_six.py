"""Every assembly of a 6-6 Stewart platform whose base joints lie in one plane and whose
platform joints lie in one plane, counted independently of symkin (the test's reference).

The pose is the platform's rotation R (columns r1, r2, r3) and origin t; platform joint k is
R p_k + t with p_k = (p_kx, p_ky, 0), base joint b_k = (b_kx, b_ky, 0). Expanding
|R p_k + t - b_k|^2 = L_k^2, every unknown enters through nine quantities, linearly:

    w = (|t|^2, t.r1, t.r2, r11, r21, r12, r22, tx, ty),

    |t|^2 + 2 p_kx t.r1 + 2 p_ky t.r2 - 2 b_k . (p_kx (r11, r21) + p_ky (r12, r22))
        - 2 (b_kx tx + b_ky ty) = L_k^2 - |p_k|^2 - |b_k|^2,

six equations in nine unknowns: w = w0 + N lam, lam in C^3. What is left, x = (tz, r31, r32),
enters only through its products: G = x x^T = [[s, u, v], [u, a, c], [v, c, b]] with

    s = |t|^2 - tx^2 - ty^2,   u = t.r1 - tx r11 - ty r21,   v = t.r2 - tx r12 - ty r22,
    a = 1 - r11^2 - r21^2,     b = 1 - r12^2 - r22^2,        c = -(r11 r12 + r21 r22),

each quadratic in lam. G has rank one: s a = u^2, s b = v^2, s c = u v (three quartics in
lam), which for s != 0 give G = x x^T with x = (sqrt s, u / sqrt s, v / sqrt s); their roots
with s = 0 (then u = v = 0 whatever a, b, c) are no assemblies and are dropped. (The minor
a b = c^2 is not used: its gradient vanishes where a = b = c = 0, a platform parallel to the
base, so such an assembly would be a double root and the homotopy would lose it.) Each real
lam with s > 0 gives two assemblies, x and -x: the mirror images in the base plane.

The quartics are solved by a total-degree homotopy (64 paths, a random complex gamma,
predictor-corrector with step halving), which finds every isolated complex root with
probability one: the count of roots with s != 0 is 20 (the 40 complex assemblies of a
general 6-6 platform, in mirror pairs), which checks that no path was lost.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MAXSTEP = 0.05
"""The longest homotopy step in tau."""

GAMMA = complex(0.8723, 0.4891)
"""The homotopy's random constant (fixed: the count repeats)."""


@dataclass(frozen=True)
class Platform:
    """Base joints b (6, 2) in the ground plane z = 0, platform joints p (6, 2) in the
    platform frame's plane z = 0."""

    b: np.ndarray
    p: np.ndarray

    def linear(self, legs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """w0 and N of w = w0 + N lam (the module docstring)."""
        rows, rhs = [], []
        for (bx, by), (px, py), length in zip(self.b, self.p, legs):
            rows.append([1.0, 2 * px, 2 * py, -2 * bx * px, -2 * by * px, -2 * bx * py,
                         -2 * by * py, -2 * bx, -2 * by])
            rhs.append(length**2 - px**2 - py**2 - bx**2 - by**2)
        matrix = np.array(rows)
        _, singular, vt = np.linalg.svd(matrix)
        assert singular[-1] > 1e-9 * singular[0], "the leg equations are dependent"
        return np.linalg.lstsq(matrix, np.array(rhs), rcond=None)[0], vt[6:].T


def _products(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(s, u, v, a, b, c) at w and their gradients (6, 9)."""
    big_t, g1, g2, r11, r21, r12, r22, tx, ty = w
    values = np.array([big_t - tx**2 - ty**2, g1 - tx * r11 - ty * r21,
                       g2 - tx * r12 - ty * r22, 1 - r11**2 - r21**2, 1 - r12**2 - r22**2,
                       -(r11 * r12 + r21 * r22)])
    zero = 0 * tx
    one = zero + 1
    gradients = np.array([
        [one, zero, zero, zero, zero, zero, zero, -2 * tx, -2 * ty],
        [zero, one, zero, -tx, -ty, zero, zero, -r11, -r21],
        [zero, zero, one, zero, zero, -tx, -ty, -r12, -r22],
        [zero, zero, zero, -2 * r11, -2 * r21, zero, zero, zero, zero],
        [zero, zero, zero, zero, zero, -2 * r12, -2 * r22, zero, zero],
        [zero, zero, zero, -r12, -r22, -r11, -r21, zero, zero]])
    return values, gradients


def _target(lam: np.ndarray, w0: np.ndarray, null: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The three quartics at lam and their Jacobian (3, 3)."""
    (s, u, v, a, b, c), d = _products(w0 + null @ lam)
    f = np.array([s * a - u * u, s * b - v * v, s * c - u * v])
    df = np.array([s * d[3] + a * d[0] - 2 * u * d[1], s * d[4] + b * d[0] - 2 * v * d[2],
                   s * d[5] + c * d[0] - u * d[2] - v * d[1]])
    return f, df @ null


def _homotopy(lam: np.ndarray, tau: float, w0: np.ndarray, null: np.ndarray, gamma: complex
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """H = gamma (1 - tau) (lam^4 - 1) + tau F(lam): H, dH/dlam, dH/dtau."""
    f, df = _target(lam, w0, null)
    start = lam**4 - 1
    h = gamma * (1 - tau) * start + tau * f
    dh = gamma * (1 - tau) * np.diag(4 * lam**3) + tau * df
    return h, dh, f - gamma * start


def _track(lam: np.ndarray, w0: np.ndarray, null: np.ndarray, gamma: complex
           ) -> np.ndarray | None:
    """Follow one path from tau = 0 to 1 (Euler predictor, Newton corrector, the step halved
    when the corrector does not contract); None when it runs off to infinity."""
    tau, step = 0.0, 0.01
    while tau < 1.0:
        step = min(step, 1.0 - tau)
        _, dh, dtau = _homotopy(lam, tau, w0, null, gamma)
        guess = lam - step * np.linalg.solve(dh, dtau)
        corrected = _correct(guess, tau + step, w0, null, gamma)
        if corrected is None:
            step /= 2
            if step < 1e-12:
                return None
            continue
        lam, tau = corrected, tau + step
        step = min(2 * step, MAXSTEP)
        if np.abs(lam).max() > 1e8:
            return None
    return _polish(lam, w0, null)


def _correct(lam: np.ndarray, tau: float, w0: np.ndarray, null: np.ndarray, gamma: complex
             ) -> np.ndarray | None:
    size = 1.0 + np.abs(lam).max()
    previous = math.inf
    for _ in range(4):
        h, dh, _ = _homotopy(lam, tau, w0, null, gamma)
        delta = np.linalg.solve(dh, -h)
        norm = np.abs(delta).max()
        if norm > 0.5 * previous or norm > 0.1 * size:
            return None
        lam = lam + delta
        previous = norm
        if norm < 1e-10 * size:
            return lam
    return lam if previous < 1e-7 * size else None


def _polish(lam: np.ndarray, w0: np.ndarray, null: np.ndarray) -> np.ndarray:
    for _ in range(20):
        f, df = _target(lam, w0, null)
        lam = lam - np.linalg.solve(df, f)
    return lam


def _start_points() -> list[np.ndarray]:
    roots = [1, 1j, -1, -1j]
    return [np.array([roots[i], roots[j], roots[k]], dtype=complex)
            for i in range(4) for j in range(4) for k in range(4)]


@dataclass(frozen=True)
class Count:
    """complex: the roots with the right sign (20 for a general platform); poses: the real
    assemblies, each (R (3, 3), t (3,))."""

    complex: int
    poses: list[tuple[np.ndarray, np.ndarray]]


def assemblies(platform: Platform, legs: np.ndarray, gamma: complex = GAMMA) -> Count:
    """Every assembly of ``platform`` at leg lengths ``legs`` (the module docstring; gamma:
    the homotopy's constant)."""
    w0, null = platform.linear(np.asarray(legs, dtype=float))
    roots: list[np.ndarray] = []
    for start in _start_points():
        end = _track(start, w0.astype(complex), null.astype(complex), gamma)
        if end is None or not np.all(np.isfinite(end)):
            continue
        if np.abs(_target(end, w0, null)[0]).max() > 1e-8 * (1 + np.abs(end).max())**4:
            continue
        if not any(np.abs(end - root).max() < 1e-6 for root in roots):
            roots.append(end)
    right = [lam for lam in roots if _off_the_plane(lam, w0, null)]
    poses = []
    for lam in right:
        if np.abs(lam.imag).max() < 1e-7 * (1 + np.abs(lam).max()):
            poses += _poses(lam.real, w0, null)
    return Count(len(right), poses)


def _off_the_plane(lam: np.ndarray, w0: np.ndarray, null: np.ndarray) -> bool:
    """s = tz^2 away from zero: where s = 0 the three quartics hold with u = v = 0 whatever
    a, b, c are, which is no assembly."""
    s = _products(w0 + null @ lam)[0][0]
    return bool(abs(s) > 1e-8 * (1 + np.abs(lam).max()) ** 2)


def _poses(lam: np.ndarray, w0: np.ndarray, null: np.ndarray
           ) -> list[tuple[np.ndarray, np.ndarray]]:
    """The mirror pair of assemblies of one real root (none when s <= 0: tz not real)."""
    w = w0 + null @ lam
    s, u, v, _, _, _ = _products(w)[0]
    if s <= 0:
        return []
    found = []
    for tz in (math.sqrt(s), -math.sqrt(s)):
        r1 = np.array([w[3], w[4], u / tz])
        r2 = np.array([w[5], w[6], v / tz])
        found.append((np.column_stack([r1, r2, np.cross(r1, r2)]),
                      np.array([w[7], w[8], tz])))
    return found
