"""Point on a curve: a point P of body j stays on a curve [x(s), y(s)] fixed in body i (a
slot of any shape, a guide, a track). The curve parameter s is a coordinate of its own,
``NAME.s``, solved with the bodies' (first guess ``s0``):

    r_j + R_j s_P - r_i - R_i c(s) = 0                                   (2 rows: x, y)

In the local layout c(s) is written in i's frame; in the drawn layout it is global, as
drawn, and carried by i (converted to i's frame here), and P must lie on it at s0.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal

import sympy as sp

from symkin.errors import ExpressionError, MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import Expr, PointRef, Strict, Vec2

S = "s"


class PointOnCurve(Strict):
    """Point ``point`` of body j on ``curve`` [x(s), y(s)] of body i; s starts at ``s0``."""

    type: Literal["point_on_curve"]
    name: str | None = None
    i: str
    j: str
    point: PointRef
    curve: Vec2
    s0: Expr = 0
    range: Vec2 | None = None  # where the curve is meant to be followed: [a, b] of s


def curve_of(raw: list[Any], s: sp.Symbol, geometry: kit.Geometry) -> sp.Matrix:
    """The curve's point c(s) in its body's frame."""
    return sp.Matrix([geometry.curve(item, s) for item in raw])


def equations(c: PointOnCurve, geometry: kit.Geometry) -> list[sp.Expr]:
    """r_j + R_j s_P - (r_i + R_i c(s)) = 0."""
    s = geometry.coordinate(f"{c.name}.{S}")
    on_j = geometry.pose(c.j).point(geometry.local(c.j, c.point))
    on_i = geometry.pose(c.i).point(curve_of(c.curve, s, geometry))
    return list(on_j - on_i)


def check(c: PointOnCurve, checks: kit.Checks, path: kit.Path) -> None:
    """Each component an expression of s (its derivatives printable), real at s0."""
    s0 = checks.value(checks.expression(c.s0, path + ("s0",)), path + ("s0",))
    check_range(c.range, s0, checks, path)
    for k, raw in enumerate(c.curve):
        expr = checks.curve(raw, path + ("curve", k))
        checks.curve_value(expr, s0, path + ("curve", k))


def check_range(raw: list[Any] | None, s0: float, checks: kit.Checks, path: kit.Path) -> None:
    """A range [a, b] of constants with a < b that holds s0."""
    if raw is None:
        return
    low, high = (checks.value(checks.expression(item, path + ("range", k)),
                              path + ("range", k)) for k, item in enumerate(raw))
    if not low < high:
        raise MechanismError(f"the range [{low:g}, {high:g}] is empty", path + ("range",),
                             "Give [a, b] with a < b: the values of s the curve is meant "
                             "for.")
    if not low <= s0 <= high:
        raise MechanismError(f"s0 = {s0:g} is outside the range [{low:g}, {high:g}]",
                             path + ("s0",), "Start the contact inside the curve's range.")


def drawn_curve(drawing: kit.Drawing, data: Mapping[str, Any], raw: Any, path: kit.Path,
                ) -> tuple[list[str], Any]:
    """A drawn curve in the frame of body i, and the drawn curve's point at s0."""
    body = drawing.body(data, "i", path)
    texts, at = drawing.curve(body, raw, path)
    s0 = drawing.value(data.get("s0", 0), path + ("s0",))
    try:
        return texts, at(s0)
    except ExpressionError as error:
        raise MechanismError(f"the curve has no finite real point at s0 = {s0:g}: "
                             f"{error.message}", path, "Give s0 inside the curve's range.") \
            from None


def to_local(data: Mapping[str, Any], drawing: kit.Drawing, path: kit.Path) -> kit.DrawnResult:
    """The curve to i's frame; the point to j's; the gap between the point and c(s0)."""
    local = dict(data)
    if "curve" not in data or "point" not in data:
        return local, None  # the schema names the missing key
    local["curve"], (cx, cy) = drawn_curve(drawing, data, data["curve"], path + ("curve",))
    j = drawing.body(data, "j", path)
    local["point"], drawn_point = drawing.point(j, data["point"], path + ("point",))
    px, py = (q.value for q in drawn_point)
    return local, math.hypot(px - cx, py - cy)


def outputs(c: PointOnCurve, geometry: kit.Geometry
            ) -> dict[str, tuple[sp.Expr, sp.Expr | None]]:
    """The contact point c(s) in the global frame, ``contact_x`` and ``contact_y``."""
    s = geometry.coordinate(f"{c.name}.{S}")
    return kit.contact_outputs(geometry.pose(c.i).point(curve_of(c.curve, s, geometry)))


def marks(c: PointOnCurve, geometry: kit.Geometry) -> list[kit.Mark]:
    """The curve over its range, else s0 - pi to s0 + pi (where it is real)."""
    s0 = geometry.expr(c.s0)
    span = ((s0 - sp.pi, s0 + sp.pi) if c.range is None
            else tuple(geometry.expr(end) for end in c.range))
    return [(c.i, "curve", curve_of(c.curve, kit.S_MARK, geometry), span)]


TYPE = kit.PairType(
    name="point_on_curve", model=PointOnCurve, sections=("joints",), equations=equations,
    rows=("x", "y"), points=(("point", "j"),), check=check, to_local=to_local,
    coordinate="s0", marks=marks, coordinate_range="range", outputs=outputs)
