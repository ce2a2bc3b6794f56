"""Trajectory driver in space: point B of body j follows f(t) = [x, y, z] (3 equations)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

import sympy as sp
from pydantic import Field

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import PointRef3, Strict, TimeFunction
from symkin.pairs.spatial import basic


class Trajectory(Strict):
    type: Literal["trajectory"]
    name: str | None = None
    j: str
    sB: PointRef3
    f: Annotated[list[TimeFunction], Field(min_length=3, max_length=3)]


class DrawnTrajectory(Strict):
    type: Literal["trajectory"]
    name: str | None = None
    j: str
    point: PointRef3
    f: Annotated[list[TimeFunction], Field(min_length=3, max_length=3)]


def equations(c: Trajectory, geometry: basic.Geometry) -> list[sp.Expr]:
    """r_j + A_j s_B - f(t) = 0."""
    target = sp.Matrix([geometry.time_function(item) for item in c.f])
    return list(geometry.pose(c.j).point(geometry.local(c.j, c.sB)) - target)


def to_local(data: Any, drawing: basic.Drawing, path: kit.Path) -> kit.DrawnResult:
    body = drawing.body(data, "j", path)
    if "point" not in data:
        raise MechanismError("the required key 'point' is missing", path + ("point",))
    local = {key: data[key] for key in ("type", "name", "j", "f") if key in data}
    local["sB"] = drawing.point(body, data["point"], path + ("point",))
    return local, None


TYPE = kit.PairType(name="trajectory", model=Trajectory, drawn_model=DrawnTrajectory,
                    sections=("drivers",), equations=equations, rows=("x", "y", "z"),
                    bodies=("j",), on_ground=True, points=(("sB", "j"),),
                    time_functions=("f",), to_local=to_local)
