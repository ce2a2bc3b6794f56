"""Phi_q, Phi_t and Gamma of every spatial joint and driver against finite differences of
Phi, at random states (Euler parameters not normalised: the rows are functions of any q).

Only Phi comes from symkin; its derivatives are estimated with 40-digit arithmetic (mpmath):

    Phi_q[:, k]  ~ (Phi(q + h e_k, t) - Phi(q - h e_k, t)) / 2h
    Phi_t        ~ (Phi(q, t + h) - Phi(q, t - h)) / 2h
    Gamma        ~ -(Phi(s = h) - 2 Phi(0) + Phi(s = -h)) / h^2 along q + dq s, t + s
"""

from __future__ import annotations

import random

import mpmath
import pytest
import sympy as sp

from symkin import pairs
from symkin.spec.validate import from_dict
from symkin.symbolic.derivation import System, derive

DIGITS = 40
STEP = mpmath.mpf("1e-12")
TOLERANCE = 1e-12

# Every spatial joint and driver type, with parameters in points and axes.
EVERY_SPATIAL = {
    "name": "every_spatial", "space": "3d", "layout": "drawn",
    "parameters": {"a": 0.7, "b": "sqrt(2)/2", "w": "2*pi/3", "g": 0.3},
    "bodies": {
        "ground": {"points": {"O": [0, 0, 0], "G": [2, -1, "b"]}},
        "b1": {"points": {"O": [0, 0, 0], "P": ["a", 0.1, 0.2]}},
        "b2": {"points": {"P": ["a", 0.1, 0.2], "U": [1, 1, "b"]}},
        "b3": {"points": {"C": [0.5, -1, 0], "D": [0.5, -1, 1]}},
        "b4": {"points": {"D": [0.5, -1, 1], "E": [1, -1, 1.5]}},
        "b5": {"points": {"U": [1, 1, "b"], "F": [1.5, 1.2, 0]}},
        "b6": {"points": {"H": [2, 2, 1]}},
        "b7": {"points": {"K": [-1, 0.5, 0.25], "L": [-1, 1, 0]}},
    },
    "joints": [
        {"type": "spherical", "i": "ground", "j": "b1", "at": "O"},
        {"type": "revolute", "name": "hinge", "i": "b1", "j": "b2", "at": "P",
         "axis": ["b", 1, "g"]},
        {"type": "cylindrical", "name": "pillar", "i": "ground", "j": "b3", "at": "C",
         "axis": [0, "g", 1]},
        {"type": "prismatic", "name": "rail", "i": "b3", "j": "b4", "at": "D",
         "axis": [1, 0, 1]},
        {"type": "universal", "i": "b2", "j": "b5", "at": "U",
         "axes": [[1, 0, 0], [0, "b", "b"]]},
        {"type": "distance", "i": "b5", "j": "b6", "A": "F", "B": "H"},
        {"type": "distance", "name": "given", "i": "b4", "j": "b6", "A": "E", "B": "H",
         "length": "a + g"},
        {"type": "custom", "name": "cam", "equations": ["b6.x*b6.e1 + b7.z - a*cos(b6.e2)"]},
    ],
    "drivers": [
        {"type": "angle", "joint": "hinge", "theta": "w*t + g*sin(2*t)"},
        {"type": "angle", "joint": "pillar", "theta": "-w*t"},
        {"type": "slide", "joint": "rail", "f": "g*t**3 - t"},
        {"type": "slide", "joint": "pillar", "f": {"poly": [0, "a", -0.3]}},
        {"type": "distance", "i": "ground", "j": "b7", "A": "G", "B": "K",
         "f": "3 + g*sin(t)"},
        {"type": "trajectory", "j": "b7", "point": "L", "f": ["cos(t)", "atan(t)", "g*t"]},
        {"type": "trajectory", "j": "b1", "point": [0, 1, 0], "f": ["t", "1", "0"]},
        {"type": "custom", "name": "coupled",
         "equations": ["sin(w*t)*(b6.e3 + b5.x) - cos(t)*b7.e0*b7.y + g*t*b1.e2",
                       "b6.e0*b2.y + b5.e1*t**2 - g", "b6.z - t", "b5.e2*b5.e3 - a*t",
                       "b7.e1 + b7.e2*t", "b6.e1 - b6.e2*t**2", "b3.e0 - cos(t)"]},
    ],
    "time": {"t0": 0, "t1": 2, "dt": 0.1},
}


@pytest.fixture(scope="module")
def system() -> System:
    return derive(from_dict(EVERY_SPATIAL))


@pytest.fixture(scope="module")
def functions(system: System):
    # The parameters are an argument, given as the 40-digit values of their floats (what
    # substituting sp.Float(v, 40) into the matrices gave, without walking them to do it).
    values = [mpmath.mpf(v) for v in system.p_values]
    arguments = (system.q, system.dq, system.t, system.p)

    def compile_(matrix: sp.MatrixBase):
        # cse: the printer walks each shared subexpression once (the 49 x 49 Phi_q lambdified
        # 4x faster); the same expressions, evaluated at 40 digits
        function = sp.lambdify(arguments, sp.Matrix(matrix), modules="mpmath", cse=True)
        return lambda q, dq, t: function(q, dq, t, values)

    return {name: compile_(getattr(system, name)) for name in ("phi", "phi_q", "phi_t", "gamma")}


def _state(size: int, seed: int) -> tuple[list, list, mpmath.mpf]:
    rng = random.Random(seed)
    return ([mpmath.mpf(rng.uniform(-1.5, 1.5)) for _ in range(size)],
            [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(size)], mpmath.mpf(rng.uniform(0, 2)))


def _column(matrix) -> list:
    return [matrix[r, 0] for r in range(matrix.rows)]


def _close(derived, estimate, what: str) -> None:
    scale = max(1, max(abs(x) for x in estimate))
    worst = max(abs(a - b) for a, b in zip(derived, estimate))
    assert worst <= TOLERANCE * scale, f"{what}: largest difference {mpmath.nstr(worst, 3)}"


def test_every_spatial_type_is_present(system: System) -> None:
    found = {(row.section, row.type) for row in system.rows}
    wanted = {(section, kind.name) for kind in pairs.SPATIAL_TYPES for section in kind.sections}
    assert wanted <= found
    assert sum(row.part == "normalisation" for row in system.rows) == 7
    assert len(system.q) == len(system.rows) == 49


@pytest.mark.parametrize("seed", [1, 2])
def test_phi_q_matches_finite_differences(system: System, functions, seed: int) -> None:
    with mpmath.workdps(DIGITS):
        q, dq, t = _state(len(system.q), seed)
        jacobian = functions["phi_q"](q, dq, t)
        for k in range(len(q)):
            plus, minus = list(q), list(q)
            plus[k] += STEP
            minus[k] -= STEP
            estimate = [(a - b) / (2 * STEP) for a, b in zip(
                _column(functions["phi"](plus, dq, t)), _column(functions["phi"](minus, dq, t)))]
            _close([jacobian[r, k] for r in range(jacobian.rows)], estimate,
                   f"Phi_q column {system.coordinates[k]}")


@pytest.mark.parametrize("seed", [3, 4])
def test_phi_t_matches_finite_differences(system: System, functions, seed: int) -> None:
    with mpmath.workdps(DIGITS):
        q, dq, t = _state(len(system.q), seed)
        phi = functions["phi"]
        estimate = [(a - b) / (2 * STEP) for a, b in zip(
            _column(phi(q, dq, t + STEP)), _column(phi(q, dq, t - STEP)))]
        _close(_column(functions["phi_t"](q, dq, t)), estimate, "Phi_t")


@pytest.mark.parametrize("seed", [5, 6])
def test_gamma_matches_second_difference_along_a_path(system: System, functions,
                                                     seed: int) -> None:
    with mpmath.workdps(DIGITS):
        q, dq, t = _state(len(system.q), seed)
        step = mpmath.mpf("1e-10")

        def along(s):
            return _column(functions["phi"]([a + b * s for a, b in zip(q, dq)], dq, t + s))

        ahead, here, behind = along(step), along(0), along(-step)
        estimate = [-(a - 2 * b + c) / step**2 for a, b, c in zip(ahead, here, behind)]
        _close(_column(functions["gamma"](q, dq, t)), estimate, "Gamma")


def test_the_drawing_satisfies_every_joint(system: System, functions) -> None:
    """At the drawn q0 (identity Euler parameters) every joint row is zero: the conversion
    put each joint's points and axes where they were drawn (Phi at 40 digits; the joint rows
    do not read t or dq)."""
    with mpmath.workdps(DIGITS):
        q0 = [mpmath.mpf(float(x)) for x in system.q0]
        phi = _column(functions["phi"](q0, [mpmath.mpf(0)] * len(q0), mpmath.mpf(0)))
    for value, label in zip(phi, system.rows, strict=True):
        if label.section == "joints" and label.type != "custom" and label.name != "given":
            assert abs(float(value)) < 1e-14, str(label)
