"""The pair and driver types: the one place that lists them.

Two families: the planar types (:mod:`symkin.pairs.planar`, ``space: 2d``, the default) and
the spatial ones (:mod:`symkin.pairs.spatial`, ``space: 3d``), which share names (revolute,
distance, angle...) but not models; a validated constraint finds its type by its model.
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
from symkin.pairs.spatial import actuator as spatial_actuator
from symkin.pairs.spatial import angle as spatial_angle
from symkin.pairs.spatial import cylindrical as spatial_cylindrical
from symkin.pairs.spatial import distance as spatial_distance
from symkin.pairs.spatial import prismatic as spatial_prismatic
from symkin.pairs.spatial import revolute as spatial_revolute
from symkin.pairs.spatial import slide as spatial_slide
from symkin.pairs.spatial import spherical as spatial_spherical
from symkin.pairs.spatial import trajectory as spatial_trajectory
from symkin.pairs.spatial import universal as spatial_universal

# In the order the schema lists them (joints, then drivers; custom in both).
TYPES: tuple[PairType, ...] = (
    revolute.TYPE, prismatic.TYPE, pin_slot.TYPE, distance.TYPE,
    gear.TYPE, rack.TYPE, point_on_curve.TYPE, cam.TYPE,
    displacement.TYPE, displacement_local.TYPE, trajectory.TYPE, angle.TYPE, slide.TYPE,
    custom.TYPE,
)
# The spatial family (space: 3d); custom is shared (its equations name coordinates).
SPATIAL_TYPES: tuple[PairType, ...] = (
    spatial_spherical.TYPE, spatial_revolute.TYPE, spatial_cylindrical.TYPE,
    spatial_prismatic.TYPE, spatial_universal.TYPE, spatial_distance.TYPE,
    spatial_actuator.TYPE, spatial_trajectory.TYPE, spatial_angle.TYPE, spatial_slide.TYPE,
    custom.TYPE,
)
SECTIONS = ("joints", "drivers")
SPACES = ("2d", "3d")

_BY_NAME = {kind.name: kind for kind in TYPES}
_FAMILY = {"2d": TYPES, "3d": SPATIAL_TYPES}
_BY_MODEL = {model: kind for kind in (*TYPES, *SPATIAL_TYPES)
             for model in (kind.model, kind.drawn_model) if model is not None}


def get(name: str) -> PairType:
    """The type called ``name`` (the schema has refused unknown names before)."""
    return _BY_NAME[name]


def of(constraint: Any) -> PairType:
    """The type of a validated joint or driver (of either family: found by its model)."""
    return _BY_MODEL[type(constraint)]


def named(name: object) -> PairType | None:
    """The type called ``name``, or None (for raw data not yet validated)."""
    return _BY_NAME.get(name) if isinstance(name, str) else None


def in_section(section: str, space: str = "2d") -> tuple[PairType, ...]:
    """The types a section (``joints`` or ``drivers``) of a ``space`` file may list."""
    return tuple(kind for kind in _FAMILY[space] if section in kind.sections)


def named_in(name: object, section: str, space: str) -> PairType | None:
    """The type called ``name`` that a section of a ``space`` file may list, or None."""
    found = [kind for kind in in_section(section, space) if kind.name == name]
    return found[0] if found else None


def union(section: str, drawn: bool = False, space: str = "2d") -> Any:
    """The pydantic union of a section's models, told apart by ``type``."""
    models = tuple((kind.drawn_model or kind.model) if drawn else kind.model
                   for kind in in_section(section, space))
    return Annotated[Union[models], Field(discriminator="type")]  # noqa: UP007
