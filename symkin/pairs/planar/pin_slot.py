"""Pin-in-slot pair (2.22 alone): A, on the pin's axis, moves along the line through B."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import Vec2


class PinSlot(kit.Pair):
    """Pin-in-slot pair (2.22 alone): A, on the pin's axis, moves along the line through B."""

    type: Literal["pin_slot"]
    v: Vec2


class DrawnPinSlot(kit.DrawnPair):
    """axis: the slot's direction as drawn (v, its normal, follows)."""

    type: Literal["pin_slot"]
    axis: Vec2


def equations(c: PinSlot, geometry: kit.Geometry) -> list[sp.Expr]:
    """The perpendicularity row of a prismatic pair alone (2.22)."""
    bi, bj, sA, sB = kit.relative(c, geometry)
    return [kit.perpendicular(bi, bj, sA, sB, geometry.vector(c.v))]


def to_local(data: Mapping[str, Any], drawing: kit.Drawing, path: kit.Path) -> kit.DrawnResult:
    """v from the drawn axis; the pin must lie on the slot."""
    joined = drawing.joined(data, path, frozenset({"axis"}))
    normal, gap = drawing.slide_normal(joined, data, path)
    return {**joined.local, "v": normal}, gap


TYPE = kit.PairType(
    name="pin_slot", model=PinSlot, drawn_model=DrawnPinSlot, sections=("joints",),
    equations=equations, rows=("perpendicular",), points=(("sA", "i"), ("sB", "j")),
    directions=(("v", "j"),), to_local=to_local, slide="v")
