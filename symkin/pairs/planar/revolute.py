"""Revolute pair (2.18): point A of body i and point B of body j coincide."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import sympy as sp

from symkin.pairs import kit


class Revolute(kit.Pair):
    """Revolute pair (2.18): A on i and B on j coincide."""

    type: Literal["revolute"]


class DrawnRevolute(kit.DrawnPair):
    type: Literal["revolute"]


def equations(c: Revolute, geometry: kit.Geometry) -> list[sp.Expr]:
    """r_i + R_i s_A - (r_j + R_j s_B) = 0  (2.18)."""
    bi, bj, sA, sB = kit.relative(c, geometry)
    return list(bi.point(sA) - bj.point(sB))


def to_local(data: Mapping[str, Any], drawing: kit.Drawing, path: kit.Path) -> kit.DrawnResult:
    """The shared point, local in each body; the drawing closes where A and B coincide."""
    joined = drawing.joined(data, path)
    return joined.local, joined.gap


TYPE = kit.PairType(
    name="revolute", model=Revolute, drawn_model=DrawnRevolute, sections=("joints",),
    equations=equations, rows=("x", "y"), points=(("sA", "i"), ("sB", "j")),
    to_local=to_local, pivot=True)
