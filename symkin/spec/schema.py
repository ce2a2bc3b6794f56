"""The mechanism file format: pydantic models, the single source of truth of its schema.

The models check shapes and types only; what needs the whole file (names, references between
fields, expressions, the time grid, the degree-of-freedom count) is checked by
:mod:`symkin.spec.validate`, whose :class:`~symkin.spec.validate.Mechanism` adds that pass.
:func:`json_schema` exports the format. The joints' and drivers' models come from the pair
registry (:mod:`symkin.pairs`).
"""

from __future__ import annotations

import hashlib
import json
from typing import Annotated, Any, Literal

from pydantic import Field

from symkin import pairs
from symkin.pairs.fields import Expr, Strict, Vec2, Vec3
from symkin.spec import expressions


class Body(Strict):
    """A moving rigid body: first Newton guess q0 = [x, y, phi] and named points."""

    q0: Vec3 = Field(default_factory=lambda: [0, 0, 0])
    points: dict[str, Vec2] = Field(default_factory=dict)


# The joints and drivers a file may list: each a union of the registered types' models.
Joint: Any = pairs.union("joints")
Driver: Any = pairs.union("drivers")


def equation_count(constraint: Any) -> int:
    """How many rows of Phi a joint or driver owns."""
    return pairs.of(constraint).equation_count(constraint)


class TimeGrid(Strict):
    """The analysis grid t0, t0 + dt, ..., t1 (end point included)."""

    t0: Expr = 0
    t1: Expr
    dt: Expr


# A unit is a label printed on plots and reports (lengths are not converted; angles may be
# shown in degrees): short, and made of characters that are safe in any output format.
UNIT_PATTERN = r"^[A-Za-z0-9µμ°/^.*· -]{1,16}$"
Unit = Annotated[str, Field(pattern=UNIT_PATTERN)]


class Units(Strict):
    """Units of the file's numbers, for plots and reports: ``{length: m, angle: rad}``.

    symkin computes in the file's own numbers (angles always in radians); ``angle: deg`` only
    shows angles in degrees.
    """

    length: Unit | None = None
    angle: Literal["rad", "deg"] = "rad"
    time: Unit = "s"


class MechanismSpec(Strict):
    """The fields of a mechanism file, shape-checked; :class:`symkin.spec.validate.Mechanism`
    adds the semantic checks."""

    name: str
    parameters: dict[str, Expr] = Field(default_factory=dict)
    bodies: dict[str, Body] = Field(min_length=1)
    joints: list[Joint] = Field(default_factory=list)
    drivers: list[Driver] = Field(default_factory=list)
    time: TimeGrid
    units: Units | None = None

    # -- derived views ------------------------------------------------------------------------
    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(self.bodies)

    def parameter_values(self) -> dict[str, float]:
        """The nominal value of every parameter."""
        return {name: float(expressions.parse(raw, {})) for name, raw in self.parameters.items()}

    def canonical_json(self) -> str:
        """The spec in a canonical text form: the input of its sha256. Units only label
        pictures, so they are left out: the generated code does not depend on them."""
        return json.dumps(self.model_dump(mode="json", exclude={"units"}), sort_keys=True,
                          separators=(",", ":"))

    def spec_hash(self) -> str:
        return hashlib.sha256(self.canonical_json().encode()).hexdigest()
