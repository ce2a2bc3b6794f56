"""Planar geometry for the pair modules: body poses in absolute coordinates (x, y, phi) and
the :class:`Context` a pair's equations are written in (the :class:`symkin.pairs.kit.Geometry`
of a planar mechanism).

Each pair module (:mod:`symkin.pairs`) writes only its rows of Phi; Phi_q, Phi_t and Gamma are
derived from them symbolically in :mod:`symkin.symbolic.derivation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp

from symkin.pairs.fields import GROUND
from symkin.spec import expressions
from symkin.spec.schema import MechanismSpec
from symkin.symbolic.symbols import Symbols

# Around the time of the call, an input's function of t is its Taylor polynomial
# u + du (t - tau) + ddu (t - tau)^2 / 2: differentiated like any time function, then taken at
# tau = t, it gives Phi the value u, Phi_t the rate du and Gamma the acceleration ddu.
TAU = sp.Dummy("tau", real=True)


@dataclass(frozen=True)
class InputSlot:
    """What derivation puts in place of a driver's ``input`` before its equations are
    written: the input's function of t (see TAU)."""

    expression: sp.Expr


def input_slot(u: sp.Symbol, du: sp.Symbol, ddu: sp.Symbol, t: sp.Symbol) -> InputSlot:
    """The slot of one input: its Taylor polynomial about TAU in t."""
    h = t - TAU
    return InputSlot(u + du * h + ddu * h**2 / 2)


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

    mech: MechanismSpec
    symbols: Symbols

    def pose(self, body: str) -> Pose:
        x, y, phi = self.symbols.body(body)
        return Pose(sp.Matrix([x, y]), phi)

    def initial_pose(self, body: str) -> Pose:
        """The body's pose at its first guess q0, as expressions of the parameters."""
        if body == GROUND:
            return Pose(sp.zeros(2, 1), sp.Integer(0))
        x, y, phi = (self.expr(raw) for raw in self.mech.bodies[body].q0)
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
        if isinstance(raw, InputSlot):
            return raw.expression
        return expressions.parse_time_function(raw, self.symbols.parameters, self.symbols.t)

    def coordinate(self, name: str) -> sp.Symbol:
        """The symbol of a coordinate a pair adds (``NAME.s``)."""
        return self.symbols.q[self.symbols.coordinates.index(name)]

    def curve(self, raw: Any, s: sp.Symbol) -> sp.Expr:
        """A component of a curve: an expression of the parameters and its parameter ``s``."""
        return expressions.parse(raw, {**self.symbols.parameters, "s": s})

    def sign_at_nominal(self, expr: sp.Expr) -> int:
        """The sign of an expression of the parameters at their nominal values: a choice the
        file's first configuration makes once (which side, which sense), not a function of
        the parameters to differentiate."""
        values = self.mech.parameter_values()
        value = float(expr.subs({symbol: values[name]
                                 for name, symbol in self.symbols.parameters.items()}))
        return 1 if value > 0 else -1 if value < 0 else 0

    def rate(self, expr: sp.Expr) -> sp.Expr:
        """d expr / dt along the motion: sum of d expr / dq_k dq_k, plus d expr / dt."""
        symbols = self.symbols
        used = expr.free_symbols
        return sp.Add(*(sp.diff(expr, q) * dq for q, dq in zip(symbols.q, symbols.dq)
                        if q in used), sp.diff(expr, symbols.t))

    def equation(self, text: str) -> sp.Expr:
        """An equation written by the user: coordinates, t and parameters."""
        names = {**self.symbols.parameters, "t": self.symbols.t}
        return expressions.parse(text, names, self.symbols.by_coordinate)
