"""The shapes of a drawn document (``layout: drawn``), for the JSON Schema of the file format.

The drawn layout is checked by :mod:`symkin.spec.drawn` while it is turned into the local form,
and the local form by :mod:`symkin.spec.schema`; these models only describe the drawn keys to
editors and other tools. Each joint type's drawn keys come from its module (the pair
registry).
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from symkin import pairs
from symkin.pairs.fields import Expr, PointRef, PointRef3, Strict, Vec2, Vec3
from symkin.spec.forces import Load
from symkin.spec.schema import Driver, SpatialMechanismSpec, TimeGrid, Units


class Frame(Strict):
    """A body's frame: its origin (a point of the body or global [x, y]) and angle."""

    origin: PointRef | None = None
    angle: Expr = 0


class DrawnBody(Strict):
    """A body as drawn: global points; the frame defaults to the first point, global axes."""

    points: dict[str, Vec2] = Field(default_factory=dict)
    frame: Frame | None = None
    mass: Expr | None = None
    inertia: Expr | None = None
    com: PointRef | None = None  # a point name, or global [x, y] as drawn


DrawnJoint: Any = pairs.union("joints", drawn=True)


class DrawnMechanism(Strict):
    """A mechanism file in the drawn layout: global coordinates in one assembled pose."""

    layout: Literal["drawn"]
    name: str
    parameters: dict[str, Expr] = Field(default_factory=dict)
    bodies: dict[str, DrawnBody] = Field(min_length=1)
    joints: list[DrawnJoint] = Field(default_factory=list)
    drivers: list[Driver] = Field(default_factory=list)
    forces: list[Load] = Field(default_factory=list)  # points global as drawn
    time: TimeGrid
    units: Units | None = None


SpatialDrawnJoint: Any = pairs.union("joints", drawn=True, space="3d")
SpatialDrawnDriver: Any = pairs.union("drivers", drawn=True, space="3d")


class SpatialFrame(Strict):
    """A spatial body's frame origin (its axes are parallel to the global ones as drawn)."""

    origin: PointRef3


class SpatialDrawnBody(Strict):
    """A spatial body as drawn: global [x, y, z] points; the frame at the first point."""

    points: dict[str, Vec3] = Field(default_factory=dict)
    frame: SpatialFrame | None = None


class SpatialDrawnMechanism(Strict):
    """A ``space: 3d`` file in the drawn layout."""

    space: Literal["3d"]
    layout: Literal["drawn"]
    name: str
    parameters: dict[str, Expr] = Field(default_factory=dict)
    bodies: dict[str, SpatialDrawnBody] = Field(min_length=1)
    joints: list[SpatialDrawnJoint] = Field(default_factory=list)
    drivers: list[SpatialDrawnDriver] = Field(default_factory=list)
    time: TimeGrid
    units: Units | None = None


def json_schema_of(local: type[Any]) -> dict[str, Any]:
    """The schema of a mechanism file: the local layout or the drawn one, planar or spatial."""
    from pydantic import TypeAdapter

    return TypeAdapter(local | DrawnMechanism | SpatialDrawnMechanism  # type: ignore[arg-type]
                       | SpatialMechanismSpec).json_schema()
