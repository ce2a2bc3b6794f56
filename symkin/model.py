"""Stage 1 — the mechanism model: a validated description of bodies, joints and drivers.

The pydantic classes below are the single source of truth for the mechanism file format
(YAML, TOML or the same structure built in Python); :func:`json_schema` exports it. Validation
happens in two passes: pydantic checks shapes and types, then :func:`_check_semantics` checks
what needs the whole file (names, references between fields, expressions, the time grid and the
degree-of-freedom count). Both report a :class:`MechanismError` carrying the field path.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Annotated, Any, Literal

import sympy as sp
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PlainValidator,
    ValidationError,
    WithJsonSchema,
    model_validator,
)
from pydantic_core import PydanticCustomError

from symkin import expressions, loader
from symkin.errors import ExpressionError, MechanismError, format_path
from symkin.names import name_problem

GROUND = "ground"
MAX_GRID_POINTS = 10_000_000


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


def _vector(size: int):
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


class Mechanism(_Strict):
    """A validated planar mechanism. Build it with :func:`load` or :func:`from_dict`."""

    name: str
    parameters: dict[str, Expr] = {}
    bodies: dict[str, Body] = Field(min_length=1)
    joints: list[Joint] = []
    drivers: list[Driver] = []
    time: TimeGrid

    @model_validator(mode="after")
    def _semantics(self) -> Mechanism:
        _check_semantics(self)
        return self

    # -- derived views ------------------------------------------------------------------------
    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(self.bodies)

    def parameter_values(self) -> dict[str, float]:
        """The nominal value of every parameter."""
        return {name: float(expressions.parse(raw, {})) for name, raw in self.parameters.items()}

    def canonical_json(self) -> str:
        """The spec in a canonical text form: the input of its sha256."""
        return json.dumps(self.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))

    def spec_hash(self) -> str:
        return hashlib.sha256(self.canonical_json().encode()).hexdigest()


# ----- symbols -------------------------------------------------------------------------------

@dataclass(frozen=True)
class Symbols:
    """The SymPy symbols of a mechanism: coordinates, velocities, time and parameters."""

    q: tuple[sp.Symbol, ...]
    dq: tuple[sp.Symbol, ...]
    t: sp.Symbol
    p: tuple[sp.Symbol, ...]
    coordinates: tuple[str, ...]

    # Built once per Symbols: derivation asks for them for every constraint and expression.
    @cached_property
    def parameters(self) -> dict[str, sp.Symbol]:
        return {symbol.name: symbol for symbol in self.p}

    @cached_property
    def by_coordinate(self) -> dict[tuple[str, str], sp.Symbol]:
        """``(body, "x"|"y"|"phi") -> q symbol``, for custom constraints."""
        pairs = (name.partition(".") for name in self.coordinates)
        return {(body, part): q for (body, _, part), q in zip(pairs, self.q)}

    @cached_property
    def _first_coordinate(self) -> dict[str, int]:
        """Body name -> index of its x coordinate."""
        return {name[:-2]: k for k, name in enumerate(self.coordinates) if name.endswith(".x")}

    def body(self, name: str, velocities: bool = False) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """(x, y, phi) of a body (or their rates); the ground is fixed at zero."""
        if name == GROUND:
            return (sp.Integer(0),) * 3
        start = self._first_coordinate[name]
        source = self.dq if velocities else self.q
        return source[start], source[start + 1], source[start + 2]


def make_symbols(mech: Mechanism) -> Symbols:
    """Create the symbols of ``mech``; coordinate names are ``body.x``, ``body.y``, ``body.phi``."""
    coordinates = tuple(f"{b}.{c}" for b in mech.bodies for c in ("x", "y", "phi"))
    q = tuple(sp.Symbol(name, real=True) for name in coordinates)
    dq = tuple(sp.Symbol(name + "_t", real=True) for name in coordinates)
    p = tuple(sp.Symbol(name, real=True) for name in mech.parameters)
    return Symbols(q, dq, sp.Symbol("t", real=True), p, coordinates)


# ----- loading -------------------------------------------------------------------------------

def load(path: str | Path) -> Mechanism:
    """Read and validate a mechanism file (YAML, or TOML by suffix)."""
    document = loader.read(path)
    return _validate(document)


def from_dict(data: Mapping[str, Any], source: str = "<mechanism>") -> Mechanism:
    """Validate a mechanism given as plain Python data (the file's structure)."""
    return _validate(loader.Document(dict(data) if isinstance(data, Mapping) else data, source))


def json_schema() -> dict[str, Any]:
    """The JSON Schema of the mechanism file format."""
    return Mechanism.model_json_schema()


def _validate(document: loader.Document) -> Mechanism:
    if not isinstance(document.data, dict):
        raise MechanismError("the file must be a mapping with keys name, parameters, bodies, "
                             "joints, drivers, time", source=document.source, line=1)
    try:
        return Mechanism.model_validate(document.data)
    except MechanismError as error:
        raise error.located(document.source, document.line_of(error.path)) from None
    except ValidationError as error:
        raise _translate(error, document) from None


def _translate(error: ValidationError, document: loader.Document) -> MechanismError:
    """Turn pydantic's first error into a MechanismError that names file, line and field."""
    first = error.errors()[0]
    path = tuple(part for part in first["loc"] if part != "[key]")
    path = _data_path(document.data, path)
    kind = first["type"]
    message, hint = first["msg"], ""
    if kind == "extra_forbidden":
        message = f"unknown key {path[-1]!r}"
        hint = f"Allowed keys here: {', '.join(_allowed_keys(path, document.data))}."
    elif kind == "missing":
        message = f"the required key {path[-1]!r} is missing"
    elif kind == "union_tag_invalid":
        tag = first.get("input", {}).get("type") if isinstance(first.get("input"), dict) else None
        message = f"unknown type {tag!r}"
        hint = f"Use one of: {first['ctx']['expected_tags']}."
    elif kind == "union_tag_not_found":
        message = "the key 'type' is missing"
        kinds = "revolute, prismatic, pin_slot, custom" if path[:1] == ("joints",) else \
            "displacement, displacement_local, trajectory, angle, slide, custom"
        hint = f"Add type: one of {kinds}."
    elif kind in _PYDANTIC_MESSAGES:
        message = _PYDANTIC_MESSAGES[kind].format(kind=_kind(first.get("input")),
                                                  **first.get("ctx", {}))
    return MechanismError(message, path, hint, document.source, document.line_of(path))


# pydantic's own wording for shape errors, said the way a mechanism file's reader thinks.
_PYDANTIC_MESSAGES = {
    "string_type": "expected a name (text), got {kind}",
    "dict_type": "expected a mapping of keys to values, got {kind}",
    "model_type": "expected a mapping of keys to values, got {kind}",
    "model_attributes_type": "expected a mapping of keys to values, got {kind}",
    "list_type": "expected a list, got {kind}",
    "too_short": "needs at least {min_length} item(s), got {actual_length}",
    "too_long": "takes at most {max_length} item(s), got {actual_length}",
}


def _data_path(data: Any, loc: tuple[Any, ...]) -> tuple[str | int, ...]:
    """Drop the union-member names pydantic puts into locations; keep real field paths."""
    path: list[str | int] = []
    node = data
    for part in loc:
        if isinstance(node, dict) and part in node or isinstance(node, list) and isinstance(part, int) and part < len(node):
            path.append(part)
            node = node[part]
        elif isinstance(node, dict) and isinstance(part, str) and part in _ALL_FIELDS:
            path.append(part)  # a missing key
            break
    return tuple(path)


def _allowed_keys(path: tuple[str | int, ...], data: Any) -> list[str]:
    section = path[0] if path else ""
    if len(path) <= 1:
        return list(Mechanism.model_fields)
    if section == "bodies":
        return list(Body.model_fields)
    if section == "time":
        return list(TimeGrid.model_fields)
    try:
        model = _CONSTRAINT_MODELS[data[section][path[1]]["type"]]
    except (KeyError, IndexError, TypeError):
        return ["type, name and the keys of that type"]
    return list(model.model_fields)


_CONSTRAINT_MODELS: dict[str, type[BaseModel]] = {
    model.model_fields["type"].annotation.__args__[0]: model  # type: ignore[union-attr]
    for model in (Revolute, Prismatic, PinSlot, Custom, Displacement, DisplacementLocal,
                  Trajectory, Angle, Slide)}


_ALL_FIELDS = {name for model in (Mechanism, Body, Revolute, Prismatic, PinSlot, Custom,
                                  Displacement, DisplacementLocal, Trajectory, Angle, Slide,
                                  TimeGrid) for name in model.model_fields}


# ----- semantic checks -----------------------------------------------------------------------

def _check_semantics(mech: Mechanism) -> None:
    _check_names(mech)
    symbols = make_symbols(mech)
    values = _check_parameters(mech)
    nominal = {symbols.parameters[name]: value for name, value in values.items()}
    for name, body in mech.bodies.items():
        for k, raw in enumerate(body.q0):
            _expression(raw, symbols, ("bodies", name, "q0", k), values=nominal)
        for point, vector in body.points.items():
            for k, raw in enumerate(vector):
                _expression(raw, symbols, ("bodies", name, "points", point, k), values=nominal)
    named: dict[str, tuple[str | int, ...]] = {}
    for section in ("joints", "drivers"):
        for index, constraint in enumerate(getattr(mech, section)):
            path = (section, index)
            _check_constraint(mech, constraint, symbols, nominal, path)
            if constraint.name in named:
                raise MechanismError(f"the name {constraint.name!r} is already used by "
                                     f"{format_path(named[constraint.name])}", path + ("name",),
                                     "Joints and drivers need different names: each labels "
                                     "rows of Phi.")
            if constraint.name is not None:
                named[constraint.name] = path
    _check_time(mech, symbols, nominal)
    check_degrees_of_freedom(mech)


def _check_names(mech: Mechanism) -> None:
    problem = name_problem(mech.name)
    if problem:
        raise MechanismError(problem, ("name",), "Use a plain identifier such as crank_slider; "
                             "it becomes the C prefix.")
    seen: dict[str, tuple[str | int, ...]] = {}
    for section in ("parameters", "bodies"):
        for name in getattr(mech, section):
            path = (section, name)
            problem = name_problem(name)
            if problem:
                raise MechanismError(problem, path, "Rename it.")
            if name.lower() in seen:
                raise MechanismError(f"the name {name!r} is already used at "
                                     f"{'.'.join(map(str, seen[name.lower()]))}", path,
                                     "Names of parameters and bodies must differ (ignoring "
                                     "case).")
            seen[name.lower()] = path
    for body, spec in mech.bodies.items():
        for point in spec.points:
            problem = name_problem(point)
            if problem:
                raise MechanismError(problem, ("bodies", body, "points", point), "Rename it.")


def _check_parameters(mech: Mechanism) -> dict[str, float]:
    values = {}
    for name, raw in mech.parameters.items():
        try:
            expr = expressions.parse(raw, {})
        except ExpressionError as error:
            raise MechanismError(str(error), ("parameters", name),
                                 "A parameter's value is a number or an expression of numbers, "
                                 "pi and E; it cannot use t or other parameters.") from None
        values[name] = _numeric(expr, {}, ("parameters", name))
    return values


def _numeric(expr: sp.Expr, values: Mapping[sp.Symbol, float],
             path: tuple[str | int, ...]) -> float:
    """The value of ``expr`` at the nominal parameters: a finite real number, or an error."""
    try:
        number = float(expr.subs(values))
    except (TypeError, ValueError, OverflowError, ZeroDivisionError):
        number = math.nan  # complex (sqrt(-1), asin(2)) or too large for a float
    if not math.isfinite(number):
        raise MechanismError(f"{sp.sstr(expr)} is not a finite real number at the nominal "
                             f"parameter values", path,
                             "Check the arguments of sqrt, log, asin, acos and the magnitudes.")
    return number


def _expression(raw: Any, symbols: Symbols | None, path: tuple[str | int, ...],
                time: bool = False, coordinates: bool = False,
                values: Mapping[sp.Symbol, float] | None = None) -> sp.Expr:
    """Parse a field; with ``values`` (a constant field) also check its nominal value."""
    if values is not None:
        expr = _expression(raw, symbols, path, time, coordinates)
        _numeric(expr, values, path)
        return expr
    names = dict(symbols.parameters) if symbols else {}
    if time and symbols:
        names["t"] = symbols.t
    try:
        if time and isinstance(raw, Mapping):
            return expressions.parse_time_function(raw, names, symbols.t)  # type: ignore[union-attr]
        return expressions.parse(raw, names, symbols.by_coordinate if coordinates and symbols
                                 else None)
    except ExpressionError as error:
        hint = "Use numbers, parameter names, pi, E, + - * / ** and the listed functions"
        hint += ", and t." if time else "."
        raise MechanismError(str(error), path, hint) from None


def _body_ref(mech: Mechanism, name: str, path: tuple[str | int, ...]) -> None:
    if name != GROUND and name not in mech.bodies:
        known = ", ".join([GROUND, *mech.bodies])
        raise MechanismError(f"unknown body {name!r}", path, f"Use one of: {known}.")


def _point(mech: Mechanism, body: str, ref: Any, symbols: Symbols,
           nominal: Mapping[sp.Symbol, float], path: tuple[str | int, ...]) -> None:
    if isinstance(ref, str):
        points = mech.bodies[body].points if body != GROUND else {}
        if ref not in points:
            known = ", ".join(points) or "none"
            raise MechanismError(f"body {body!r} has no point named {ref!r}", path,
                                 f"Its points are: {known}; or give a vector [x, y].")
        return
    for k, raw in enumerate(ref):
        _expression(raw, symbols, path + (k,), values=nominal)


def _check_constraint(mech: Mechanism, constraint: Any, symbols: Symbols,
                      nominal: Mapping[sp.Symbol, float], path: tuple[str | int, ...]) -> None:
    if constraint.name is not None and name_problem(constraint.name):
        raise MechanismError(str(name_problem(constraint.name)), path + ("name",), "Rename it.")
    if isinstance(constraint, Custom):
        for k, text in enumerate(constraint.equations):
            expr = _expression(text, symbols, path + ("equations", k), time=True,
                               coordinates=True)
            if not expr.free_symbols & set(symbols.q):
                raise MechanismError("this equation uses no coordinate, so it cannot "
                                     "constrain the mechanism", path + ("equations", k),
                                     "Use coordinates such as crank.phi or rod.x in it.")
        return
    bodies = [key for key in ("i", "j") if hasattr(constraint, key)]
    for key in bodies:
        _body_ref(mech, getattr(constraint, key), path + (key,))
    if constraint.type == "trajectory" and constraint.j == GROUND:
        raise MechanismError("a trajectory needs a moving body j, not the ground",
                             path + ("j",), "Name the body whose point should follow f(t).")
    if len(bodies) == 2 and constraint.i == constraint.j:
        raise MechanismError(f"a {constraint.type} joins body {constraint.i!r} to itself",
                             path + ("j",), "A constraint needs two different bodies.")
    for key, body_key in (("sA", "i"), ("sB", "j")):
        if hasattr(constraint, key):
            _point(mech, getattr(constraint, body_key), getattr(constraint, key), symbols,
                   nominal, path + (key,))
    for key in ("v", "u"):
        if hasattr(constraint, key):
            vector = [_expression(raw, symbols, path + (key, k), values=nominal)
                      for k, raw in enumerate(getattr(constraint, key))]
            _nonzero_vector(vector, nominal, path + (key,))
    if hasattr(constraint, "phi0"):
        _expression(constraint.phi0, symbols, path + ("phi0",), values=nominal)
    for key in ("f", "theta"):
        if hasattr(constraint, key):
            value = getattr(constraint, key)
            items = value if isinstance(value, list) else [value]
            for k, raw in enumerate(items):
                _expression(raw, symbols, path + ((key, k) if key == "f" and
                                                  isinstance(value, list) else (key,)), time=True)


def _nonzero_vector(vector: list[sp.Expr], nominal: Mapping[sp.Symbol, float],
                    path: tuple[str | int, ...]) -> None:
    if all(_numeric(component, nominal, path) == 0.0 for component in vector):
        raise MechanismError("the direction vector is zero", path,
                             "Give a non-zero vector, e.g. [0, 1].")


def _check_time(mech: Mechanism, symbols: Symbols, nominal: Mapping[sp.Symbol, float]) -> None:
    grid = {}
    for key in ("t0", "t1", "dt"):
        expr = _expression(getattr(mech.time, key), symbols, ("time", key))
        grid[key] = _numeric(expr, nominal, ("time", key))
    if not grid["dt"] > 0:
        raise MechanismError(f"the time step dt = {grid['dt']} is not positive",
                             ("time", "dt"), "Use dt > 0.")
    if not grid["t1"] > grid["t0"]:
        raise MechanismError(f"the end time t1 = {grid['t1']} is not after t0 = {grid['t0']}",
                             ("time", "t1"), "Use t1 > t0.")
    if (grid["t1"] - grid["t0"]) / grid["dt"] > MAX_GRID_POINTS:
        raise MechanismError(f"the grid has more than {MAX_GRID_POINTS} points", ("time", "dt"),
                             "Use a larger dt or a shorter interval.")


def degrees_of_freedom(mech: Mechanism) -> int:
    """Grübler's count w = 3n - 2 p5 - p4, less the equations of custom joints."""
    return 3 * len(mech.bodies) - sum(equation_count(joint) for joint in mech.joints)


def check_degrees_of_freedom(mech: Mechanism) -> None:
    """Check that the drivers supply exactly as many equations as there are DOF."""
    dof = degrees_of_freedom(mech)
    driving = sum(equation_count(driver) for driver in mech.drivers)
    if dof == driving:
        return
    p5 = sum(joint.type in ("revolute", "prismatic") for joint in mech.joints)
    p4 = sum(joint.type == "pin_slot" for joint in mech.joints)
    formula = f"w = 3·{len(mech.bodies)} − 2·{p5} − {p4}"
    custom = dof - (3 * len(mech.bodies) - 2 * p5 - p4)
    if custom:
        formula += f" − {-custom} (custom joint equations)"
    if driving < dof:
        fix = f"Add drivers for {dof - driving} more equation(s), or add joints."
    else:
        fix = f"Remove {driving - dof} driving equation(s), or check for a missing joint."
    raise MechanismError(f"the mechanism has {formula} = {dof} degree(s) of freedom but its "
                         f"drivers give {driving} equation(s)", ("drivers",), fix)
