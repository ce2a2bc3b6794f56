"""The constraint library: each kinematic pair and driver writes its rows of Phi (chapter 2.4).

Every unit takes the constraint's spec and a :class:`Context` (the symbols of the two bodies
and the resolved local vectors) and returns its equations in the chapter's vector form. Only
Phi is written here; Phi_q, Phi_t and Gamma are derived from it symbolically in
:mod:`symkin.symbolic.derivation`, and the tests check them against the chapter's closed forms.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import sympy as sp

from symkin.spec import expressions
from symkin.spec import schema as model
from symkin.spec.schema import GROUND
from symkin.spec.schema import MechanismSpec as Mechanism
from symkin.symbolic.symbols import Symbols

OMEGA = sp.Matrix([[0, -1], [1, 0]])  # (2.41)


def rotation(phi: sp.Expr) -> sp.Matrix:
    """R(phi), the rotation matrix of a body frame (2.10)."""
    return sp.Matrix([[sp.cos(phi), -sp.sin(phi)], [sp.sin(phi), sp.cos(phi)]])


@dataclass(frozen=True)
class Pose:
    """A body's position r, angle phi and rotation matrix R, as symbols."""

    r: sp.Matrix
    phi: sp.Expr

    @property
    def R(self) -> sp.Matrix:
        return rotation(self.phi)

    def point(self, s: sp.Matrix) -> sp.Matrix:
        """Global position of a point with local vector s (2.14)."""
        return self.r + self.R * s


@dataclass(frozen=True)
class Context:
    """What a constraint unit needs: poses, local vectors and expression parsing."""

    mech: Mechanism
    symbols: Symbols

    def pose(self, body: str) -> Pose:
        x, y, phi = self.symbols.body(body)
        return Pose(sp.Matrix([x, y]), phi)

    def expr(self, raw: Any) -> sp.Expr:
        return expressions.parse(raw, self.symbols.parameters)

    def vector(self, raw: list[Any]) -> sp.Matrix:
        return sp.Matrix([self.expr(item) for item in raw])

    def local(self, body: str, ref: Any) -> sp.Matrix:
        """A local vector given directly or as the name of a point of ``body``."""
        if isinstance(ref, str):
            ref = self.mech.bodies[body].points[ref]
        return self.vector(ref)

    def time_function(self, raw: Any) -> sp.Expr:
        return expressions.parse_time_function(raw, self.symbols.parameters, self.symbols.t)


def _relative(c: Any, ctx: Context) -> tuple[Pose, Pose, sp.Matrix, sp.Matrix]:
    return ctx.pose(c.i), ctx.pose(c.j), ctx.local(c.i, c.sA), ctx.local(c.j, c.sB)


def _perpendicular(bi: Pose, bj: Pose, sA: sp.Matrix, sB: sp.Matrix,
                   v: sp.Matrix) -> sp.Expr:
    """(R_j v)^T (r_j + R_j s_B - r_i - R_i s_A)  (2.22)."""
    return ((bj.R * v).T * (bj.point(sB) - bi.point(sA)))[0]


def revolute(c: model.Revolute, ctx: Context) -> list[sp.Expr]:
    """r_i + R_i s_A - (r_j + R_j s_B) = 0  (2.18)."""
    bi, bj, sA, sB = _relative(c, ctx)
    return list(bi.point(sA) - bj.point(sB))


def prismatic(c: model.Prismatic, ctx: Context) -> list[sp.Expr]:
    """phi_i - phi_j - phi0 = 0 (2.19), then the perpendicularity row (2.22)."""
    bi, bj, sA, sB = _relative(c, ctx)
    return [bi.phi - bj.phi - ctx.expr(c.phi0), _perpendicular(bi, bj, sA, sB, ctx.vector(c.v))]


def pin_slot(c: model.PinSlot, ctx: Context) -> list[sp.Expr]:
    """The perpendicularity row of a prismatic pair alone (2.22)."""
    bi, bj, sA, sB = _relative(c, ctx)
    return [_perpendicular(bi, bj, sA, sB, ctx.vector(c.v))]


def displacement(c: model.Displacement, ctx: Context) -> list[sp.Expr]:
    """r_j + R_j s_B - (r_i + R_i s_A) - f(t) = 0  (2.24)."""
    bi, bj, sA, sB = _relative(c, ctx)
    f = sp.Matrix([ctx.time_function(item) for item in c.f])
    return list(bj.point(sB) - bi.point(sA) - f)


def displacement_local(c: model.DisplacementLocal, ctx: Context) -> list[sp.Expr]:
    """R_i^T (r_j + R_j s_B) - (R_i^T r_i + s_A) - f(t) = 0  (2.25)."""
    bi, bj, sA, sB = _relative(c, ctx)
    f = sp.Matrix([ctx.time_function(item) for item in c.f])
    return list(bi.R.T * bj.point(sB) - (bi.R.T * bi.r + sA) - f)


def trajectory(c: model.Trajectory, ctx: Context) -> list[sp.Expr]:
    """r_j + R_j s_B - f(t) = 0: (2.24) with i = ground (2.26)."""
    bj = ctx.pose(c.j)
    f = sp.Matrix([ctx.time_function(item) for item in c.f])
    return list(bj.point(ctx.local(c.j, c.sB)) - f)


def angle(c: model.Angle, ctx: Context) -> list[sp.Expr]:
    """phi_i - phi_j - theta(t) = 0  (2.27)."""
    return [ctx.pose(c.i).phi - ctx.pose(c.j).phi - ctx.time_function(c.theta)]


def slide(c: model.Slide, ctx: Context) -> list[sp.Expr]:
    """(R_j u)^T (r_j + R_j s_B - r_i - R_i s_A) - f(t) = 0  (2.28)."""
    bi, bj, sA, sB = _relative(c, ctx)
    return [_perpendicular(bi, bj, sA, sB, ctx.vector(c.u)) - ctx.time_function(c.f)]


def custom(c: model.Custom, ctx: Context) -> list[sp.Expr]:
    """Equations given as expressions of coordinates, t and parameters."""
    names = {**ctx.symbols.parameters, "t": ctx.symbols.t}
    return [expressions.parse(text, names, ctx.symbols.by_coordinate) for text in c.equations]


UNITS: Mapping[str, Callable[[Any, Context], list[sp.Expr]]] = {
    "revolute": revolute, "prismatic": prismatic, "pin_slot": pin_slot,
    "displacement": displacement, "displacement_local": displacement_local,
    "trajectory": trajectory, "angle": angle, "slide": slide, "custom": custom,
}

# What each row of a constraint type is called, in the order the unit writes them.
ROW_PARTS: Mapping[str, tuple[str, ...]] = {
    "revolute": ("x", "y"), "prismatic": ("angle", "perpendicular"),
    "pin_slot": ("perpendicular",), "displacement": ("x", "y"),
    "displacement_local": ("x", "y"), "trajectory": ("x", "y"), "angle": ("angle",),
    "slide": ("slide",),
}


def equations(constraint: Any, ctx: Context) -> list[sp.Expr]:
    """The rows of Phi that ``constraint`` owns."""
    return UNITS[constraint.type](constraint, ctx)


def bodies_of(constraint: Any) -> tuple[str, ...]:
    """The bodies a constraint joins (ground included), for row labels."""
    if constraint.type == "trajectory":
        return (GROUND, constraint.j)
    return tuple(getattr(constraint, key) for key in ("i", "j") if hasattr(constraint, key))
