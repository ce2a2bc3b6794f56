"""The masses and loads of a spatial file (``space: 3d``): the same keys as the planar ones
(:mod:`symkin.spec.forces`) with 3-vectors, and the inertia tensor's forms and checks.

A spatial body's ``inertia`` is its tensor about the centre of mass, in the body frame (as
drawn, the body frame is parallel to the global axes): a number J (J I), a list of the three
principal moments [Jxx, Jyy, Jzz] (along the frame's axes), or the 3x3 matrix. The loads:

    {type: gravity, g: [gx, gy, gz]}
    {type: force,  name, body, at: POINT | [x, y, z], f: [fx, fy, fz]}   global components
    {type: torque, name, body, m: [mx, my, mz]}                          global components
    {type: spring, name, i, A, j, B, k, length0, damping}
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Annotated, Any, Literal

from pydantic import Field, PlainValidator, WithJsonSchema
from pydantic_core import PydanticCustomError

from symkin.pairs.fields import _EXPR_SCHEMA, PointRef3, Strict, Vec3, _expr, _vector, kind_of
from symkin.spec import forces

# A spatial body's coordinates and their rates, as a load's expression may name them.
COORDINATE_PARTS = ("x", "y", "z", "e0", "e1", "e2", "e3")

Path_ = tuple[str | int, ...]


def _inertia(value: Any) -> Any:
    """A number, three principal moments, or a 3x3 matrix (shapes only)."""
    if not isinstance(value, (list, tuple)):
        return _expr(value)
    if len(value) == 3 and all(isinstance(row, (list, tuple)) for row in value):
        return [_vector(3)(row) for row in value]
    if len(value) == 3 and not any(isinstance(item, (list, tuple)) for item in value):
        return _vector(3)(value)
    raise PydanticCustomError("inertia", "expected a number, three principal moments "
                              "[Jxx, Jyy, Jzz] or a 3x3 matrix, got {got}",
                              {"got": f"{len(value)} items" if value else kind_of(value)})


_MATRIX_SCHEMA = {"type": "array", "items": _EXPR_SCHEMA, "minItems": 3, "maxItems": 3}
Inertia3 = Annotated[Any, PlainValidator(_inertia), WithJsonSchema({"anyOf": [
    *_EXPR_SCHEMA["anyOf"], _MATRIX_SCHEMA,
    {"type": "array", "items": _MATRIX_SCHEMA, "minItems": 3, "maxItems": 3}]})]


class Gravity(Strict):
    """A uniform field: the force m g at every body's centre of mass."""

    type: Literal["gravity"]
    g: Vec3


class PointForce(Strict):
    """A force f (global components) applied at a point of one body."""

    type: Literal["force"]
    name: str | None = None
    body: str
    at: PointRef3 = Field(default_factory=lambda: [0, 0, 0])
    f: Vec3


class Torque(Strict):
    """A pure moment m (global components) on one body."""

    type: Literal["torque"]
    name: str | None = None
    body: str
    m: Vec3


class Spring(forces.Spring):
    """A linear spring-damper between point A of body i and point B of body j."""

    A: PointRef3 = Field(default_factory=lambda: [0, 0, 0])
    B: PointRef3 = Field(default_factory=lambda: [0, 0, 0])


Load = Annotated[Gravity | PointForce | Torque | Spring, Field(discriminator="type")]


def matrix(raw: Any) -> list[list[Any]]:
    """The 3x3 tensor of an ``inertia`` value of any of its forms (entries as written)."""
    if not isinstance(raw, list):
        return [[raw if r == c else 0 for c in range(3)] for r in range(3)]
    if not isinstance(raw[0], list):
        return [[raw[r] if r == c else 0 for c in range(3)] for r in range(3)]
    return [list(row) for row in raw]


def entries(raw: Any) -> list[tuple[Path_, Any]]:
    """Each number of a ``mass`` or ``inertia`` value with its place under the key."""
    if not isinstance(raw, list):
        return [((), raw)]
    if not isinstance(raw[0], list):
        return [((k,), item) for k, item in enumerate(raw)]
    return [((r, c), item) for r, row in enumerate(raw) for c, item in enumerate(row)]


def magnitude_problem(key: str, values: dict[Path_, float]) -> tuple[str, str] | None:
    """Why a mass or an inertia (its values by place, from :func:`entries`) is not one:
    (message, hint), or None. A mass is >= 0; an inertia tensor symmetric, with principal
    moments >= 0 that satisfy the triangle inequality (J1 + J2 >= J3: every rigid body's)."""
    if len(values) == 1:
        value = next(iter(values.values()))
        if value < 0:
            return f"the {key} {value:g} is negative", f"A {key} is zero or positive."
        return None
    tensor = [[0.0] * 3 for _ in range(3)]
    for place, value in values.items():
        r, c = (int(place[0]), int(place[-1]))  # (k,): a principal moment, on the diagonal
        tensor[r][c] = value
    scale = max(abs(v) for row in tensor for v in row) or 1.0
    for r, c in ((0, 1), (0, 2), (1, 2)):
        if abs(tensor[r][c] - tensor[c][r]) > 1e-12 * scale:
            return (f"the inertia tensor is not symmetric: [{r}][{c}] = {tensor[r][c]:g} but "
                    f"[{c}][{r}] = {tensor[c][r]:g}", "An inertia tensor equals its transpose.")
    # in units of the largest entry: the closed form squares the entries, which overflows
    # for entries above 1e154 (an inertia of 1e200 was accepted unchecked)
    moments = [scale * m for m in _eigenvalues([[v / scale for v in row] for row in tensor])]
    if moments[0] < -1e-12 * scale:
        return (f"the inertia tensor has a negative principal moment {moments[0]:g}",
                "Its principal moments (eigenvalues) are zero or positive.")
    if moments[0] + moments[1] < moments[2] * (1 - 1e-9):
        return (f"the principal moments {', '.join(f'{m:g}' for m in moments)} break the "
                "triangle inequality J1 + J2 >= J3", "No rigid body has them: check the "
                "values (about the centre of mass, in the body frame).")
    return None


def _eigenvalues(tensor: list[list[float]]) -> list[float]:
    """The eigenvalues of a symmetric 3x3 matrix, ascending (closed form, no NumPy here)."""
    (a, d, e), (_, b, f), (_, _, c) = tensor
    p1 = d * d + e * e + f * f
    mean = (a + b + c) / 3
    p2 = (a - mean) * (a - mean) + (b - mean) * (b - mean) + (c - mean) * (c - mean) + 2 * p1
    if p2 == 0:
        return [mean] * 3
    p = math.sqrt(p2 / 6)
    m = [[(tensor[r][k] - (mean if r == k else 0)) / p for k in range(3)] for r in range(3)]
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
           - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
           + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    angle = math.acos(max(-1.0, min(1.0, det / 2))) / 3
    high = mean + 2 * p * math.cos(angle)
    low = mean + 2 * p * math.cos(angle + 2 * math.pi / 3)
    return sorted([low, 3 * mean - high - low, high])


def coordinate_names(bodies: Any, symbol: Callable[[str], Any] | None = None
                     ) -> dict[tuple[str, str], Any]:
    """``(body, "x"|"e0"|"x_t"|...) -> Symbol``, what a spatial load's expression may name."""
    return forces.coordinate_names(bodies, symbol, COORDINATE_PARTS)
