"""Universal (Hooke, Cardan) joint: the points coincide and an axis fixed in i stays
perpendicular to an axis fixed in j (4 equations); the axes are perpendicular as drawn."""

from __future__ import annotations

from typing import Annotated, Any, Literal

import sympy as sp
from pydantic import Field

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import Vec3
from symkin.pairs.spatial import basic, models

Axes = Annotated[list[Vec3], Field(min_length=2, max_length=2)]


class Universal(models.Pair):
    """``axes``: [the cross's axis fixed in i, its axis fixed in j], each in its body's frame."""

    type: Literal["universal"]
    axes: Axes


class DrawnUniversal(models.DrawnPair):
    type: Literal["universal"]
    axes: Axes


def equations(c: Universal, geometry: basic.Geometry) -> list[sp.Expr]:
    a, b = (geometry.vector(axis) for axis in c.axes)
    cross = basic.perpendicular_vectors(geometry.pose(c.i), basic.unit(a),
                                        geometry.pose(c.j), basic.unit(b))
    return [*basic.coincident(c, geometry), cross]


# Drawn axes count as perpendicular when the cosine of their angle is below this.
PERPENDICULAR = 1e-9


def to_local(data: Any, drawing: basic.Drawing, path: kit.Path) -> kit.DrawnResult:
    """The shared point; the two axes checked perpendicular as drawn."""
    local = drawing.joined(data, path)
    raw = data.get("axes")
    if not isinstance(raw, list) or len(raw) != 2:
        raise MechanismError("expected axes: [[axis fixed in i], [axis fixed in j]]",
                             path + ("axes",))
    axes = [drawing.direction(axis, path + ("axes", k)) for k, axis in enumerate(raw)]
    local["axes"] = axes
    return local, None


def check(c: Universal, checks: Any, path: kit.Path) -> None:
    """The two axes are perpendicular as drawn (at q0, the bodies' frames are parallel)."""
    a, b = ([checks.value(checks.expression(x, path + ("axes", n, k)), path + ("axes", n, k))
             for k, x in enumerate(axis)] for n, axis in enumerate(c.axes))
    # each axis divided by its largest component first: at 1e-200 (or 1e200) the squares
    # under- (over-)flow, and the cosine of two directions is the same at any length
    a, b = ([x / max(map(abs, axis)) if any(axis) else 0.0 for x in axis] for axis in (a, b))
    dot = sum(x * y for x, y in zip(a, b))
    norm = (sum(x * x for x in a) * sum(y * y for y in b)) ** 0.5
    if norm == 0 or abs(dot) > PERPENDICULAR * norm:
        raise MechanismError(f"the two axes are not perpendicular (cosine "
                             f"{dot / norm if norm else float('nan'):.3g})", path + ("axes",),
                             "A universal joint's cross has perpendicular axes: give them "
                             "as drawn, e.g. [[0, 1, 0], [0, 0, 1]].")


TYPE = kit.PairType(
    name="universal", model=Universal, drawn_model=DrawnUniversal, sections=("joints",),
    equations=equations, rows=("x", "y", "z", "cross"), points=models.POINTS,
    to_local=to_local, check=check, pivot=True)
