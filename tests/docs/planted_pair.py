"""Tether: point A of body i stays within reach of point B of body j (a pair type planted by
the site fixture of tests/docs/conftest.py, written as a pair module is: its model,
equations and registry entry)."""

from __future__ import annotations

from typing import Any

from symkin.pairs import kit
from symkin.pairs.fields import PointRef, Strict


class Tether(Strict):
    """Tether between A on i and B on j."""

    type: str
    name: str | None = None
    i: str
    j: str
    sA: PointRef
    sB: PointRef
    reach: float
    slack_factor: float = 0.5


def equations(c: Tether, geometry: kit.Geometry) -> list[Any]:
    """|r_B - r_A|^2 - reach^2 = 0  (planted by a test)."""
    return []


TYPE = kit.PairType(name="tether", model=Tether, sections=("joints",), equations=equations,
                    rows=("reach",), points=(("sA", "i"), ("sB", "j")), constants=("reach",))
