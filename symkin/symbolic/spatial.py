"""Spatial geometry for the spatial pair modules: body poses in absolute coordinates
(x, y, z and Euler parameters e0..e3, e0 the scalar part) and the :class:`SpatialContext` a
spatial pair's equations are written in (:class:`symkin.pairs.spatial.basic.Geometry`).

A body's rotation matrix from its Euler parameters (Nikravesh, Haug) is

    A(e) = (2 e0^2 - 1) I + 2 (e e^T + e0 e~),   e = [e1, e2, e3]

written here in the form that is a rotation for any e with e0^2 + e^T e = 1; one
normalisation row per body, e0^2 + e^T e - 1 = 0, keeps the parameters on that sphere.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp

from symkin.pairs.fields import GROUND
from symkin.spec import constants
from symkin.symbolic.planar import Context


def rotation(e0: sp.Expr, e1: sp.Expr, e2: sp.Expr, e3: sp.Expr) -> sp.Matrix:
    """A(e), the rotation matrix of Euler parameters (e0 the scalar part)."""
    return sp.Matrix([
        [e0**2 + e1**2 - e2**2 - e3**2, 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)],
        [2 * (e1 * e2 + e0 * e3), e0**2 - e1**2 + e2**2 - e3**2, 2 * (e2 * e3 - e0 * e1)],
        [2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), e0**2 - e1**2 - e2**2 + e3**2]])


@dataclass(frozen=True)
class Pose:
    """A body's position r and Euler parameters e, as symbols (or constants)."""

    r: sp.Matrix
    e: tuple[sp.Expr, sp.Expr, sp.Expr, sp.Expr]

    @property
    def A(self) -> sp.Matrix:
        return rotation(*self.e)

    def point(self, s: sp.Matrix) -> sp.Matrix:
        """Global position of a point with local vector s: r + A s."""
        return self.r + self.A * s


def normalisation(pose: Pose) -> sp.Expr:
    """e0^2 + e1^2 + e2^2 + e3^2 - 1 = 0."""
    return sp.Add(*(value**2 for value in pose.e)) - 1


@dataclass(frozen=True)
class SpatialContext(Context):
    """The planar Context's expressions, with spatial poses."""

    def pose(self, body: str) -> Pose:  # type: ignore[override]
        x, y, z, e0, e1, e2, e3 = self.symbols.body(body)
        return Pose(sp.Matrix([x, y, z]), (e0, e1, e2, e3))

    def initial_pose(self, body: str) -> Pose:  # type: ignore[override]
        if body == GROUND:
            return Pose(sp.zeros(3, 1), (sp.Integer(1), sp.Integer(0), sp.Integer(0),
                                         sp.Integer(0)))
        x, y, z, e0, e1, e2, e3 = (self.expr(raw) for raw in self.mech.bodies[body].q0)
        return Pose(sp.Matrix([x, y, z]), (e0, e1, e2, e3))

    def value(self, expr: Any) -> float:
        """The value of a constant expression at the nominal parameters."""
        nominal = {self.symbols.parameters[name]: value
                   for name, value in self.mech.parameter_values().items()}
        return constants.value(sp.sympify(expr), nominal)
