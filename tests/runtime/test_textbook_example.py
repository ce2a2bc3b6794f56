"""The textbook crank-slider against the chapter's worked values (Examples 2.2 and 2.5)."""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from symkin.runtime.outputs.results import point_kinematics

ROOT_2PI = math.sqrt(2 * math.pi)
# Example 2.5 data
Q_STAR = [0, 0, math.pi, -1, 0, math.atan(4 / 3), 2, 4, 0]
DQ_STAR = [0, 0, ROOT_2PI, 0, -ROOT_2PI, ROOT_2PI / 3, -4 * ROOT_2PI / 3, 0, 0]
T_STAR = math.sqrt(math.pi / 2)

# Example 2.5 (j), copied from the book
PHI_Q_J = np.array([
    [-1, 0, 0, 0, 0, 0, 0, 0, 0],
    [0, -1, 0, 0, 0, 0, 0, 0, 0],
    [1, 0, 0, -1, 0, 0, 0, 0, 0],
    [0, 1, -1, 0, -1, 0, 0, 0, 0],
    [0, 0, 0, 1, 0, -4, -1, 0, 0],
    [0, 0, 0, 0, 1, 3, 0, -1, 0],
    [0, 0, 0, 0, 0, 0, 0, 0, 1],
    [0, 0, 0, 0, 0, 0, 0, -1, 0],
    [0, 0, 1, 0, 0, 0, 0, 0, 0],
], dtype=float)
PHI_T_K = np.array([0] * 8 + [-ROOT_2PI])
GAMMA_L = np.array([0, 0, -2 * math.pi, 0, 2 * math.pi / 3, 8 * math.pi / 9, 0, 0, 2])


def _evaluate(system, matrix) -> np.ndarray:
    values = {**dict(zip(system.q, Q_STAR)), **dict(zip(system.dq, DQ_STAR)),
              **dict(zip(system.p, system.p_values)), system.t: T_STAR}
    return np.array(sp.Matrix(matrix).evalf(30, subs=values), dtype=float)


def test_row_and_coordinate_order(crank_slider_system) -> None:
    assert crank_slider_system.coordinates[:3] == ("crank.x", "crank.y", "crank.phi")
    assert [row.type for row in crank_slider_system.rows] == \
        ["revolute"] * 6 + ["prismatic"] * 2 + ["angle"]


def test_phi_is_example_2_7_b(crank_slider_system) -> None:
    x1, y1, f1, x2, y2, f2, x3, y3, f3 = crank_slider_system.q
    a, b, c = crank_slider_system.p
    t = crank_slider_system.t
    expected = [-x1, -y1, x1 + a * sp.cos(f1) - x2, y1 + a * sp.sin(f1) - y2,
                x2 + b * sp.cos(f2) - x3, y2 + b * sp.sin(f2) - y3, f3, c - y3,
                f1 - t**2 - sp.pi / 2]
    assert [sp.simplify(e - d) for e, d in zip(expected, crank_slider_system.phi)] == [0] * 9


def test_jacobian_equals_example_2_5_j(crank_slider_system) -> None:
    np.testing.assert_allclose(_evaluate(crank_slider_system, crank_slider_system.phi_q),
                               PHI_Q_J, rtol=0, atol=1e-14)


def test_phi_t_equals_example_2_5_k(crank_slider_system) -> None:
    np.testing.assert_allclose(_evaluate(crank_slider_system, crank_slider_system.phi_t)[:, 0],
                               PHI_T_K, rtol=0, atol=1e-14)


def test_gamma_equals_example_2_5_l(crank_slider_system) -> None:
    np.testing.assert_allclose(_evaluate(crank_slider_system, crank_slider_system.gamma)[:, 0],
                               GAMMA_L, rtol=0, atol=1e-14)


def test_point_kinematics_of_example_2_2() -> None:
    r, dr, ddr = point_kinematics([0, 1, math.atan(3 / 4)], [-1, 0, 0], [0, -1, 0.25], [5, 0])
    np.testing.assert_allclose(r, [4, 4], atol=1e-14)
    np.testing.assert_allclose(dr, [-1, 0], atol=1e-14)
    np.testing.assert_allclose(ddr, [-0.75, 0], atol=1e-14)
