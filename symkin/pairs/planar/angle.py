"""Relative angle driver (2.27): phi_i - phi_j = theta(t)."""

from __future__ import annotations

from typing import Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import Strict, TimeFunction


class Angle(Strict):
    """Relative angle phi_i - phi_j = theta(t) (2.27)."""

    type: Literal["angle"]
    name: str | None = None
    i: str
    j: str
    theta: TimeFunction


def equations(c: Angle, geometry: kit.Geometry) -> list[sp.Expr]:
    """phi_i - phi_j - theta(t) = 0  (2.27)."""
    return [geometry.pose(c.i).phi - geometry.pose(c.j).phi - geometry.time_function(c.theta)]


TYPE = kit.PairType(name="angle", model=Angle, sections=("drivers",), equations=equations,
                    rows=("angle",), time_functions=("theta",))
