"""Distance driver in space (``type: distance`` among the drivers): |r_B - r_A| = f(t), a
linear actuator with no body (a Stewart platform's leg). Written (d^T d - f^2) / (2 L0) with
L0 the length as drawn, so that its row has the size of a unit vector and stays smooth."""

from __future__ import annotations

from typing import Any, Literal

import sympy as sp

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import PointRef3, Strict, TimeFunction, is_input
from symkin.pairs.spatial import basic, distance


class Actuator(Strict):
    type: Literal["distance"]
    name: str | None = None
    i: str
    j: str
    A: PointRef3
    B: PointRef3
    f: TimeFunction


def check(c: Actuator, checks: Any, path: kit.Path) -> None:
    """A and B apart as drawn, and the length f never negative over the file's grid: the row
    holds f squared, so a negative f would be solved silently as its absolute value (and the
    leg's force would change sign)."""
    distance.apart(c, checks, path)
    if is_input(c.f):  # its values come from the caller (runtime.input_driven.inputs checks them)
        return
    f = checks.expression(c.f, path + ("f",), time=True)
    samples = checks.over_time(f)
    # a length that touches zero (its rounding a hair below) is not a sign written wrong
    floor = -1e-9 * max((abs(value) for _, value in samples), default=0.0)
    for t, value in samples:
        if value < floor:
            raise MechanismError(
                f"the length f is negative at t = {t:.6g} ({value:.6g})", path + ("f",),
                "A distance driver's f is the length |B - A|, never negative: write its "
                "absolute value (the sign does not reverse the leg).")


def equations(c: Actuator, geometry: basic.Geometry) -> list[sp.Expr]:
    d = basic.separation(c, geometry, "A", "B")
    f = geometry.time_function(c.f)
    return [((d.T * d)[0] - f**2) / (2 * distance.drawn_length(c, geometry))]


TYPE = kit.PairType(name="distance", model=Actuator, sections=("drivers",),
                    equations=equations, rows=("length",), points=distance.POINTS,
                    time_functions=("f",), lengths=("f",), check=check,
                    to_local=distance.points_to_local, rod=True)
