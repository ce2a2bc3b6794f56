"""Prismatic joint: a cylindrical joint that cannot turn (5 equations: the cylindrical four
and v of j perpendicular to u of i, which holds as drawn). Those rows also hold with j turned
half a turn about the axis (v of j reversed) or about a line across it (the axis reversed):
its senses, the axes' cosine and the v vectors' cosine, are positive only as drawn."""

from __future__ import annotations

from typing import Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.spatial import basic, cylindrical, revolute


class Prismatic(revolute.Revolute):
    type: Literal["prismatic"]  # type: ignore[assignment]


class DrawnPrismatic(revolute.DrawnRevolute):
    type: Literal["prismatic"]  # type: ignore[assignment]


def equations(c: Prismatic, geometry: basic.Geometry) -> list[sp.Expr]:
    _, u, v = basic.frame_of(geometry.vector(c.axis), geometry)
    no_turn = basic.perpendicular_vectors(geometry.pose(c.i), u, geometry.pose(c.j), v)
    return cylindrical.equations(c, geometry) + [no_turn]  # type: ignore[arg-type]


def senses(c: Prismatic, geometry: basic.Geometry) -> list[sp.Expr]:
    """The axes' cosine (revolute.parallel) and v's: v of j along v of i, not reversed."""
    _, _, v = basic.frame_of(geometry.vector(c.axis), geometry)
    vi, vj = geometry.pose(c.i).A * v, geometry.pose(c.j).A * v
    return revolute.parallel(c, geometry) + [(vi.T * vj)[0]]


TYPE = kit.PairType(
    name="prismatic", model=Prismatic, drawn_model=DrawnPrismatic, sections=("joints",),
    equations=equations, rows=("axis u", "axis v", "line u", "line v", "turn"),
    points=(("sA", "i"), ("sB", "j")), directions=(("axis", "i"),),
    to_local=revolute.to_local, senses=senses)
