"""Relative displacement driver in the frame of body i (2.25)."""

from __future__ import annotations

from typing import Annotated, Literal

import sympy as sp
from pydantic import Field

from symkin.pairs import kit
from symkin.pairs.fields import TimeFunction


class DisplacementLocal(kit.Pair):
    """Relative displacement of A and B in the frame of body i (2.25)."""

    type: Literal["displacement_local"]
    f: Annotated[list[TimeFunction], Field(min_length=2, max_length=2)]


def equations(c: DisplacementLocal, geometry: kit.Geometry) -> list[sp.Expr]:
    """R_i^T (r_j + R_j s_B) - (R_i^T r_i + s_A) - f(t) = 0  (2.25)."""
    bi, bj, sA, sB = kit.relative(c, geometry)
    return list(bi.R.T * bj.point(sB) - (bi.R.T * bi.r + sA) - kit.components(c.f, geometry))


TYPE = kit.PairType(name="displacement_local", model=DisplacementLocal, sections=("drivers",),
                    equations=equations, rows=("x", "y"), points=(("sA", "i"), ("sB", "j")),
                    time_functions=("f",))
