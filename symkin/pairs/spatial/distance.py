"""Distance constraint in space: A (a point of body i) and B (of body j) stay ``length``
apart, a rod with no body (1 equation); ``length`` defaults to the distance as drawn."""

from __future__ import annotations

import math
from typing import Any, Literal

import sympy as sp

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import Expr, PointRef3, Strict
from symkin.pairs.spatial import basic

POINTS = (("A", "i"), ("B", "j"))


class Distance(Strict):
    type: Literal["distance"]
    name: str | None = None
    i: str
    j: str
    A: PointRef3
    B: PointRef3
    length: Expr | None = None


def drawn_length(c: Any, geometry: basic.Geometry) -> sp.Expr:
    """|B - A| at the first guess q0 (as drawn)."""
    d0 = (geometry.initial_pose(c.j).point(geometry.local(c.j, c.B))
          - geometry.initial_pose(c.i).point(geometry.local(c.i, c.A)))
    return sp.sqrt((d0.T * d0)[0])


def equations(c: Distance, geometry: basic.Geometry) -> list[sp.Expr]:
    d = basic.separation(c, geometry, "A", "B")
    length = drawn_length(c, geometry) if c.length is None else geometry.expr(c.length)
    return [basic.distance(d, length)]


def apart(c: Any, checks: Any, path: kit.Path) -> None:
    """A and B must be apart at q0 (as drawn): the row is scaled by that length."""
    a, b = checks.point_at_q0(c.i, c.A), checks.point_at_q0(c.j, c.B)
    if math.dist(a, b) == 0:  # no overflow for huge coordinates, unlike a sum of squares
        raise MechanismError("A and B coincide where they start (as drawn), so the length "
                             "they keep is zero", path, "Give length: (positive), or use a "
                             "spherical joint to make the two points coincide.")


def check(c: Distance, checks: Any, path: kit.Path) -> None:
    if c.length is None:
        apart(c, checks, path)
        return
    value = checks.value(checks.expression(c.length, path + ("length",)), path + ("length",))
    if not value > 0:
        raise MechanismError(f"the length {value:g} is not positive", path + ("length",),
                             "A distance keeps two points a positive length apart; to make "
                             "them coincide use a spherical joint.")


def points_to_local(data: Any, drawing: basic.Drawing, path: kit.Path) -> kit.DrawnResult:
    """A on i and B on j, each a point name of its body or global [x, y, z]."""
    local = dict(data)
    for key, body_key in POINTS:
        body = drawing.body(data, body_key, path)
        if key not in data:
            raise MechanismError(f"the required key {key!r} is missing", path + (key,))
        local[key] = drawing.point(body, data[key], path + (key,))
    return local, None


TYPE = kit.PairType(name="distance", model=Distance, sections=("joints",),
                    equations=equations, rows=("length",), points=POINTS,
                    constants=("length",), check=check, to_local=points_to_local, rod=True)
