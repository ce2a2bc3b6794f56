"""The spatial equations of motion symkin derives (M, h and the inverse dynamics' right-hand
side Q - M q̈ - h, whose M q̈ + h is grouped per body as Newton-Euler) against Lagrange's
equations of a kinetic energy written here, independently of symkin: per body
T = ½ m |ṙ + d/dt(A c)|² + ½ ω'ᵀ J' ω' with A(p) and ω' = 2 G(p) ṗ written out below, then
M = ∂²T/∂q̇² and h = (∂²T/∂q̇∂q) q̇ - ∂T/∂q by SymPy's differentiation.

Compared at random states, the Euler parameters deliberately off the unit sphere and ṗ not
orthogonal to p: the grouping is the same polynomial for any p, not only on the motion.
Two free bodies, each with an offset centre of mass and a full inertia tensor (one of them
given by parameters), gravity and a torque, so that Q is there too and rhs - Q is M q̈ + h."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import symkin
from symkin.spec.validate import from_dict

TWO_BODIES = {
    "name": "two_tumblers", "space": "3d",
    "parameters": {"m": 2.5, "Jxy": 0.03, "cx": 0.2},
    "bodies": {
        "box": {"q0": [0, 0, 0, 1, 0, 0, 0], "mass": "m", "com": ["cx", -0.1, 0.05],
                "inertia": [[0.4, "Jxy", 0.02], ["Jxy", 0.3, -0.01], [0.02, -0.01, 0.5]]},
        "plate": {"q0": [1, 0, 0, 1, 0, 0, 0], "mass": 1.5, "com": [0.0, 0.3, -0.2],
                  "inertia": [[0.2, 0, 0], [0, 0.25, 0.05], [0, 0.05, 0.3]]},
    },
    "forces": [{"type": "gravity", "g": [0, 0, -9.81]},
               {"type": "torque", "name": "spin", "body": "plate", "m": ["sin(t)", 0.2, 0.3]}],
    "time": {"t0": 0, "t1": 1, "dt": 0.1},
}
BODIES = {"box": ("m", ("cx", -0.1, 0.05),
                  (("0.4", "Jxy", "0.02"), ("Jxy", "0.3", "-0.01"), ("0.02", "-0.01", "0.5"))),
          "plate": ("1.5", ("0", "0.3", "-0.2"),
                    (("0.2", "0", "0"), ("0", "0.25", "0.05"), ("0", "0.05", "0.3")))}
STATES = 5


@pytest.fixture(scope="module")
def system():
    return symkin.derive(from_dict(TWO_BODIES))


def _rotation(e0, e1, e2, e3) -> sp.Matrix:
    v = sp.Matrix([e1, e2, e3])
    skew = sp.Matrix([[0, -e3, e2], [e3, 0, -e1], [-e2, e1, 0]])
    return (e0**2 - (v.T * v)[0, 0]) * sp.eye(3) + 2 * v * v.T + 2 * e0 * skew


def _reference(system) -> tuple[sp.Matrix, sp.Matrix, sp.Expr]:
    """M, h and T of Lagrange's equations, from the kinetic energy written here."""
    names = {str(symbol): symbol for symbol in system.p}
    position = dict(zip(system.coordinates, system.q))
    rate = dict(zip(system.coordinates, system.dq))

    def number(text: str) -> sp.Expr:
        return names[text] if text in names else sp.Rational(text)

    kinetic = sp.Integer(0)
    for body, (mass, com, inertia) in BODIES.items():
        parts = ("x", "y", "z", "e0", "e1", "e2", "e3")
        q = [position[f"{body}.{part}"] for part in parts]
        dq = [rate[f"{body}.{part}"] for part in parts]
        centre = sp.Matrix(q[:3]) + _rotation(*q[3:]) * sp.Matrix([number(c) for c in com])
        velocity = sum((centre.diff(s) * ds for s, ds in zip(q, dq)), sp.zeros(3, 1))
        e0, e1, e2, e3 = q[3:]
        frame_rates = sp.Matrix([[-e1, e0, e3, -e2], [-e2, -e3, e0, e1], [-e3, e2, -e1, e0]])
        omega = 2 * frame_rates * sp.Matrix(dq[3:])
        tensor = sp.Matrix([[number(j) for j in row] for row in inertia])
        kinetic += (number(mass) * (velocity.T * velocity)[0, 0] / 2
                    + (omega.T * tensor * omega)[0, 0] / 2)
    qs, dqs = list(system.q), list(system.dq)
    momentum = sp.Matrix([kinetic.diff(s) for s in dqs])
    mass_matrix = momentum.jacobian(dqs)
    h = momentum.jacobian(qs) * sp.Matrix(dqs) - sp.Matrix([kinetic.diff(s) for s in qs])
    return mass_matrix, h, kinetic


def _values(system, seed: int) -> dict[sp.Symbol, float]:
    """A random state: q (Euler parameters not unit), dq, ddq, t; the nominal parameters."""
    generator = np.random.default_rng(seed)
    n = len(system.q)
    draws = generator.uniform(-1.5, 1.5, 3 * n + 1)
    symbols = (*system.q, *system.dq, *system.dynamics.ddq, system.t)
    return {**dict(zip(symbols, draws.tolist())), **dict(zip(system.p, system.p_values))}


def _number(matrix: sp.MatrixBase, values: dict[sp.Symbol, float]) -> np.ndarray:
    return np.array(sp.Matrix(matrix).xreplace(values).evalf(30), dtype=float)


def test_mass_velocity_terms_and_rhs_are_lagranges_equations(system) -> None:
    dynamics = system.dynamics
    mass_matrix, h, kinetic = _reference(system)
    # M q̈ + h as derived, formed once: the states only substitute into it. The reference's
    # M q̈ + h is formed from its M and h evaluated at 30 digits (a product of floats, 1e-16).
    inertial_rows = sp.Matrix(dynamics.applied - dynamics.rhs)
    for seed in range(STATES):
        values = _values(system, seed)
        expected_mass = _number(mass_matrix, values)
        expected_h = _number(h, values)
        scale = max(np.abs(expected_mass).max(), np.abs(expected_h).max())
        np.testing.assert_allclose(_number(dynamics.mass_matrix, values), expected_mass,
                                   rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(_number(dynamics.velocity_terms, values), expected_h,
                                   rtol=0, atol=1e-12 * scale)
        inertial = _number(inertial_rows, values)
        ddq = np.array([values[symbol] for symbol in dynamics.ddq], dtype=float)
        expected = expected_mass @ ddq[:, None] + expected_h
        np.testing.assert_allclose(inertial, expected, rtol=0,
                                   atol=1e-12 * np.abs(expected).max())
        assert float(dynamics.kinetic.xreplace(values)) == pytest.approx(
            float(kinetic.xreplace(values)), rel=1e-12)


def test_the_inertial_rows_are_not_formed_from_the_dense_block(system) -> None:
    """The right-hand side's size (operations after common subexpressions) stays well below
    that of Q - M q̈ - h written from the 7 x 7 blocks: the structure the code runs on."""
    dynamics = system.dynamics
    grouped = _cse_ops(list(dynamics.rhs))
    dense = _cse_ops(list(dynamics.applied - dynamics.mass_matrix * sp.Matrix(dynamics.ddq)
                          - dynamics.velocity_terms))
    assert grouped < 0.8 * dense, (grouped, dense)


def _cse_ops(expressions: list[sp.Expr]) -> int:
    replacements, reduced = sp.cse(expressions)
    return sum(sp.count_ops(e) for _, e in replacements) + sum(sp.count_ops(e) for e in reduced)
