"""Distance driver in space (``type: distance`` among the drivers): |r_B - r_A| = f(t), a
linear actuator with no body (a Stewart platform's leg). Written (d^T d - f^2) / (2 L0) with
L0 the length as drawn, so that its row has the size of a unit vector and stays smooth."""

from __future__ import annotations

from typing import Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import PointRef3, Strict, TimeFunction
from symkin.pairs.spatial import basic, distance


class Actuator(Strict):
    type: Literal["distance"]
    name: str | None = None
    i: str
    j: str
    A: PointRef3
    B: PointRef3
    f: TimeFunction


def equations(c: Actuator, geometry: basic.Geometry) -> list[sp.Expr]:
    d = basic.separation(c, geometry, "A", "B")
    f = geometry.time_function(c.f)
    return [((d.T * d)[0] - f**2) / (2 * distance.drawn_length(c, geometry))]


TYPE = kit.PairType(name="distance", model=Actuator, sections=("drivers",),
                    equations=equations, rows=("length",), points=distance.POINTS,
                    time_functions=("f",), check=distance.apart,
                    to_local=distance.points_to_local, rod=True)
