"""The driver against closed forms derived here, independently of symkin's derivation.

Each mechanism's coordinates are written as explicit functions of t (Example 2.7 for the
textbook; circle intersection, triangle geometry and inverse trigonometry for the others) and
differentiated exactly with SymPy; both backends must reproduce them over the whole grid:
q within 1e-9, dq within 1e-8, d2q within 1e-7.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest
import sympy as sp
from driver_support import BACKENDS, derive, kernel_for

import symkin

T = sp.Symbol("t", real=True)
TOLERANCES = (1e-9, 1e-8, 1e-7)


Jet = tuple  # (value, first derivative, second derivative), arrays over the grid


def _jet(expr: sp.Expr, times: np.ndarray, known: dict[sp.Symbol, Jet]) -> Jet:
    """Value and exact first two t-derivatives of expr(t, u...), by the chain rule through the
    intermediate quantities u whose jets are known (forward-mode differentiation with SymPy:
    each step differentiates one small expression, never the whole nested closed form)."""
    us = sorted((s for s in expr.free_symbols if s in known), key=str)
    args = (T, *us)

    def value(e: sp.Expr) -> np.ndarray:
        return np.broadcast_to(np.asarray(sp.lambdify(args, e, "numpy")(
            times, *(known[u][0] for u in us)), dtype=float), times.shape)

    first = value(sp.diff(expr, T))
    second = value(sp.diff(expr, T, 2))
    for i, u in enumerate(us):
        du, ddu = known[u][1], known[u][2]
        e_u = sp.diff(expr, u)
        first = first + value(e_u) * du
        second = second + value(e_u) * ddu + 2 * value(sp.diff(e_u, T)) * du
        for v in us:
            second = second + value(sp.diff(e_u, v)) * du * known[v][1]
    return value(expr), first, second


def _derivatives(expressions: dict[str, sp.Expr], times: np.ndarray,
                 steps: Sequence[tuple[sp.Symbol, sp.Expr]] = ()) -> dict[str, Jet]:
    """Jets of the closed forms on the grid; ``steps`` defines intermediate quantities in order."""
    known: dict[sp.Symbol, Jet] = {}
    for symbol, expr in steps:
        known[symbol] = _jet(expr, times, known)
    return {name: _jet(sp.sympify(expr), times, known) for name, expr in expressions.items()}


def _wrapped(angle: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * angle))


def _check(trajectory, expressions: dict[str, sp.Expr], steps=()) -> None:
    reference = _derivatives(expressions, trajectory.t, steps)
    assert set(reference) == set(trajectory.coordinates)
    for k, name in enumerate(trajectory.coordinates):
        exact = reference[name]
        error_q = trajectory.q[:, k] - exact[0]
        if name.endswith(".phi"):
            error_q = _wrapped(error_q)
        assert np.abs(error_q).max() <= TOLERANCES[0], name
        assert np.abs(trajectory.dq[:, k] - exact[1]).max() <= TOLERANCES[1], name
        assert np.abs(trajectory.d2q[:, k] - exact[2]).max() <= TOLERANCES[2], name


def _check_point(trajectory, body: str, point: str, expr: sp.Matrix, steps=()) -> None:
    reference = _derivatives({"x": expr[0], "y": expr[1]}, trajectory.t, steps)
    for k, (r, limit) in enumerate(zip(trajectory.point(body, point), TOLERANCES)):
        exact = np.column_stack([reference["x"][k], reference["y"][k]])
        assert np.abs(r - exact).max() <= limit


def _perp(v: sp.Matrix) -> sp.Matrix:
    return sp.Matrix([-v[1], v[0]])


# ----- the textbook crank-slider (Example 2.7) -----------------------------------------------

def textbook_closed_form(a=1, b=5, c=4) -> dict[str, sp.Expr]:
    phi1 = T**2 + sp.pi / 2
    x2, y2 = a * sp.cos(phi1), a * sp.sin(phi1)
    phi2 = sp.asin((c - y2) / b)
    return {"crank.x": sp.S(0), "crank.y": sp.S(0), "crank.phi": phi1,
            "rod.x": x2, "rod.y": y2, "rod.phi": phi2,
            "slider.x": x2 + b * sp.cos(phi2), "slider.y": sp.S(c), "slider.phi": sp.S(0)}


@pytest.mark.parametrize("backend", BACKENDS)
def test_textbook_example_2_7(backend: str, crank_slider_system) -> None:
    trajectory = symkin.solve(kernel_for(crank_slider_system, backend))
    assert trajectory.t.size == 31 and trajectory.t[0] == 0.0 and trajectory.t[-1] == 1.5
    _check(trajectory, textbook_closed_form())
    phi1 = T**2 + sp.pi / 2
    rod_end = sp.Matrix([sp.cos(phi1), sp.sin(phi1)]) + 5 * sp.Matrix(
        [sp.cos(textbook_closed_form()["rod.phi"]), sp.sin(textbook_closed_form()["rod.phi"])])
    _check_point(trajectory, "rod", "P", rod_end)


# ----- a four-bar by circle intersection ----------------------------------------------------

def four_bar_closed_form(a=1.0, b=3.0, c=2.5, d=3.0, upper=True):
    """B is where the circle of radius b about A meets the circle of radius c about O4.

    Returns (coordinate closed forms, the coupler point M = [b/2, 0.5], intermediate steps).
    """
    theta, ax, ay, dist, along, across, bx, by = sp.symbols(
        "theta ax ay dist along across bx by", real=True)
    cx, cy = d - ax, -ay  # the chord A -> O4
    side = 1 if upper else -1  # chord x perp(chord) points left of A -> O4: upward at t = 0
    steps = [
        (theta, sp.Rational(3, 10) + 2 * T + T**2 / 2),
        (ax, a * sp.cos(theta)), (ay, a * sp.sin(theta)),
        (dist, sp.sqrt(cx**2 + cy**2)),
        (along, (b**2 - c**2 + dist**2) / (2 * dist)),
        (across, sp.sqrt(b**2 - along**2)),
        (bx, ax + (along * cx - side * across * cy) / dist),
        (by, ay + (along * cy + side * across * cx) / dist),
    ]
    forms = {"crank.x": sp.S(0), "crank.y": sp.S(0), "crank.phi": theta,
             "coupler.x": ax, "coupler.y": ay, "coupler.phi": sp.atan2(by - ay, bx - ax),
             "rocker.x": sp.S(d), "rocker.y": sp.S(0), "rocker.phi": sp.atan2(by, bx - d)}
    A, B = sp.Matrix([ax, ay]), sp.Matrix([bx, by])
    midpoint = A + (B - A) / 2 + sp.Rational(1, 2) * _perp(B - A) / b  # M = [b/2, 0.5]
    return forms, midpoint, steps


@pytest.mark.parametrize("backend", BACKENDS)
def test_four_bar_by_circle_intersection(backend: str) -> None:
    trajectory = symkin.solve(kernel_for(derive("four_bar_test"), backend))
    assert trajectory.t.size == 101
    expressions, midpoint, steps = four_bar_closed_form()
    _check(trajectory, expressions, steps)
    _check_point(trajectory, "coupler", "M", midpoint, steps)


def test_four_bar_other_assembly_reached_from_q0() -> None:
    """Where several assemblies exist, the one reached from q0 is taken."""
    kernel = kernel_for(derive("four_bar_test"), "numpy")
    q0 = np.array(kernel.q0)
    q0[5], q0[8] = -0.5, -1.5  # coupler and rocker pointing below the ground line
    trajectory = symkin.solve(kernel, q0=q0)
    expressions, _, steps = four_bar_closed_form(upper=False)
    _check(trajectory, expressions, steps)


# ----- an offset crank-slider ----------------------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
def test_offset_crank_slider(backend: str) -> None:
    a, b, e = 1.2, 4.0, 0.5
    theta = 1 + 3 * T
    rod_phi = sp.asin((e - a * sp.sin(theta)) / b)
    slider_x = a * sp.cos(theta) + b * sp.cos(rod_phi)
    expressions = {"crank.x": sp.S(0), "crank.y": sp.S(0), "crank.phi": theta,
                   "rod.x": a * sp.cos(theta), "rod.y": a * sp.sin(theta), "rod.phi": rod_phi,
                   "slider.x": slider_x, "slider.y": sp.S(e), "slider.phi": sp.S(0)}
    trajectory = symkin.solve(kernel_for(derive("offset_crank_slider"), backend))
    _check(trajectory, expressions)
    _check_point(trajectory, "slider", "pin", sp.Matrix([slider_x, e]))


# ----- driven by a slide driver --------------------------------------------------------------

def slide_closed_form(a=1.0, b=3.0, x0=3.0, amp=0.6) -> dict[str, sp.Expr]:
    x = x0 + amp * sp.sin(2 * T)
    theta = sp.acos((a**2 + x**2 - b**2) / (2 * a * x))  # law of cosines, crank above the axis
    A = a * sp.Matrix([sp.cos(theta), sp.sin(theta)])
    return {"crank.x": sp.S(0), "crank.y": sp.S(0), "crank.phi": theta,
            "rod.x": A[0], "rod.y": A[1], "rod.phi": sp.atan2(-A[1], x - A[0]),
            "slider.x": x, "slider.y": sp.S(0), "slider.phi": sp.S(0)}


@pytest.mark.parametrize("backend", BACKENDS)
def test_slide_driver(backend: str) -> None:
    trajectory = symkin.solve(kernel_for(derive("slide_driven"), backend))
    _check(trajectory, slide_closed_form())


# ----- driven by a point trajectory ----------------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
def test_point_trajectory_driver(backend: str) -> None:
    L = 2.0
    fx, fy = 1 + T, sp.sin(T) / 2
    xs = fx - sp.sqrt(L**2 - fy**2)
    expressions = {"slider.x": xs, "slider.y": sp.S(0), "slider.phi": sp.S(0),
                   "rod.x": xs, "rod.y": sp.S(0), "rod.phi": sp.asin(fy / L)}
    trajectory = symkin.solve(kernel_for(derive("point_trajectory"), backend))
    _check(trajectory, expressions)
    _check_point(trajectory, "rod", "tip", sp.Matrix([fx, fy]))
