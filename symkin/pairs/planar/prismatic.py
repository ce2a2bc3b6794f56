"""Prismatic pair (2.19, 2.22): no relative rotation, and A moves along the line through B."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import Expr, Vec2


class Prismatic(kit.Pair):
    """Prismatic pair (2.19, 2.22): no relative rotation, AB perpendicular to v (in j)."""

    type: Literal["prismatic"]
    v: Vec2
    phi0: Expr = 0


class DrawnPrismatic(kit.DrawnPair):
    """axis: the sliding direction as drawn (v, the slide's normal, and phi0 follow)."""

    type: Literal["prismatic"]
    axis: Vec2


def equations(c: Prismatic, geometry: kit.Geometry) -> list[sp.Expr]:
    """phi_i - phi_j - phi0 = 0 (2.19), then the perpendicularity row (2.22)."""
    bi, bj, sA, sB = kit.relative(c, geometry)
    return [bi.phi - bj.phi - geometry.expr(c.phi0),
            kit.perpendicular(bi, bj, sA, sB, geometry.vector(c.v))]


def to_local(data: Mapping[str, Any], drawing: kit.Drawing, path: kit.Path) -> kit.DrawnResult:
    """v from the drawn axis, phi0 from the frames as drawn; A must lie on the slide."""
    joined = drawing.joined(data, path, frozenset({"axis"}))
    normal, gap = drawing.slide_normal(joined, data, path)
    local = {**joined.local, "v": normal, "phi0": drawing.relative_angle(joined.i, joined.j)}
    return local, gap


TYPE = kit.PairType(
    name="prismatic", model=Prismatic, drawn_model=DrawnPrismatic, sections=("joints",),
    equations=equations, rows=("angle", "perpendicular"), points=(("sA", "i"), ("sB", "j")),
    directions=(("v", "j"),), constants=("phi0",), to_local=to_local, slide="v")
