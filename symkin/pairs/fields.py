"""The value types of a mechanism file's fields: numbers or expressions, vectors, point
references and time functions, each a pydantic type with its JSON Schema.

They check shapes only (an expression is parsed later, by the whitelist parser, where its names
are known). Shared by the file's top-level models (:mod:`symkin.spec.schema`) and by every pair
module.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, PlainValidator, WithJsonSchema
from pydantic_core import PydanticCustomError

# The fixed body every mechanism has: it needs no entry in `bodies`, its q is zero.
GROUND = "ground"

# A driver's function written ``input``: its value, rate and acceleration come from the caller
# at run time (a sensor, an encoder), not from a formula in t.
INPUT = "input"


def is_input(raw: Any) -> bool:
    """True for a time function written ``input`` (the exact word, nothing around it)."""
    return isinstance(raw, str) and raw.strip() == INPUT


def kind_of(value: object) -> str:
    """How a value of the wrong type is named in a message: ``a mapping``, ``a list``, ..."""
    return {dict: "a mapping", list: "a list", bool: "a boolean", type(None): "nothing"}.get(
        type(value), type(value).__name__)


def _expr(value: Any) -> Any:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise PydanticCustomError("expr", "expected a number or an expression, got {kind}",
                                  {"kind": kind_of(value)})
    if isinstance(value, float) and not math.isfinite(value):
        raise PydanticCustomError("expr", "{value} is not a finite number", {"value": value})
    return value


def _vector(size: int) -> Callable[[Any], list[Any]]:
    def check(value: Any) -> list[Any]:
        if not isinstance(value, (list, tuple)) or len(value) != size:
            got = f"{len(value)} items" if isinstance(value, (list, tuple)) else kind_of(value)
            raise PydanticCustomError("vector", "expected a vector of {size} numbers, got {got}",
                                      {"size": size, "got": got})
        return [_expr(item) for item in value]
    return check


def _point_ref(value: Any) -> Any:
    return value if isinstance(value, str) else _vector(2)(value)


def _point_ref3(value: Any) -> Any:
    return value if isinstance(value, str) else _vector(3)(value)


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
# A spatial body's first guess: x, y, z and Euler parameters e0..e3.
Vec7 = Annotated[list[Any], PlainValidator(_vector(7)),
                 WithJsonSchema({"type": "array", "items": _EXPR_SCHEMA,
                                 "minItems": 7, "maxItems": 7})]
PointRef = Annotated[Any, PlainValidator(_point_ref),
                     WithJsonSchema({"anyOf": [{"type": "string"},
                                               {"type": "array", "items": _EXPR_SCHEMA,
                                                "minItems": 2, "maxItems": 2}]})]
PointRef3 = Annotated[Any, PlainValidator(_point_ref3),
                      WithJsonSchema({"anyOf": [{"type": "string"},
                                                {"type": "array", "items": _EXPR_SCHEMA,
                                                 "minItems": 3, "maxItems": 3}]})]
TimeFunction = Annotated[Any, PlainValidator(_time_function),
                         WithJsonSchema({"anyOf": [*_EXPR_SCHEMA["anyOf"], {
                             "type": "object", "properties": {"poly": {
                                 "type": "array", "items": _EXPR_SCHEMA, "minItems": 1}},
                             "required": ["poly"], "additionalProperties": False}]})]


class Strict(BaseModel):
    """A file's mapping: unknown keys are refused, the validated value is frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True)
