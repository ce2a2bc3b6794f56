"""Revolute joint: the points coincide and the axis fixed in j stays along the axis fixed in i
(5 equations: spherical, and the axis of j perpendicular to two vectors u, v of i that are
perpendicular to the axis)."""

from __future__ import annotations

from typing import Any, Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import Vec3
from symkin.pairs.spatial import basic, models


class Revolute(models.Pair):
    """``axis``: the joint's axis in i's frame and in j's (they agree as drawn)."""

    type: Literal["revolute"]
    axis: Vec3


class DrawnRevolute(models.DrawnPair):
    type: Literal["revolute"]
    axis: Vec3


def aligned(c: Any, geometry: basic.Geometry) -> list[sp.Expr]:
    """The axis of j perpendicular to u and v of i: the two axes stay parallel."""
    a, u, v = basic.frame_of(geometry.vector(c.axis), geometry)
    bi, bj = geometry.pose(c.i), geometry.pose(c.j)
    return [basic.perpendicular_vectors(bi, u, bj, a), basic.perpendicular_vectors(bi, v, bj, a)]


def parallel(c: Any, geometry: basic.Geometry) -> list[sp.Expr]:
    """The axes' cosine: the aligned rows hold with j's axis reversed too (cosine -1)."""
    a = basic.unit(geometry.vector(c.axis))
    return [((geometry.pose(c.i).A * a).T * (geometry.pose(c.j).A * a))[0]]


def equations(c: Revolute, geometry: basic.Geometry) -> list[sp.Expr]:
    return basic.coincident(c, geometry) + aligned(c, geometry)


def to_local(data: Any, drawing: basic.Drawing, path: kit.Path) -> kit.DrawnResult:
    local = drawing.joined(data, path)
    local["axis"] = drawing.direction(data.get("axis"), path + ("axis",))
    return local, None


TYPE = kit.PairType(
    name="revolute", model=Revolute, drawn_model=DrawnRevolute, sections=("joints",),
    equations=equations, rows=("x", "y", "z", "axis u", "axis v"), points=models.POINTS,
    directions=(("axis", "i"),), to_local=to_local, pivot=True,
    senses=parallel)
