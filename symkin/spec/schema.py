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
from symkin.pairs.fields import Expr, PointRef, PointRef3, Strict, Vec2, Vec3, Vec7
from symkin.spec import expressions, forces3d, motion
from symkin.spec.forces import Load

DYNAMICS_BODY_KEYS = ("mass", "inertia", "com")


class Body(Strict):
    """A moving rigid body: first Newton guess q0 = [x, y, phi] and named points; for
    inverse dynamics its mass, its moment of inertia about the centre of mass and where that
    centre is (a point name or a vector in the body frame; the frame's origin by default)."""

    q0: Vec3 = Field(default_factory=lambda: [0, 0, 0])
    points: dict[str, Vec2] = Field(default_factory=dict)
    mass: Expr | None = None
    inertia: Expr | None = None
    com: PointRef | None = None


class SpatialBody(Strict):
    """A moving body of a ``space: 3d`` file: first guess q0 = [x, y, z, e0, e1, e2, e3]
    (position of its frame and Euler parameters, e0 the scalar part) and named 3-vectors; for
    inverse dynamics its mass, its inertia tensor about the centre of mass in the body frame
    (:mod:`symkin.spec.forces3d`) and that centre (a point name or a local 3-vector)."""

    q0: Vec7 = Field(default_factory=lambda: [0, 0, 0, 1, 0, 0, 0])
    points: dict[str, Vec3] = Field(default_factory=dict)
    mass: Expr | None = None
    inertia: forces3d.Inertia3 | None = None
    com: PointRef3 | None = None


# The coordinates of one body, by space: planar x, y, phi; spatial x, y, z and the Euler
# parameters e0 (scalar part) .. e3.
COORDINATES = {"2d": ("x", "y", "phi"), "3d": ("x", "y", "z", "e0", "e1", "e2", "e3")}

# The joints and drivers a file may list: each a union of the registered types' models.
Joint: Any = pairs.union("joints")
Driver: Any = pairs.union("drivers")
SpatialJoint: Any = pairs.union("joints", space="3d")
SpatialDriver: Any = pairs.union("drivers", space="3d")


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
    forces: list[Load] = Field(default_factory=list)
    time: TimeGrid
    units: Units | None = None
    # forward dynamics (spec.motion): a file whose forces move it
    initial: motion.Initial | None = None
    integrator: motion.Integrator | None = None

    # -- derived views ------------------------------------------------------------------------
    @property
    def is_spatial(self) -> bool:
        """True for a ``space: 3d`` file."""
        return False

    @property
    def body_coordinates(self) -> tuple[str, ...]:
        """The names of one body's coordinates (``x``, ``y``, ``phi`` in a planar file)."""
        return COORDINATES["3d" if self.is_spatial else "2d"]

    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(self.bodies)

    def parameter_values(self) -> dict[str, float]:
        """The nominal value of every parameter."""
        return {name: float(expressions.parse(raw, {})) for name, raw in self.parameters.items()}

    def canonical_json(self) -> str:
        """The spec in a canonical text form: the input of its sha256. Units only label
        pictures, so they are left out: the generated code does not depend on them."""
        data = self.model_dump(mode="json", exclude={"units"})
        # The keys of inverse dynamics are left out where unused, so a file of kinematics
        # alone keeps the hash (and the generated bytes) it had before they existed.
        if not data["forces"]:
            del data["forces"]
        for key in ("initial", "integrator"):  # forward dynamics' keys, likewise
            if data[key] is None:
                del data[key]
        for body in data["bodies"].values():
            for key in DYNAMICS_BODY_KEYS:
                if key in body and body[key] is None:
                    del body[key]
        return json.dumps(data, sort_keys=True, separators=(",", ":"))

    def spec_hash(self) -> str:
        return hashlib.sha256(self.canonical_json().encode()).hexdigest()


class SpatialMechanismSpec(MechanismSpec):
    """The fields of a ``space: 3d`` file: 3-vectors, seven coordinates per body and the
    spatial pair types."""

    space: Literal["3d"]
    bodies: dict[str, SpatialBody] = Field(min_length=1)  # type: ignore[assignment]
    joints: list[SpatialJoint] = Field(default_factory=list)
    drivers: list[SpatialDriver] = Field(default_factory=list)
    forces: list[forces3d.Load] = Field(default_factory=list)  # type: ignore[assignment]

    @property
    def is_spatial(self) -> bool:
        return True
