"""The pair and driver types: the one place that lists them.

Each type is one module of this package holding everything about it (see
:mod:`symkin.pairs.kit`); the stages ask this registry for a type by name, or for the schema
unions of a section, and never name a type themselves. Adding a type is a module here and
its line in :data:`TYPES`.
"""

from __future__ import annotations

from typing import Annotated, Any, Union

from pydantic import Field

from symkin.pairs.kit import PairType
from symkin.pairs.planar import (
    angle,
    cam,
    custom,
    displacement,
    displacement_local,
    distance,
    gear,
    pin_slot,
    point_on_curve,
    prismatic,
    rack,
    revolute,
    slide,
    trajectory,
)

# In the order the schema lists them (joints, then drivers; custom in both).
TYPES: tuple[PairType, ...] = (
    revolute.TYPE, prismatic.TYPE, pin_slot.TYPE, distance.TYPE,
    gear.TYPE, rack.TYPE, point_on_curve.TYPE, cam.TYPE,
    displacement.TYPE, displacement_local.TYPE, trajectory.TYPE, angle.TYPE, slide.TYPE,
    custom.TYPE,
)
SECTIONS = ("joints", "drivers")

_BY_NAME = {kind.name: kind for kind in TYPES}


def get(name: str) -> PairType:
    """The type called ``name`` (the schema has refused unknown names before)."""
    return _BY_NAME[name]


def of(constraint: Any) -> PairType:
    """The type of a validated joint or driver."""
    return _BY_NAME[constraint.type]


def named(name: object) -> PairType | None:
    """The type called ``name``, or None (for raw data not yet validated)."""
    return _BY_NAME.get(name) if isinstance(name, str) else None


def in_section(section: str) -> tuple[PairType, ...]:
    """The types a section (``joints`` or ``drivers``) may list."""
    return tuple(kind for kind in TYPES if section in kind.sections)


def union(section: str, drawn: bool = False) -> Any:
    """The pydantic union of a section's models, told apart by ``type``."""
    models = tuple((kind.drawn_model or kind.model) if drawn else kind.model
                   for kind in in_section(section))
    return Annotated[Union[models], Field(discriminator="type")]  # noqa: UP007
