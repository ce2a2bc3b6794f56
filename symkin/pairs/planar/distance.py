"""Distance constraint: point A of body i and point B of body j stay ``length`` apart, a rod
with no body of its own (a coupler of negligible mass, a cable kept taut, a linear measure).

One equation, written so that it is smooth everywhere and its row of Phi_q has the size of a
unit vector, like the other pairs' rows (tolerances then mean a length):

    ((r_B - r_A)^T (r_B - r_A) - length^2) / (2 length) = 0

which agrees with |r_B - r_A| - length to first order. ``length`` defaults to the distance at
the first guess q0 (the drawn distance in the drawn layout, whose q0 is the drawing).
"""

from __future__ import annotations

import math
from typing import Literal

import sympy as sp

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import Expr, PointRef, Strict


class Distance(Strict):
    """|r_B - r_A| = length: A (a point of body i) and B (of body j), a name or a vector."""

    type: Literal["distance"]
    name: str | None = None
    i: str
    j: str
    A: PointRef
    B: PointRef
    length: Expr | None = None


def equations(c: Distance, geometry: kit.Geometry) -> list[sp.Expr]:
    """((r_B - r_A)^T (r_B - r_A) - length^2) / (2 length) = 0."""
    sA, sB = geometry.local(c.i, c.A), geometry.local(c.j, c.B)
    d = geometry.pose(c.j).point(sB) - geometry.pose(c.i).point(sA)
    if c.length is None:
        d0 = geometry.initial_pose(c.j).point(sB) - geometry.initial_pose(c.i).point(sA)
        length = sp.sqrt((d0.T * d0)[0])
    else:
        length = geometry.expr(c.length)
    return [((d.T * d)[0] - length**2) / (2 * length)]


def check(c: Distance, checks: kit.Checks, path: kit.Path) -> None:
    """A length is positive; without one, A and B must be apart at q0 (or as drawn)."""
    if c.length is not None:
        value = checks.value(checks.expression(c.length, path + ("length",)), path + ("length",))
        if not value > 0:
            raise MechanismError(f"the length {value:g} is not positive", path + ("length",),
                                 "A distance constraint keeps two points a positive length "
                                 "apart; to make them coincide use a revolute joint.")
        return
    (ax, ay), (bx, by) = checks.point_at_q0(c.i, c.A), checks.point_at_q0(c.j, c.B)
    if math.hypot(ax - bx, ay - by) == 0:  # no overflow for huge coordinates
        raise MechanismError("A and B coincide where they start (q0, or as drawn), so the "
                             "length they keep is zero", path,
                             "Give length: (positive), or use a revolute joint to make the "
                             "two points coincide.")


TYPE = kit.PairType(name="distance", model=Distance, sections=("joints",),
                    equations=equations, rows=("length",), points=(("A", "i"), ("B", "j")),
                    constants=("length",), check=check, rod=True)
