"""Slide driver in space: (X_j - X_i)^T (A_i a) = f(t), with a the unit axis of a prismatic or
cylindrical joint fixed in i and X the joint's point carried by each body (0 as drawn)."""

from __future__ import annotations

from typing import Any, Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import Strict, TimeFunction, Vec3
from symkin.pairs.spatial import basic, cylindrical, models, prismatic

SLIDING = (prismatic.TYPE.name, cylindrical.TYPE.name)


class Slide(models.Pair):
    type: Literal["slide"]
    axis: Vec3
    f: TimeFunction


class DrawnSlide(Strict):
    type: Literal["slide"]
    name: str | None = None
    joint: str
    f: TimeFunction


def equations(c: Slide, geometry: basic.Geometry) -> list[sp.Expr]:
    a = basic.unit(geometry.vector(c.axis))
    d = basic.separation(c, geometry)
    return [basic.perpendicular_separation(geometry.pose(c.i), a, d)
            - geometry.time_function(c.f)]


def to_local(data: Any, drawing: basic.Drawing, path: kit.Path) -> kit.DrawnResult:
    """The named joint's bodies, points and axis."""
    joint = drawing.joint(data.get("joint"), path + ("joint",), SLIDING)
    local = {key: data[key] for key in ("type", "name", "f") if key in data}
    local.update({key: joint[key] for key in ("i", "j", "sA", "sB", "axis")})
    return local, None


TYPE = kit.PairType(name="slide", model=Slide, drawn_model=DrawnSlide, sections=("drivers",),
                    equations=equations, rows=("slide",), points=models.POINTS,
                    directions=(("axis", "i"),), time_functions=("f",), to_local=to_local)
