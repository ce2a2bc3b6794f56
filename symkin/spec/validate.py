"""Validation of a mechanism: shapes (pydantic, :mod:`symkin.spec.schema`), then what needs
the whole file — names, references between fields, expressions, the time grid and the
degree-of-freedom count. Every mistake is a :class:`MechanismError` with the field path.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from pydantic import ValidationError, model_validator

from symkin import pairs
from symkin.errors import ExpressionError, MechanismError, UsageError, format_path
from symkin.limits import MAX_GRID_POINTS, grid_points, listed
from symkin.pairs.fields import GROUND, is_input
from symkin.spec import constants, drawn, drawn3d, drawn_schema, expressions, forces, loader, motion
from symkin.spec.field_values import Names, body_ref, expression, names_of, numeric
from symkin.spec.field_values import point as point_ref
from symkin.spec.forces3d import coordinate_names as spatial_coordinate_names
from symkin.spec.forces3d import entries, magnitude_problem
from symkin.spec.messages import translate
from symkin.spec.mobility import check_degrees_of_freedom
from symkin.spec.mobility import degrees_of_freedom as degrees_of_freedom
from symkin.spec.name_checks import _check_coordinate_name, _check_input_names, _check_names
from symkin.spec.names import name_problem
from symkin.spec.schema import MechanismSpec, SpatialMechanismSpec


class Mechanism(MechanismSpec):
    """A validated planar mechanism. Build it with :func:`load` or :func:`from_dict`."""

    @model_validator(mode="after")
    def _semantics(self) -> Mechanism:
        _check_semantics(self)
        return self


class SpatialMechanism(SpatialMechanismSpec, Mechanism):
    """A validated spatial mechanism (``space: 3d``)."""


def load(path: str | Path, overrides: Mapping[str, str] | None = None) -> Mechanism:
    """Read and validate a mechanism file (YAML, or TOML by suffix).

    Args:
        path: the file.
        overrides: parameter values replacing the file's (``--set b=2*pi``): each a number or
            an expression of numbers, read by the whitelist parser.

    Raises:
        MechanismError: the file is invalid.
        UsageError: an override names no parameter of the file or is not a finite number.
    """
    document = loader.read(path)
    if overrides:
        document.data = override_parameters(document.data, overrides, document.source)
    return _validate(document)


def locate(error: MechanismError, path: str | Path) -> MechanismError:
    """An error found after loading (e.g. by the rank analysis of a derived System) that names
    a field of the file, located in the file ``path``: its name and the field's line."""
    if error.source is not None:
        return error
    try:
        document = loader.read(path)
    except MechanismError:
        return error.located(str(path), None)
    return error.located(document.source, document.line_of(error.path))


def override_parameters(data: Any, overrides: Mapping[str, str], source: str) -> Any:
    """The file's data with parameter values replaced; each new value is checked here."""
    if not isinstance(data, Mapping):
        return data
    parameters = data.get("parameters")
    parameters = parameters if isinstance(parameters, Mapping) else {}
    known = list(parameters)
    for name, text in overrides.items():
        if name not in known:
            raise UsageError(f"--set {name}: {source} has no parameter {name!r}; its "
                             f"parameters are: {listed(map(str, known)) or 'none'}")
        try:
            constants.value(expressions.parse(text, {}))
        except ExpressionError as error:
            raise UsageError(f"--set {name}={text}: {error}. Give a number or an expression "
                             "of numbers, such as 2.5 or 2*pi/3") from None
    return {**data, "parameters": {**parameters, **{name: _number_or_text(text)
                                                    for name, text in overrides.items()}}}


def _number_or_text(text: str) -> float | str:
    """A plain number stays a number (shown as one by ``show --local``); else the text."""
    try:
        return float(text)
    except ValueError:
        return text


def from_dict(data: Mapping[str, Any], source: str = "<mechanism>") -> Mechanism:
    """Validate a mechanism given as plain Python data (the file's structure)."""
    return _validate(loader.from_python(data, source))


def json_schema() -> dict[str, Any]:
    """The JSON Schema of the mechanism file format."""
    return drawn_schema.json_schema_of(Mechanism)


def _validate(document: loader.Document) -> Mechanism:
    if not isinstance(document.data, dict):
        raise MechanismError("the file must be a mapping with keys name, parameters, bodies, "
                             "joints, drivers, time", source=document.source, line=1)
    try:
        # A drawn document (layout: drawn) is first turned into the local form.
        if drawn3d.space_of(document.data) == "3d":
            return SpatialMechanism.model_validate(drawn3d.to_local(document.data))
        planar = {key: value for key, value in document.data.items() if key != "space"}
        return Mechanism.model_validate(drawn.to_local(planar))
    except MechanismError as error:
        raise error.located(document.source, document.line_of(error.path)) from None
    except ValidationError as error:
        raise translate(error, document) from None


def _check_semantics(mech: Mechanism) -> None:
    _check_names(mech)
    symbols = names_of(mech)
    values = _check_parameters(mech)
    nominal = {symbols.parameters[name]: value for name, value in values.items()}
    for name, body in mech.bodies.items():
        for k, raw in enumerate(body.q0):
            expression(raw, symbols, ("bodies", name, "q0", k), values=nominal)
        for point, vector in body.points.items():
            for k, raw in enumerate(vector):
                expression(raw, symbols, ("bodies", name, "points", point, k), values=nominal)
    named: dict[str, tuple[str | int, ...]] = {}
    for section in ("joints", "drivers"):
        for index, constraint in enumerate(getattr(mech, section)):
            path = (section, index)
            _check_coordinate_name(mech, constraint, path)
            _check_constraint(mech, constraint, symbols, nominal, path)
            if constraint.name in named:
                raise MechanismError(f"the name {constraint.name!r} is already used by "
                                     f"{format_path(named[constraint.name])}", path + ("name",),
                                     "Joints and drivers need different names: each labels "
                                     "rows of Phi.")
            if constraint.name is not None:
                named[constraint.name] = path
    _check_input_names(mech)
    _check_time(mech, symbols, nominal)
    _check_dynamics(mech, symbols, nominal)
    check_degrees_of_freedom(mech)
    motion.check(mech, symbols.parameters, nominal)


def _check_parameters(mech: Mechanism) -> dict[str, float]:
    values = {}
    for name, raw in mech.parameters.items():
        try:
            expr = expressions.parse(raw, {})
        except ExpressionError as error:
            raise MechanismError(str(error), ("parameters", name),
                                 "A parameter's value is a number or an expression of numbers, "
                                 "pi and E; it cannot use t or other parameters.") from None
        values[name] = numeric(expr, {}, ("parameters", name))
    return values


@dataclass(frozen=True)
class _Checks:
    """What a pair module's own checks are given (:class:`symkin.pairs.kit.Checks`)."""

    mech: Mechanism
    symbols: Names
    nominal: Mapping[sp.Symbol, float]

    def expression(self, raw: Any, path: tuple[str | int, ...], *, time: bool = False,
                   coordinates: bool = False) -> sp.Expr:
        return expression(raw, self.symbols, path, time, coordinates)

    def uses_coordinates(self, expr: sp.Expr) -> bool:
        return bool(expr.free_symbols & set(self.symbols.q))

    def value(self, expr: sp.Expr, path: tuple[str | int, ...]) -> float:
        return numeric(expr, self.nominal, path)

    def over_time(self, expr: sp.Expr, count: int = 201) -> list[tuple[float, float]]:
        """(t, value) of a time function at the nominal parameters, at ``count`` times spread
        over the file's grid t0 .. t1 (both ends included); times where it has no finite real
        value are left out (the run reports those)."""
        try:
            t0, t1 = (numeric(expression(getattr(self.mech.time, key), self.symbols,
                                           ("time", key)), self.nominal, ("time", key))
                      for key in ("t0", "t1"))
        except MechanismError:  # said by the grid's own check
            return []
        times = np.linspace(t0, t1, count)
        # in floats (not exact numbers), vectorised: mpmath at each time would take seconds
        # for a long expression such as a Stewart leg's
        floating = expr.subs(self.nominal).evalf()
        try:
            function = sp.lambdify(self.symbols.t, floating, modules="numpy")
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                values = np.broadcast_to(np.asarray(function(times)), times.shape)
        except (TypeError, ValueError, ZeroDivisionError, OverflowError, AttributeError):
            return []
        if np.iscomplexobj(values):
            return []
        values = np.asarray(values, dtype=float)
        return [(float(t), float(v)) for t, v in zip(times, values) if math.isfinite(v)]

    def curve(self, raw: Any, path: tuple[str | int, ...], order: int = 2) -> sp.Expr:
        """A curve's component: an expression of the parameters and ``s``, whose derivatives
        in s up to ``order`` (what Phi_q and Gamma need) are printable."""
        s = sp.Symbol("s", real=True)
        if "s" in self.symbols.parameters:
            raise MechanismError("a parameter is called s, the curve's own parameter",
                                 ("parameters", "s"), "Rename the parameter.")
        try:
            expr = expressions.parse(raw, {**self.symbols.parameters, "s": s})
            lower = sp.diff(expr, s, order - 2) if order > 2 else expr
            expressions.check_derivatives(lower, [s], str(raw))
        except ExpressionError as error:
            raise MechanismError(str(error), path, "Use numbers, parameter names, s, pi, E, "
                                 "+ - * / ** and the listed functions.") from None
        return expr

    def curve_value(self, expr: sp.Expr, s: float, path: tuple[str | int, ...]) -> float:
        """A curve's expression at the nominal parameters and ``s``."""
        at_s = expr.subs(self.nominal).subs(sp.Symbol("s", real=True), s)
        return numeric(at_s, {}, path)

    def body_names(self) -> tuple[str, ...]:
        return tuple(self.mech.bodies)

    def at_nominal(self, expr: sp.Expr) -> sp.Expr:
        """``expr`` with the parameters at their nominal values and every constant part a
        double (exact numbers would reach NumPy as Python ints: constants.lambdify_floats)."""
        return constants.fold(expr.subs(self.nominal))

    def point(self, body: str, ref: Any, path: tuple[str | int, ...]) -> None:
        """A point of ``body`` by name, or a vector of constant expressions."""
        point_ref(self.mech, body, ref, self.symbols, self.nominal, path)

    def pins(self, a: str, b: str) -> list[tuple[tuple[float, ...], tuple[float, ...]]]:
        """Where a pivot pair (a revolute) pins bodies ``a`` and ``b`` together: each such
        joint's local points (nominal values) as (point on a, point on b), in file order."""
        found = []
        for constraint in self.mech.joints:
            kind = pairs.of(constraint)
            if not kind.pivot:
                continue
            at = {getattr(constraint, body): getattr(constraint, key)
                  for key, body in kind.points}
            if set(at) == {a, b}:
                with contextlib.suppress(KeyError, ExpressionError):  # its own check says
                    found.append((self._local(a, at[a]), self._local(b, at[b])))
        return found

    def _local(self, body: str, ref: Any) -> tuple[float, ...]:
        """A point's local vector (or any list of constants) at the nominal values."""
        local = self.mech.bodies[body].points[ref] if isinstance(ref, str) else ref
        return tuple(constants.value(expressions.parse(raw, self.symbols.parameters),
                                     self.nominal) for raw in local)

    def point_at_q0(self, body: str, ref: Any) -> tuple[float, ...]:
        """The global position of a (checked) point of ``body`` at its first guess q0."""
        local = self._local(body, ref)  # checked already: parses and has a value
        if self.mech.is_spatial:
            return _spatial_point(list(local), body,
                                  list(self._local(body, self.mech.bodies[body].q0))
                                  if body != GROUND else None)
        sx, sy = local
        if body == GROUND:
            return sx, sy
        x, y, phi = self._local(body, self.mech.bodies[body].q0)
        return (x + math.cos(phi) * sx - math.sin(phi) * sy,
                y + math.sin(phi) * sx + math.cos(phi) * sy)


def _spatial_point(s: list[float], body: str, q0: list[float] | None) -> tuple[float, ...]:
    """r + A(e) s for a spatial body at q0 = [x, y, z, e0..e3] (the ground: s itself)."""
    if q0 is None:
        return tuple(s)
    e0, e1, e2, e3 = q0[3:]
    a = ((e0*e0 + e1*e1 - e2*e2 - e3*e3, 2*(e1*e2 - e0*e3), 2*(e1*e3 + e0*e2)),
         (2*(e1*e2 + e0*e3), e0*e0 - e1*e1 + e2*e2 - e3*e3, 2*(e2*e3 - e0*e1)),
         (2*(e1*e3 - e0*e2), 2*(e2*e3 + e0*e1), e0*e0 - e1*e1 - e2*e2 + e3*e3))
    return tuple(q0[k] + sum(a[k][m] * s[m] for m in range(3)) for k in range(3))


def _check_constraint(mech: Mechanism, constraint: Any, symbols: Names,
                      nominal: Mapping[sp.Symbol, float], path: tuple[str | int, ...]) -> None:
    """The generic checks, driven by what the pair module says its keys are, then its own."""
    kind = pairs.of(constraint)
    role = "joint" if path[0] == "joints" else "driver"
    if constraint.name is not None and name_problem(constraint.name, role):
        raise MechanismError(str(name_problem(constraint.name, role)), path + ("name",),
                             "Rename it.")
    for key in kind.bodies:
        body_ref(mech, getattr(constraint, key), path + (key,))
    if len(kind.bodies) == 2 and len(set(kind.joined_bodies(constraint))) == 1:
        raise MechanismError(f"a {kind.name} joins body {constraint.i!r} to itself",
                             path + ("j",), "A constraint needs two different bodies.")
    if kind.on_ground and GROUND in (getattr(constraint, key) for key in kind.bodies):
        raise MechanismError(f"a {kind.name} needs a moving body {kind.bodies[0]}, not the "
                             "ground", path + (kind.bodies[0],), "Name the body whose point "
                             "should follow f(t).")
    for key, body_key in kind.points:
        point_ref(mech, getattr(constraint, body_key), getattr(constraint, key), symbols,
               nominal, path + (key,))
    for key, _ in kind.directions:
        vector = [expression(raw, symbols, path + (key, k), values=nominal)
                  for k, raw in enumerate(getattr(constraint, key))]
        _nonzero_vector(vector, nominal, path + (key,))
    for key in kind.constants:
        if getattr(constraint, key) is not None:
            expression(getattr(constraint, key), symbols, path + (key,), values=nominal)
    for key in kind.time_functions:
        value = getattr(constraint, key)
        for k, raw in enumerate(value) if isinstance(value, list) else ((None, value),):
            if not is_input(raw):  # an input has no formula to check
                expression(raw, symbols, path + ((key, k) if k is not None else (key,)),
                            time=True)
    if kind.check is not None:
        kind.check(constraint, _Checks(mech, symbols, nominal), path)


def _nonzero_vector(vector: list[sp.Expr], nominal: Mapping[sp.Symbol, float],
                    path: tuple[str | int, ...]) -> None:
    if all(numeric(component, nominal, path) == 0.0 for component in vector):
        raise MechanismError("the direction vector is zero", path,
                             "Give a non-zero vector, e.g. [0, 1].")


def _check_time(mech: Mechanism, symbols: Names, nominal: Mapping[sp.Symbol, float]) -> None:
    grid = {}
    for key in ("t0", "t1", "dt"):
        expr = expression(getattr(mech.time, key), symbols, ("time", key))
        grid[key] = numeric(expr, nominal, ("time", key))
    if not grid["dt"] > 0:
        raise MechanismError(f"the time step dt = {grid['dt']} is not positive",
                             ("time", "dt"), "Use dt > 0.")
    if not grid["t1"] > grid["t0"]:
        raise MechanismError(f"the end time t1 = {grid['t1']} is not after t0 = {grid['t0']}",
                             ("time", "t1"), "Use t1 > t0.")
    if grid_points(grid["t0"], grid["t1"], grid["dt"]) > MAX_GRID_POINTS:
        raise MechanismError(f"the grid has more than {MAX_GRID_POINTS} points", ("time", "dt"),
                             "Use a larger dt or a shorter interval.")


def _gravity(mech: Mechanism, symbols: Names, nominal: Mapping[sp.Symbol, float]) -> float:
    """The largest |g| component of the file's gravity loads that is a constant (0 without):
    a g that varies with t or the coordinates is checked with the other loads' expressions."""
    found = []
    for k, load in enumerate(mech.forces):
        if load.type != "gravity":
            continue
        for n, raw in enumerate(load.g):
            path = ("forces", k, "g", n)
            with contextlib.suppress(MechanismError):  # not a constant: judged as a load
                found.append(abs(numeric(expression(raw, symbols, path), nominal, path)))
    return max(found, default=0.0)


def _check_dynamics(mech: Mechanism, symbols: Names,
                    nominal: Mapping[sp.Symbol, float]) -> None:
    """Masses and inertias are constants >= 0; a load names known bodies and points, and its
    expressions use only t, parameters, coordinates and their rates."""
    gravity = _gravity(mech, symbols, nominal)
    for name, body in mech.bodies.items():
        massless = forces.massless_problem(body)
        if massless is not None:
            raise MechanismError(massless[0], ("bodies", name, "com"), massless[1])
        for key in ("mass", "inertia"):
            raw = getattr(body, key)
            if raw is None:
                continue
            path = ("bodies", name, key)
            values = {at: numeric(expression(item, symbols, path + at), nominal, path + at)
                      for at, item in entries(raw)}
            problem = magnitude_problem(key, values) or (
                forces.weight_problem(values[()], gravity) if key == "mass" else None)
            if problem is not None:
                raise MechanismError(problem[0], path, problem[1])
        if body.com is not None:
            point_ref(mech, name, body.com, symbols, nominal, ("bodies", name, "com"))
    names = spatial_coordinate_names if mech.is_spatial else forces.coordinate_names
    moving = Names(symbols.parameters, symbols.t, names(mech.bodies))
    for index, load in enumerate(mech.forces):
        where: tuple[str | int, ...] = ("forces", index)
        for key in forces.BODY_KEYS[load.type]:
            body_ref(mech, getattr(load, key), where + (key,))
        if load.type in ("force", "torque") and load.body == GROUND:
            raise MechanismError(f"a {load.type} on the ground does nothing", where + ("body",),
                                 "Apply it to a moving body.")
        for key, body_key in forces.POINT_KEYS[load.type]:
            point_ref(mech, getattr(load, body_key), getattr(load, key), symbols, nominal,
                   where + (key,))
        for key in forces.EXPRESSION_KEYS[load.type]:
            raw = getattr(load, key)
            for k, item in (enumerate(raw) if isinstance(raw, list) else [(None, raw)]):
                at: tuple[str | int, ...] = (key,) if k is None else (key, k)
                expression(item, moving, where + at, time=True, coordinates=True)
