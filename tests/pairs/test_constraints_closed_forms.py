"""Every pair and driver against the chapter's closed forms, symbolically.

Each test builds a two-body mechanism whose vectors sA, sB, v, u are parameters, so SymPy
sees them as generic symbols, derives it with symkin, and compares the rows the constraint
owns with the formulas of the chapter, written out below from the source chapter (section 2.4):

    revolute             Phi_q blocks (2.31)-(2.34), Gamma (2.42)
    prismatic            angle row (2.43)-(2.48), perpendicular row (2.49)-(2.52), (2.59)
    pin_slot             the perpendicular row alone
    displacement         (2.24) with (2.60)
    trajectory           (2.26) = (2.24) with i = ground
    displacement_local   (2.61)-(2.64), Gamma (2.71)
    angle                (2.43)-(2.48) plus theta's time derivatives (2.27)
    slide                (2.49)-(2.52) and (2.59) with u for v, plus f's derivatives (2.28)

Each case runs with both bodies moving and with the ground on either side.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import pytest
import sympy as sp

from symkin.spec.validate import from_dict
from symkin.symbolic.derivation import System, derive

OMEGA = sp.Matrix([[0, -1], [1, 0]])
I2 = sp.eye(2)
t = sp.Symbol("t", real=True)


def _p(name: str) -> sp.Symbol:
    return sp.Symbol(name, real=True)


sA = sp.Matrix([_p("sAx"), _p("sAy")])
sB = sp.Matrix([_p("sBx"), _p("sBy")])
v = sp.Matrix([_p("vx"), _p("vy")])
u = sp.Matrix([_p("ux"), _p("uy")])
phi0, c1, c2, w = _p("phi0"), _p("c1"), _p("c2"), _p("w")
# Generic-enough time functions, with non-zero first and second derivatives.
FX, FY = c1 * sp.sin(w * t) + c2 * t**3, c2 * sp.cos(w * t) - c1 * t**2
FX_TEXT, FY_TEXT = "c1*sin(w*t) + c2*t**3", "c2*cos(w*t) - c1*t**2"

PARAMETERS = {"sAx": 0.3, "sAy": -0.7, "sBx": 1.1, "sBy": 0.4, "vx": 0.6, "vy": 0.8,
              "ux": -0.28, "uy": 0.96, "phi0": 0.25, "c1": 0.7, "c2": 1.3, "w": 2.0}


def R(phi: sp.Expr) -> sp.Matrix:
    return sp.Matrix([[sp.cos(phi), -sp.sin(phi)], [sp.sin(phi), sp.cos(phi)]])


@dataclass(frozen=True)
class Pose:
    """Position, angle and their rates of one body; all zero for the ground."""

    r: sp.Matrix
    phi: sp.Expr
    dr: sp.Matrix
    dphi: sp.Expr

    @property
    def R(self) -> sp.Matrix:
        return R(self.phi)


def pose(body: str) -> Pose:
    if body == "ground":
        return Pose(sp.zeros(2, 1), sp.Integer(0), sp.zeros(2, 1), sp.Integer(0))
    x, y, phi = (_p(f"{body}.{c}") for c in ("x", "y", "phi"))
    dx, dy, dphi = (_p(f"{body}.{c}_t") for c in ("x", "y", "phi"))
    return Pose(sp.Matrix([x, y]), phi, sp.Matrix([dx, dy]), dphi)


@dataclass(frozen=True)
class ClosedForm:
    """The chapter's formulas for one constraint: Phi, Jacobian blocks, Phi_t, Gamma."""

    phi: sp.Matrix
    r_i: sp.Matrix
    phi_i: sp.Matrix
    r_j: sp.Matrix
    phi_j: sp.Matrix
    phi_t: sp.Matrix
    gamma: sp.Matrix


def _stack(*forms: ClosedForm) -> ClosedForm:
    fields = ClosedForm.__dataclass_fields__
    return ClosedForm(**{k: sp.Matrix.vstack(*(getattr(f, k) for f in forms)) for k in fields})


def revolute_form(i: Pose, j: Pose) -> ClosedForm:
    return ClosedForm(
        phi=i.r + i.R * sA - j.r - j.R * sB,                                    # (2.18)
        r_i=I2, phi_i=OMEGA * i.R * sA, r_j=-I2, phi_j=-OMEGA * j.R * sB,       # (2.31)-(2.34)
        phi_t=sp.zeros(2, 1),                                                   # (2.30)
        gamma=i.R * sA * i.dphi**2 - j.R * sB * j.dphi**2)                      # (2.42)


def angle_form(i: Pose, j: Pose, theta: sp.Expr) -> ClosedForm:
    return ClosedForm(                                                          # (2.19), (2.27)
        phi=sp.Matrix([i.phi - j.phi - theta]),
        r_i=sp.zeros(1, 2), phi_i=sp.Matrix([1]), r_j=sp.zeros(1, 2), phi_j=sp.Matrix([-1]),
        phi_t=sp.Matrix([-sp.diff(theta, t)]),
        gamma=sp.Matrix([sp.diff(theta, t, 2)]))                                # (2.48) + theta''


def perpendicular_form(i: Pose, j: Pose, vec: sp.Matrix, f: sp.Expr) -> ClosedForm:
    h = j.R * vec
    return ClosedForm(
        phi=h.T * (j.r + j.R * sB - i.r - i.R * sA) - sp.Matrix([f]),          # (2.22), (2.28)
        r_i=-h.T, phi_i=-h.T * OMEGA * i.R * sA,                                # (2.49), (2.50)
        r_j=h.T, phi_j=-h.T * OMEGA * (j.r - i.r - i.R * sA),                   # (2.51), (2.52)
        phi_t=sp.Matrix([-sp.diff(f, t)]),
        gamma=h.T * (2 * OMEGA * (j.dr - i.dr) * j.dphi + (j.r - i.r) * j.dphi**2  # (2.59)
                     - i.R * sA * (j.dphi - i.dphi)**2) + sp.Matrix([sp.diff(f, t, 2)]))


def displacement_form(i: Pose, j: Pose) -> ClosedForm:
    f = sp.Matrix([FX, FY])
    return ClosedForm(
        phi=j.r + j.R * sB - i.r - i.R * sA - f,                                # (2.24)
        r_i=-I2, phi_i=-OMEGA * i.R * sA, r_j=I2, phi_j=OMEGA * j.R * sB,
        phi_t=-sp.diff(f, t),                                                   # (2.60)
        gamma=j.R * sB * j.dphi**2 - i.R * sA * i.dphi**2 + sp.diff(f, t, 2))


def displacement_local_form(i: Pose, j: Pose) -> ClosedForm:
    f = sp.Matrix([FX, FY])
    return ClosedForm(
        phi=i.R.T * (j.r + j.R * sB) - (i.R.T * i.r + sA) - f,                  # (2.25)
        r_i=-i.R.T,                                                             # (2.61)
        phi_i=-i.R.T * OMEGA * (j.r + j.R * sB - i.r),                          # (2.62)
        r_j=i.R.T,  # (2.63) prints R_j^T: a misprint, (2.65) and (2.70) use R_i^T
        phi_j=i.R.T * OMEGA * j.R * sB,                                         # (2.64)
        phi_t=-sp.diff(f, t),                                                   # (2.60)
        gamma=i.R.T * (2 * OMEGA * (j.dr - i.dr) * i.dphi + (j.r - i.r) * i.dphi**2  # (2.71)
                       + j.R * sB * (j.dphi - i.dphi)**2) + sp.diff(f, t, 2))


THETA = c1 * t**2 + c2 * sp.sin(w * t)
THETA_TEXT = "c1*t**2 + c2*sin(w*t)"
SLIDE_F = FX
VEC_A, VEC_B = ["sAx", "sAy"], ["sBx", "sBy"]


@dataclass(frozen=True)
class Case:
    """A constraint spec for the file, where it goes, and its closed form."""

    spec: dict
    section: str
    form: Callable[[Pose, Pose], ClosedForm]


CASES: dict[str, Case] = {
    "revolute": Case({"type": "revolute", "sA": VEC_A, "sB": VEC_B}, "joints", revolute_form),
    "prismatic": Case(
        {"type": "prismatic", "sA": VEC_A, "sB": VEC_B, "v": ["vx", "vy"], "phi0": "phi0"},
        "joints",
        lambda i, j: _stack(angle_form(i, j, phi0), perpendicular_form(i, j, v, 0))),
    "pin_slot": Case({"type": "pin_slot", "sA": VEC_A, "sB": VEC_B, "v": ["vx", "vy"]},
                     "joints", lambda i, j: perpendicular_form(i, j, v, 0)),
    "displacement": Case({"type": "displacement", "sA": VEC_A, "sB": VEC_B,
                          "f": [FX_TEXT, FY_TEXT]}, "drivers", displacement_form),
    "displacement_local": Case({"type": "displacement_local", "sA": VEC_A, "sB": VEC_B,
                                "f": [FX_TEXT, FY_TEXT]}, "drivers", displacement_local_form),
    "angle": Case({"type": "angle", "theta": THETA_TEXT}, "drivers",
                  lambda i, j: angle_form(i, j, THETA)),
    "slide": Case({"type": "slide", "sA": VEC_A, "sB": VEC_B, "u": ["ux", "uy"],
                   "f": FX_TEXT}, "drivers",
                  lambda i, j: perpendicular_form(i, j, u, SLIDE_F)),
}

PAIRS = [("b1", "b2"), ("ground", "b2"), ("b1", "ground")]
COORDINATES = ("b1.x", "b1.y", "b1.phi", "b2.x", "b2.y", "b2.phi")


def build(spec: dict, section: str) -> System:
    """Two free bodies, the constraint under test first, and a filler custom driver so that
    the driving equations match the degrees of freedom (6 coordinates in all)."""
    rows = {"revolute": 2, "prismatic": 2, "pin_slot": 1, "displacement": 2,
            "displacement_local": 2, "trajectory": 2, "angle": 1, "slide": 1}[spec["type"]]
    filler = {"type": "custom", "equations": list(COORDINATES[:6 - rows])}
    mech = {
        "name": "closed_form", "parameters": PARAMETERS,
        "bodies": {"b1": {}, "b2": {}},
        "joints": [spec] if section == "joints" else [],
        "drivers": [spec, filler] if section == "drivers" else [filler],
        "time": {"t0": 0, "t1": 1, "dt": 0.1},
    }
    return derive(from_dict(mech))


def expected_jacobian(form: ClosedForm, i: str, j: str) -> sp.Matrix:
    """Place the blocks of bodies i and j into the 6 columns of b1 and b2."""
    rows = form.phi.rows
    jacobian = sp.zeros(rows, 6)
    for body, r_block, phi_block in ((i, form.r_i, form.phi_i), (j, form.r_j, form.phi_j)):
        if body != "ground":
            start = 0 if body == "b1" else 3
            jacobian[:, start:start + 2] += r_block
            jacobian[:, start + 2] += phi_block
    return jacobian


def assert_same(derived: sp.MatrixBase, expected: sp.MatrixBase, what: str) -> None:
    difference = (sp.Matrix(derived) - sp.Matrix(expected)).applyfunc(
        lambda e: sp.simplify(sp.expand_trig(e)))
    assert difference == sp.zeros(*difference.shape), f"{what}: derived - closed form = " \
        f"{difference}"


@pytest.mark.parametrize("i,j", PAIRS, ids=["moving-moving", "ground-j", "i-ground"])
@pytest.mark.parametrize("kind", sorted(CASES))
def test_constraint_matches_closed_form(kind: str, i: str, j: str) -> None:
    case = CASES[kind]
    system = build({**case.spec, "i": i, "j": j}, case.section)
    form = case.form(pose(i), pose(j))
    k = form.phi.rows
    assert [row.type for row in system.rows[:k]] == [kind] * k
    assert tuple(system.coordinates) == COORDINATES
    assert_same(system.phi[:k, :], form.phi, "Phi")
    assert_same(sp.Matrix(system.phi_q)[:k, :], expected_jacobian(form, i, j), "Phi_q")
    assert_same(system.phi_t[:k, :], form.phi_t, "Phi_t")
    assert_same(system.gamma[:k, :], form.gamma, "Gamma")


def test_trajectory_is_displacement_from_ground() -> None:
    """(2.26): a trajectory of point B is (2.24) with i = ground and sA = 0."""
    spec = {"type": "trajectory", "j": "b2", "sB": VEC_B, "f": [FX_TEXT, FY_TEXT]}
    system = build(spec, "drivers")
    body = pose("b2")
    f = sp.Matrix([FX, FY])
    expected = ClosedForm(
        phi=body.r + body.R * sB - f, r_i=sp.zeros(2, 2), phi_i=sp.zeros(2, 1),
        r_j=I2, phi_j=OMEGA * body.R * sB, phi_t=-sp.diff(f, t),
        gamma=body.R * sB * body.dphi**2 + sp.diff(f, t, 2))
    assert_same(system.phi[:2, :], expected.phi, "Phi")
    assert_same(sp.Matrix(system.phi_q)[:2, :], expected_jacobian(expected, "ground", "b2"),
                "Phi_q")
    assert_same(system.phi_t[:2, :], expected.phi_t, "Phi_t")
    assert_same(system.gamma[:2, :], expected.gamma, "Gamma")


@pytest.mark.parametrize("kind", sorted(CASES))
def test_only_the_two_bodies_columns_are_structural(kind: str) -> None:
    """A pair touches only q_i and q_j: with i = ground, b1's columns hold no entries."""
    case = CASES[kind]
    system = build({**case.spec, "i": "ground", "j": "b2"}, case.section)
    k = case.form(pose("ground"), pose("b2")).phi.rows
    assert all(col >= 3 for row, col in system.pattern() if row < k)
    assert all(len([c for r, c in system.pattern() if r == row]) <= 6 for row in range(k))
