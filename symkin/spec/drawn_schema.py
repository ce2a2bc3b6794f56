"""The shapes of a drawn document (``layout: drawn``), for the JSON Schema of the file format.

The drawn layout is checked by :mod:`symkin.spec.drawn` while it is turned into the local form,
and the local form by :mod:`symkin.spec.schema`; these models only describe the drawn keys to
editors and other tools.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field

from symkin.spec.schema import Driver, Expr, PointRef, TimeGrid, Units, Vec2, _Strict


class Frame(_Strict):
    """A body's frame: its origin (a point of the body or global [x, y]) and angle."""

    origin: PointRef | None = None
    angle: Expr = 0


class DrawnBody(_Strict):
    """A body as drawn: global points; the frame defaults to the first point, global axes."""

    points: dict[str, Vec2] = Field(default_factory=dict)
    frame: Frame | None = None


class _DrawnPair(_Strict):
    """One point ``at`` shared by bodies i and j, or a global sA (on i) and sB (on j)."""

    name: str | None = None
    i: str
    j: str
    at: PointRef | None = None
    sA: PointRef | None = None
    sB: PointRef | None = None


class DrawnRevolute(_DrawnPair):
    type: Literal["revolute"]


class DrawnPrismatic(_DrawnPair):
    """axis: the sliding direction as drawn (v, the slide's normal, and phi0 follow)."""

    type: Literal["prismatic"]
    axis: Vec2


class DrawnPinSlot(_DrawnPair):
    type: Literal["pin_slot"]
    axis: Vec2


class DrawnCustom(_Strict):
    type: Literal["custom"]
    name: str | None = None
    equations: list[str] = Field(min_length=1)


DrawnJoint = Annotated[DrawnRevolute | DrawnPrismatic | DrawnPinSlot | DrawnCustom,
                       Field(discriminator="type")]


class DrawnMechanism(_Strict):
    """A mechanism file in the drawn layout: global coordinates in one assembled pose."""

    layout: Literal["drawn"]
    name: str
    parameters: dict[str, Expr] = Field(default_factory=dict)
    bodies: dict[str, DrawnBody] = Field(min_length=1)
    joints: list[DrawnJoint] = Field(default_factory=list)
    drivers: list[Driver] = Field(default_factory=list)
    time: TimeGrid
    units: Units | None = None


def json_schema_of(local: type[Any]) -> dict[str, Any]:
    """The schema of a mechanism file: the local layout or the drawn one."""
    from pydantic import TypeAdapter

    return TypeAdapter(local | DrawnMechanism).json_schema()  # type: ignore[arg-type]
