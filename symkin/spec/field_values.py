"""A field of a mechanism file read against the file's names: an expression parsed (and, for a
constant field, its nominal value checked), a body named, a point named or given as a vector.
Each mistake is a :class:`MechanismError` at the field's path. Shared by the checks of
:mod:`symkin.spec.validate`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import sympy as sp

from symkin.errors import ExpressionError, MechanismError
from symkin.limits import listed
from symkin.pairs.fields import GROUND
from symkin.spec import constants, expressions
from symkin.spec.schema import MechanismSpec


@dataclass(frozen=True)
class Names:
    """What expressions of a file may name: parameters, t and (custom rows) coordinates.

    The symbols equal those of :mod:`symkin.symbolic.symbols` (same names, same assumptions),
    but validation does not depend on the symbolic stage.
    """

    parameters: dict[str, sp.Symbol]
    t: sp.Symbol
    by_coordinate: dict[tuple[str, str], sp.Symbol]

    @property
    def q(self) -> tuple[sp.Symbol, ...]:
        return tuple(self.by_coordinate.values())


def names_of(mech: MechanismSpec) -> Names:
    return Names(
        parameters={name: sp.Symbol(name, real=True) for name in mech.parameters},
        t=sp.Symbol("t", real=True),
        by_coordinate={(body, part): sp.Symbol(f"{body}.{part}", real=True)
                       for body in mech.bodies for part in mech.body_coordinates})

def numeric(expr: sp.Expr, values: Mapping[sp.Symbol, float],
             path: tuple[str | int, ...]) -> float:
    """The value of ``expr`` at the nominal parameters: a finite real number, or an error."""
    try:
        return constants.value(expr, values)
    except ExpressionError as error:
        raise MechanismError(f"{constants.describe(expr, 120)} has no finite real value at the "
                             f"nominal parameter values: {error.message}", path,
                             "Check the arguments of sqrt, log, asin, acos and the "
                             "magnitudes.") from None


def expression(raw: Any, symbols: Names | None, path: tuple[str | int, ...],
                time: bool = False, coordinates: bool = False,
                values: Mapping[sp.Symbol, float] | None = None) -> sp.Expr:
    """Parse a field; with ``values`` (a constant field) also check its nominal value."""
    if values is not None:
        expr = expression(raw, symbols, path, time, coordinates)
        numeric(expr, values, path)
        return expr
    names = dict(symbols.parameters) if symbols else {}
    if time and symbols:
        names["t"] = symbols.t
    if time and symbols and isinstance(raw, Mapping):
        # {poly: [a0, a1, ...]}: each coefficient a constant (t enters through the powers)
        for k, coefficient in enumerate(raw["poly"]):
            expression(coefficient, symbols, path + ("poly", k))
        return expressions.parse_time_function(raw, symbols.parameters, symbols.t)
    try:
        expr = expressions.parse(raw, names, symbols.by_coordinate if coordinates and symbols
                                 else None)
        if time and symbols:
            # Phi_t and Gamma differentiate it: their derivatives must be printable too.
            variables = [symbols.t, *sorted(expr.free_symbols & set(symbols.q), key=str)]
            expressions.check_derivatives(expr, variables, str(raw))
        return expr
    except ExpressionError as error:
        hint = "Use numbers, parameter names, pi, E, + - * / ** and the listed functions"
        hint += ", and t." if time else "."
        raise MechanismError(str(error), path, hint) from None


def body_ref(mech: MechanismSpec, name: str, path: tuple[str | int, ...]) -> None:
    if name != GROUND and name not in mech.bodies:
        known = listed([GROUND, *mech.bodies])
        raise MechanismError(f"unknown body {name!r}", path, f"Use one of: {known}.")


def point(mech: MechanismSpec, body: str, ref: Any, symbols: Names,
           nominal: Mapping[sp.Symbol, float], path: tuple[str | int, ...]) -> None:
    if isinstance(ref, str):
        points = mech.bodies[body].points if body != GROUND else {}
        if ref not in points:
            known = listed(points) or "none"
            raise MechanismError(f"body {body!r} has no point named {ref!r}", path,
                                 f"Its points are: {known}; or give a vector "
                                 f"{'[x, y, z]' if mech.is_spatial else '[x, y]'}.")
        return
    for k, raw in enumerate(ref):
        expression(raw, symbols, path + (k,), values=nominal)
