"""Relative displacement driver (2.24): B of body j seen from A of body i, in the global
frame, follows f(t)."""

from __future__ import annotations

from typing import Annotated, Literal

import sympy as sp
from pydantic import Field

from symkin.pairs import kit
from symkin.pairs.fields import TimeFunction


class Displacement(kit.Pair):
    """Relative displacement of A and B in the global frame (2.24)."""

    type: Literal["displacement"]
    f: Annotated[list[TimeFunction], Field(min_length=2, max_length=2)]


def equations(c: Displacement, geometry: kit.Geometry) -> list[sp.Expr]:
    """r_j + R_j s_B - (r_i + R_i s_A) - f(t) = 0  (2.24)."""
    bi, bj, sA, sB = kit.relative(c, geometry)
    return list(bj.point(sB) - bi.point(sA) - kit.components(c.f, geometry))


TYPE = kit.PairType(name="displacement", model=Displacement, sections=("drivers",),
                    equations=equations, rows=("x", "y"), points=(("sA", "i"), ("sB", "j")),
                    time_functions=("f",))
