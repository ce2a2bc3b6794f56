"""Custom constraints: equations written directly as expressions of coordinates (``rod.phi``),
t and parameters; a joint or a driver."""

from __future__ import annotations

from typing import Literal

import sympy as sp
from pydantic import Field

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import Strict


class Custom(Strict):
    """Equations written directly as expressions of coordinates (``rod.phi``), t, parameters."""

    type: Literal["custom"]
    name: str | None = None
    equations: list[str] = Field(min_length=1)


def equations(c: Custom, geometry: kit.Geometry) -> list[sp.Expr]:
    """Equations given as expressions of coordinates, t and parameters."""
    return [geometry.equation(text) for text in c.equations]


def check(c: Custom, checks: kit.Checks, path: kit.Path) -> None:
    """Each equation parses, with derivatives that print, and uses a coordinate."""
    for k, text in enumerate(c.equations):
        expr = checks.expression(text, path + ("equations", k), time=True, coordinates=True)
        if not checks.uses_coordinates(expr):
            raise MechanismError("this equation uses no coordinate, so it cannot "
                                 "constrain the mechanism", path + ("equations", k),
                                 "Use coordinates such as crank.phi or rod.x in it.")


TYPE = kit.PairType(name="custom", model=Custom, sections=("joints", "drivers"),
                    equations=equations, rows=None, bodies=(), check=check)
