"""Relative slide driver (2.28): B moves along u (fixed in body j) by f(t) from A."""

from __future__ import annotations

from typing import Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import TimeFunction, Vec2


class Slide(kit.Pair):
    """Relative slide along u (fixed in j): (R_j u)^T (r_B - r_A) = f(t) (2.28)."""

    type: Literal["slide"]
    u: Vec2
    f: TimeFunction


def equations(c: Slide, geometry: kit.Geometry) -> list[sp.Expr]:
    """(R_j u)^T (r_j + R_j s_B - r_i - R_i s_A) - f(t) = 0  (2.28)."""
    bi, bj, sA, sB = kit.relative(c, geometry)
    return [kit.perpendicular(bi, bj, sA, sB, geometry.vector(c.u))
            - geometry.time_function(c.f)]


TYPE = kit.PairType(name="slide", model=Slide, sections=("drivers",), equations=equations,
                    rows=("slide",), points=(("sA", "i"), ("sB", "j")),
                    directions=(("u", "j"),), time_functions=("f",))
