"""The mechanism file format: pydantic models, the single source of truth of its schema.

The models check shapes and types only; what needs the whole file (names, references between
fields, expressions, the time grid, the degree-of-freedom count) is checked by
:mod:`symkin.spec.validate`, whose :class:`~symkin.spec.validate.Mechanism` adds that pass.
:func:`json_schema` exports the format.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Callable, Mapping
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, PlainValidator, WithJsonSchema
from pydantic_core import PydanticCustomError

from symkin.spec import expressions

GROUND = "ground"

# ----- field types ---------------------------------------------------------------------------

def _kind(value: object) -> str:
    return {dict: "a mapping", list: "a list", bool: "a boolean", type(None): "nothing"}.get(
        type(value), type(value).__name__)


def _expr(value: Any) -> Any:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise PydanticCustomError("expr", "expected a number or an expression, got {kind}",
                                  {"kind": _kind(value)})
    if isinstance(value, float) and not math.isfinite(value):
        raise PydanticCustomError("expr", "{value} is not a finite number", {"value": value})
    return value


def _vector(size: int) -> Callable[[Any], list[Any]]:
    def check(value: Any) -> list[Any]:
        if not isinstance(value, (list, tuple)) or len(value) != size:
            got = f"{len(value)} items" if isinstance(value, (list, tuple)) else _kind(value)
            raise PydanticCustomError("vector", "expected a vector of {size} numbers, got {got}",
                                      {"size": size, "got": got})
        return [_expr(item) for item in value]
    return check


def _point_ref(value: Any) -> Any:
    return value if isinstance(value, str) else _vector(2)(value)


def _time_function(value: Any) -> Any:
    if isinstance(value, Mapping):
        if set(value) != {"poly"} or not isinstance(value["poly"], list) or not value["poly"]:
            raise PydanticCustomError("time", "a polynomial is written {poly: [a0, a1, a2]} "
                                              "for a0 + a1*t + a2*t**2 (eq. 2.75)")
        return {"poly": [_expr(item) for item in value["poly"]]}
    return _expr(value)


_EXPR_SCHEMA = {"anyOf": [{"type": "number"}, {"type": "string"}]}
Expr = Annotated[Any, PlainValidator(_expr), WithJsonSchema(_EXPR_SCHEMA)]
Vec2 = Annotated[list[Any], PlainValidator(_vector(2)),
                 WithJsonSchema({"type": "array", "items": _EXPR_SCHEMA,
                                 "minItems": 2, "maxItems": 2})]
Vec3 = Annotated[list[Any], PlainValidator(_vector(3)),
                 WithJsonSchema({"type": "array", "items": _EXPR_SCHEMA,
                                 "minItems": 3, "maxItems": 3})]
PointRef = Annotated[Any, PlainValidator(_point_ref),
                     WithJsonSchema({"anyOf": [{"type": "string"},
                                               {"type": "array", "items": _EXPR_SCHEMA,
                                                "minItems": 2, "maxItems": 2}]})]
TimeFunction = Annotated[Any, PlainValidator(_time_function),
                         WithJsonSchema({"anyOf": [*_EXPR_SCHEMA["anyOf"], {
                             "type": "object", "properties": {"poly": {
                                 "type": "array", "items": _EXPR_SCHEMA, "minItems": 1}},
                             "required": ["poly"], "additionalProperties": False}]})]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


# ----- bodies, joints, drivers --------------------------------------------------------------

class Body(_Strict):
    """A moving rigid body: first Newton guess q0 = [x, y, phi] and named points."""

    q0: Vec3 = [0, 0, 0]
    points: dict[str, Vec2] = {}


class _Pair(_Strict):
    """Point A (sA) on body i, point B (sB) on body j; a name or a local vector."""

    name: str | None = None
    i: str
    j: str
    sA: PointRef
    sB: PointRef


class Revolute(_Pair):
    """Revolute pair (2.18): A on i and B on j coincide."""

    type: Literal["revolute"]


class Prismatic(_Pair):
    """Prismatic pair (2.19, 2.22): no relative rotation, AB perpendicular to v (in j)."""

    type: Literal["prismatic"]
    v: Vec2
    phi0: Expr = 0


class PinSlot(_Pair):
    """Pin-in-slot pair (2.22 alone): A, on the pin's axis, moves along the line through B."""

    type: Literal["pin_slot"]
    v: Vec2


class Custom(_Strict):
    """Equations written directly as expressions of coordinates (``rod.phi``), t, parameters."""

    type: Literal["custom"]
    name: str | None = None
    equations: list[str] = Field(min_length=1)


class Displacement(_Pair):
    """Relative displacement of A and B in the global frame (2.24)."""

    type: Literal["displacement"]
    f: Annotated[list[TimeFunction], Field(min_length=2, max_length=2)]


class DisplacementLocal(_Pair):
    """Relative displacement of A and B in the frame of body i (2.25)."""

    type: Literal["displacement_local"]
    f: Annotated[list[TimeFunction], Field(min_length=2, max_length=2)]


class Trajectory(_Strict):
    """Point B of body j follows f(t) in the global frame (2.26)."""

    type: Literal["trajectory"]
    name: str | None = None
    j: str
    sB: PointRef
    f: Annotated[list[TimeFunction], Field(min_length=2, max_length=2)]


class Angle(_Strict):
    """Relative angle phi_i - phi_j = theta(t) (2.27)."""

    type: Literal["angle"]
    name: str | None = None
    i: str
    j: str
    theta: TimeFunction


class Slide(_Pair):
    """Relative slide along u (fixed in j): (R_j u)^T (r_B - r_A) = f(t) (2.28)."""

    type: Literal["slide"]
    u: Vec2
    f: TimeFunction


Joint = Annotated[Revolute | Prismatic | PinSlot | Custom, Field(discriminator="type")]
Driver = Annotated[Displacement | DisplacementLocal | Trajectory | Angle | Slide | Custom,
                   Field(discriminator="type")]

# Number of equations each constraint type contributes.
EQUATION_COUNT = {"revolute": 2, "prismatic": 2, "pin_slot": 1, "displacement": 2,
                  "displacement_local": 2, "trajectory": 2, "angle": 1, "slide": 1}


def equation_count(constraint: Joint | Driver) -> int:
    """How many rows of Phi a joint or driver owns."""
    if isinstance(constraint, Custom):
        return len(constraint.equations)
    return EQUATION_COUNT[constraint.type]


class TimeGrid(_Strict):
    """The analysis grid t0, t0 + dt, ..., t1 (end point included)."""

    t0: Expr = 0
    t1: Expr
    dt: Expr


# A unit is a label printed on plots and reports (lengths are not converted; angles may be
# shown in degrees): short, and made of characters that are safe in any output format.
UNIT_PATTERN = r"^[A-Za-z0-9µμ°/^.*· -]{1,16}$"
Unit = Annotated[str, Field(pattern=UNIT_PATTERN)]


class Units(_Strict):
    """Units of the file's numbers, for plots and reports: ``{length: m, angle: rad}``.

    symkin computes in the file's own numbers (angles always in radians); ``angle: deg`` only
    shows angles in degrees.
    """

    length: Unit | None = None
    angle: Literal["rad", "deg"] = "rad"
    time: Unit = "s"


class MechanismSpec(_Strict):
    """The fields of a mechanism file, shape-checked; :class:`symkin.spec.validate.Mechanism`
    adds the semantic checks."""

    name: str
    parameters: dict[str, Expr] = {}
    bodies: dict[str, Body] = Field(min_length=1)
    joints: list[Joint] = []
    drivers: list[Driver] = []
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
