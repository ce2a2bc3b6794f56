"""Phi_q, Phi_t and Gamma against finite differences of Phi, at random states.

The mechanism below uses every constraint type symkin knows, including a custom joint and a
custom driver whose equation mixes coordinates and time (so Phi_tq enters Gamma). Only Phi is
taken from symkin; its derivatives are estimated numerically with 40-digit arithmetic
(mpmath), so the differences are accurate to far better than the 1e-12 tolerance used:

    Phi_q[:, k]  ~ (Phi(q + h e_k, t) - Phi(q - h e_k, t)) / 2h
    Phi_t        ~ (Phi(q, t + h) - Phi(q, t - h)) / 2h
    Gamma: along the path q(s) = q + dq s, t(s) = t + s (so q' = dq, q'' = 0),
           d2Phi/ds2 = Phi_q q'' - Gamma = -Gamma, hence
    Gamma        ~ -(Phi(s = h) - 2 Phi(0) + Phi(s = -h)) / h^2
"""

from __future__ import annotations

import functools
import random

import mpmath
import pytest
import sympy as sp

from symkin.spec.validate import from_dict
from symkin.symbolic.derivation import System, derive

DIGITS = 40
STEP = mpmath.mpf("1e-12")
TOLERANCE = 1e-12

EVERY_CONSTRAINT = {
    "name": "every_constraint",
    "parameters": {"a": 1.5, "b": "sqrt(2)", "c": 0.75, "w": "2*pi/3", "e": 0.2},
    "bodies": {
        "crank": {"points": {"tip": ["a", 0]}},
        "slider": {},
        "lever": {"points": {"end": ["b", "c"]}},
        "arm": {},
        "tool": {"points": {"P": ["-c", "a/2"]}},
        "free": {},
        "bar": {"q0": [0.5, 1, 0.3], "points": {"Q": [0.4, "-c"]}},
    },
    "joints": [
        {"type": "revolute", "i": "ground", "j": "crank", "sA": [0.1, -0.2], "sB": [0, 0]},
        {"type": "prismatic", "i": "slider", "j": "crank", "sA": ["c", 0.3], "sB": "tip",
         "v": [0.6, "-b/2"], "phi0": "pi/7"},
        {"type": "pin_slot", "i": "slider", "j": "lever", "sA": [0.2, 0.1],
         "sB": [0.4, "-a"], "v": ["c", 1]},
        {"type": "revolute", "i": "tool", "j": "free", "sA": "P", "sB": [-0.5, "b"]},
        {"type": "custom", "name": "cam",
         "equations": ["lever.x**2 + lever.y*arm.phi - a*cos(arm.phi - lever.phi)"]},
        {"type": "distance", "i": "crank", "j": "bar", "A": "tip", "B": "Q", "length": "a + c"},
        {"type": "distance", "i": "bar", "j": "ground", "A": [0.1, "b"], "B": [2, -1]},
    ],
    "drivers": [
        {"type": "displacement", "i": "lever", "j": "arm", "sA": "end", "sB": [0.3, -0.4],
         "f": ["a*cos(w*t)", "c*sin(w*t) + t**2"]},
        {"type": "displacement_local", "i": "arm", "j": "tool", "sA": [0.5, 0.5], "sB": "P",
         "f": [{"poly": [0.1, "a", -0.3, "e"]}, "exp(-t)*sin(3*t)"]},
        {"type": "trajectory", "j": "free", "sB": [0.25, "c"],
         "f": ["1 + b*cos(t)", "atan(t)"]},
        {"type": "angle", "i": "tool", "j": "arm", "theta": "w*t + e*sin(2*t)"},
        {"type": "slide", "i": "crank", "j": "slider", "sA": [0.3, 0.2], "sB": [-0.1, 0.5],
         "u": [1, "e"], "f": "c*t**3 - t"},
        {"type": "custom", "name": "coupled",
         "equations": ["sin(w*t)*(free.phi + tool.x) - cos(t)*free.x*free.y + e*t*crank.phi",
                       "free.phi*arm.y + tool.phi*t**2 - e"]},
        {"type": "angle", "i": "bar", "j": "ground", "theta": "e*t**2"},
    ],
    "time": {"t0": 0, "t1": 2, "dt": 0.1},
}


# The higher pairs (gear, rack, point on a curve, cam with a roller and with a flat face),
# with their bodies otherwise free and held by one custom driver: Phi only has to be
# differentiable, not solvable, for the differences below.
_PINNED = ("sun", "planet", "arm")  # their x and y held by the revolutes
_FREE = ("sun", "planet", "arm", "pinion", "rack", "cam", "roller", "flat", "plate", "pin")
HIGHER_PAIRS = {
    "name": "higher_pairs",
    "parameters": {"rs": 1.0, "rp": 0.5, "rr": 0.2, "a": 1.5, "b": 1.0, "c": 0.3, "e": 0.3},
    "bodies": {**{body: {} for body in _FREE},
               "pinion": {"q0": [0, 1, 0], "points": {"C": [0.1, -0.05]}},
               "roller": {"points": {"R": [0.2, 0.4]}}},
    "joints": [
        # the gears' centres on their carrier, as a gear pair requires (ring: the ground)
        {"type": "revolute", "i": "arm", "j": "sun", "sA": [0, 0], "sB": [0, 0]},
        {"type": "revolute", "i": "arm", "j": "planet", "sA": ["rs + rp", 0], "sB": [0, 0]},
        {"type": "revolute", "i": "ground", "j": "arm", "sA": [0, 0], "sB": [0, 0]},
        {"type": "gear", "name": "g1", "i": "sun", "j": "planet", "radii": ["rs", "rp"],
         "carrier": "arm"},
        {"type": "gear", "name": "g2", "i": "planet", "j": "ground", "radii": ["rp", "rs + 2*rp"],
         "carrier": "arm", "internal": True, "offset": "c"},
        {"type": "rack", "name": "r1", "i": "pinion", "j": "rack", "radius": "rp",
         "axis": [1, "e"], "at": "C"},
        {"type": "cam", "name": "k1", "i": "cam", "j": "roller",
         "profile": {"polar": "2 + e*sin(s) + 0.1*cos(2*s)"},
         "follower": {"roller": "rr", "at": "R"}, "s0": 0.3},
        {"type": "cam", "name": "k2", "i": "cam", "j": "flat",
         "profile": ["a*cos(s) + 0.1", "b*sin(s)"],
         "follower": {"flat": True, "at": [0.1, 0.2], "normal": [0.3, 1]}, "s0": 1},
        {"type": "point_on_curve", "name": "c1", "i": "plate", "j": "pin", "point": [0.2, "c"],
         "curve": ["a*cos(s)", "b*sin(s) + c*s"], "s0": 0.5},
    ],
    "drivers": [{"type": "custom", "name": "hold", "equations": [
        f"{body}.{part} - {0.1 * k}*t" for k, (body, part) in enumerate(
            (body, part) for body in _FREE for part in ("x", "y", "phi")
            if body not in _PINNED or part == "phi")][:18]}],
    "time": {"t0": 0, "t1": 1, "dt": 0.1},
}


@functools.cache
def _derived(name: str) -> System:
    """Each mechanism derived once for every test here."""
    return derive(from_dict({"every_constraint": EVERY_CONSTRAINT,
                             "higher_pairs": HIGHER_PAIRS}[name]))


@pytest.fixture(scope="module", params=["every_constraint", "higher_pairs"])
def system(request) -> System:
    return _derived(request.param)


@pytest.fixture(scope="module")
def functions(system: System):
    """Phi, Phi_q, Phi_t, Gamma as mpmath functions of (q, dq, t) at the nominal parameters."""
    values = {p: sp.Float(v, DIGITS) for p, v in zip(system.p, system.p_values)}
    arguments = (system.q, system.dq, system.t)

    def compile_(matrix: sp.MatrixBase):
        # cse: the printer walks each shared subexpression once (the 49 x 49 Phi_q lambdified
        # 4x faster); the same expressions, evaluated at 40 digits
        return sp.lambdify(arguments, sp.Matrix(matrix).subs(values), modules="mpmath",
                           cse=True)

    return {name: compile_(getattr(system, name)) for name in ("phi", "phi_q", "phi_t", "gamma")}


def _states(count: int, size: int, seed: int) -> list[tuple[list, list, mpmath.mpf]]:
    rng = random.Random(seed)
    return [([mpmath.mpf(rng.uniform(-2, 2)) for _ in range(size)],
             [mpmath.mpf(rng.uniform(-3, 3)) for _ in range(size)],
             mpmath.mpf(rng.uniform(0, 2))) for _ in range(count)]


def _column(matrix) -> list:
    return [matrix[r, 0] for r in range(matrix.rows)]


def _close(derived, estimate, what: str) -> None:
    scale = max(1, max(abs(x) for x in estimate))
    worst = max(abs(a - b) for a, b in zip(derived, estimate))
    assert worst <= TOLERANCE * scale, f"{what}: largest difference {mpmath.nstr(worst, 3)}"


def test_every_constraint_type_is_present() -> None:
    from symkin import pairs
    systems = [_derived(name) for name in ("every_constraint", "higher_pairs")]
    types = {row.type for system in systems for row in system.rows}
    assert types == {kind.name for kind in pairs.TYPES}
    assert [len(system.q) for system in systems] == [21, 33]
    assert all(len(system.q) == len(system.rows) for system in systems)


@pytest.mark.parametrize("state", range(4))
def test_phi_q_matches_finite_differences(system: System, functions, state: int) -> None:
    with mpmath.workdps(DIGITS):
        q, dq, t = _states(4, len(system.q), seed=1)[state]
        jacobian = functions["phi_q"](q, dq, t)
        for k in range(len(q)):
            plus, minus = list(q), list(q)
            plus[k] += STEP
            minus[k] -= STEP
            estimate = [(a - b) / (2 * STEP) for a, b in zip(
                _column(functions["phi"](plus, dq, t)), _column(functions["phi"](minus, dq, t)))]
            derived = [jacobian[r, k] for r in range(jacobian.rows)]
            _close(derived, estimate, f"Phi_q column {system.coordinates[k]}")


@pytest.mark.parametrize("state", range(4))
def test_phi_t_matches_finite_differences(system: System, functions, state: int) -> None:
    with mpmath.workdps(DIGITS):
        q, dq, t = _states(4, len(system.q), seed=2)[state]
        phi = functions["phi"]
        estimate = [(a - b) / (2 * STEP) for a, b in zip(
            _column(phi(q, dq, t + STEP)), _column(phi(q, dq, t - STEP)))]
        _close(_column(functions["phi_t"](q, dq, t)), estimate, "Phi_t")


@pytest.mark.parametrize("state", range(4))
def test_gamma_matches_second_difference_along_a_path(system: System, functions,
                                                     state: int) -> None:
    with mpmath.workdps(DIGITS):
        q, dq, t = _states(4, len(system.q), seed=3)[state]
        step = mpmath.mpf("1e-10")  # a second difference: error ~ eps / h^2 = 1e-20

        def along(s):
            return _column(functions["phi"]([a + b * s for a, b in zip(q, dq)], dq, t + s))

        ahead, here, behind = along(step), along(0), along(-step)
        estimate = [-(a - 2 * b + c) / step**2 for a, b, c in zip(ahead, here, behind)]
        _close(_column(functions["gamma"](q, dq, t)), estimate, "Gamma")


def test_custom_driver_gamma_has_the_mixed_term(system: System) -> None:
    """The coupled driver depends on q and t together, so Phi_qt != 0 for its row."""
    if system.name != "every_constraint":
        pytest.skip("the coupled driver is in the first mechanism")
    row = next(r for r, label in enumerate(system.rows) if label.name == "coupled")
    mixed = [sp.diff(system.phi_q[row, k], system.t) for k in range(len(system.q))]
    assert any(m != 0 for m in mixed)
    # -2 Phi_qt dq puts terms linear in the velocities into Gamma.
    linear = [sp.diff(system.gamma[row], dq).subs({d: 0 for d in system.dq}) for dq in system.dq]
    assert any(sp.simplify(term) != 0 for term in linear)


def test_chapter_pairs_touch_at_most_six_columns(system: System) -> None:
    counts: dict[int, int] = {}
    for row, _ in system.pattern():
        counts[row] = counts.get(row, 0) + 1
    for row, label in enumerate(system.rows):
        if label.type not in ("custom", "cam", "point_on_curve"):
            assert counts.get(row, 0) <= 6, str(label)
        elif label.type != "custom":  # the two bodies' six, and the contact parameter s
            assert counts.get(row, 0) <= 7, str(label)
