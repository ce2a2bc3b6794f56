"""Trajectory driver (2.26): point B of body j follows f(t) in the global frame."""

from __future__ import annotations

from typing import Annotated, Literal

import sympy as sp
from pydantic import Field

from symkin.pairs import kit
from symkin.pairs.fields import PointRef, Strict, TimeFunction


class Trajectory(Strict):
    """Point B of body j follows f(t) in the global frame (2.26)."""

    type: Literal["trajectory"]
    name: str | None = None
    j: str
    sB: PointRef
    f: Annotated[list[TimeFunction], Field(min_length=2, max_length=2)]


def equations(c: Trajectory, geometry: kit.Geometry) -> list[sp.Expr]:
    """r_j + R_j s_B - f(t) = 0: (2.24) with i = ground (2.26)."""
    bj = geometry.pose(c.j)
    return list(bj.point(geometry.local(c.j, c.sB)) - kit.components(c.f, geometry))


TYPE = kit.PairType(name="trajectory", model=Trajectory, sections=("drivers",),
                    equations=equations, rows=("x", "y"), bodies=("j",), on_ground=True,
                    points=(("sB", "j"),), time_functions=("f",))
