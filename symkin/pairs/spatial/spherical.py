"""Spherical joint: a point of body i and a point of body j coincide (3 equations)."""

from __future__ import annotations

from typing import Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.spatial import basic, models


class Spherical(models.Pair):
    type: Literal["spherical"]


class DrawnSpherical(models.DrawnPair):
    type: Literal["spherical"]


def equations(c: Spherical, geometry: basic.Geometry) -> list[sp.Expr]:
    """r_i + A_i s_A - (r_j + A_j s_B) = 0."""
    return basic.coincident(c, geometry)


TYPE = kit.PairType(
    name="spherical", model=Spherical, drawn_model=DrawnSpherical, sections=("joints",),
    equations=equations, rows=("x", "y", "z"), points=models.POINTS, to_local=models.joined,
    pivot=True)
