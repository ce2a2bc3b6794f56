"""The shapes spatial two-body pairs share: in the local form, a point of body i (sA) and one
of body j (sB), each a point name or a local 3-vector; as drawn, one shared point ``at``."""

from __future__ import annotations

from typing import Any

from symkin.pairs.fields import PointRef3, Strict


class Pair(Strict):
    """Point A (sA) on body i, point B (sB) on body j; a name or a local 3-vector."""

    name: str | None = None
    i: str
    j: str
    sA: PointRef3
    sB: PointRef3


class DrawnPair(Strict):
    """The joint's point ``at``: a point name of i or j, or global [x, y, z]."""

    name: str | None = None
    i: str
    j: str
    at: PointRef3


POINTS = (("sA", "i"), ("sB", "j"))


def joined(data: Any, drawing: Any, path: tuple[str | int, ...]) -> tuple[dict[str, Any], None]:
    """The generic drawn joint: its shared point, local in each body (closed by construction)."""
    return drawing.joined(data, path), None
