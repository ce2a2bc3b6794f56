"""Cylindrical joint: the axes stay parallel and the point of j stays on the axis of i
(4 equations: two dot-1, two dot-2); it turns about and slides along the axis."""

from __future__ import annotations

from typing import Any, Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.spatial import basic, models, revolute


class Cylindrical(revolute.Revolute):
    type: Literal["cylindrical"]  # type: ignore[assignment]


class DrawnCylindrical(revolute.DrawnRevolute):
    type: Literal["cylindrical"]  # type: ignore[assignment]


def on_axis(c: Any, geometry: basic.Geometry) -> list[sp.Expr]:
    """The separation of the joint's points perpendicular to u and v of i."""
    _, u, v = basic.frame_of(geometry.vector(c.axis), geometry)
    bi, d = geometry.pose(c.i), basic.separation(c, geometry)
    return [basic.perpendicular_separation(bi, u, d), basic.perpendicular_separation(bi, v, d)]


def equations(c: Cylindrical, geometry: basic.Geometry) -> list[sp.Expr]:
    return revolute.aligned(c, geometry) + on_axis(c, geometry)


TYPE = kit.PairType(
    name="cylindrical", model=Cylindrical, drawn_model=DrawnCylindrical, sections=("joints",),
    equations=equations, rows=("axis u", "axis v", "line u", "line v"),
    points=models.POINTS, directions=(("axis", "i"),), to_local=revolute.to_local,
    senses=revolute.parallel)
