"""The SymPy symbols of a mechanism: coordinates, velocities, time and parameters."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import sympy as sp

from symkin import pairs
from symkin.contract.columns import RATE_SUFFIXES
from symkin.pairs.fields import GROUND
from symkin.spec.name_checks import input_places
from symkin.spec.schema import MechanismSpec


@dataclass(frozen=True)
class Input:
    """A driver function written ``input``: which driver, key and component it is, its name
    (the driver's, ``_x``/``_y`` per component of a vector; ``drivers[k]`` when unnamed) and
    the symbols of its value, rate and acceleration."""

    name: str
    driver: int
    key: str
    component: int | None
    u: sp.Symbol
    du: sp.Symbol
    ddu: sp.Symbol


@dataclass(frozen=True)
class Symbols:
    """The SymPy symbols of a mechanism: coordinates, velocities, time and parameters."""

    q: tuple[sp.Symbol, ...]
    dq: tuple[sp.Symbol, ...]
    t: sp.Symbol
    p: tuple[sp.Symbol, ...]
    coordinates: tuple[str, ...]
    per_body: int = 3
    """Coordinates per body: 3 in a planar file (x, y, phi), 7 in a spatial one."""
    inputs: tuple[Input, ...] = ()

    # Built once per Symbols: derivation asks for them for every constraint and expression.
    @cached_property
    def parameters(self) -> dict[str, sp.Symbol]:
        return {symbol.name: symbol for symbol in self.p}

    @cached_property
    def by_coordinate(self) -> dict[tuple[str, str], sp.Symbol]:
        """``(body, "x"|"y"|"phi") -> q symbol`` (spatial: x..z, e0..e3), for custom
        constraints."""
        pairs = (name.partition(".") for name in self.coordinates)
        return {(body, part): q for (body, _, part), q in zip(pairs, self.q)}

    @cached_property
    def _first_coordinate(self) -> dict[str, int]:
        """Body name -> index of its x coordinate."""
        return {name[:-2]: k for k, name in enumerate(self.coordinates) if name.endswith(".x")}

    def body(self, name: str, velocities: bool = False) -> tuple[sp.Expr, ...]:
        """(x, y, phi) of a body (spatial: x, y, z, e0..e3), or their rates; the ground is
        fixed at zero (planar) or at the identity (spatial)."""
        if name == GROUND:
            fixed = (0, 0, 0, 1, 0, 0, 0) if self.per_body == 7 else (0, 0, 0)
            return tuple(sp.Integer(0 if velocities else value) for value in fixed)
        start = self._first_coordinate[name]
        source = self.dq if velocities else self.q
        return tuple(source[start:start + self.per_body])


def extra_coordinates(mech: MechanismSpec) -> tuple[tuple[str, object], ...]:
    """The coordinates pairs add beyond the bodies' (``NAME.s`` of a curve or cam pair), with
    their first guesses, in file order."""
    return tuple(extra for section in pairs.SECTIONS for constraint in getattr(mech, section)
                 for extra in pairs.of(constraint).extra_coordinates(constraint))


def make_symbols(mech: MechanismSpec) -> Symbols:
    """Create the symbols of ``mech``; coordinate names are ``body.x``, ``body.y``, ``body.phi``
    (spatial: ``body.x`` .. ``body.z``, ``body.e0`` .. ``body.e3``), then the pairs' own
    coordinates (``NAME.s``) after all the bodies'."""
    parts = mech.body_coordinates
    coordinates = tuple(f"{b}.{c}" for b in mech.bodies for c in parts)
    coordinates += tuple(name for name, _ in extra_coordinates(mech))
    q = tuple(sp.Symbol(name, real=True) for name in coordinates)
    dq = tuple(sp.Symbol(name + "_t", real=True) for name in coordinates)
    p = tuple(sp.Symbol(name, real=True) for name in mech.parameters)
    return Symbols(q, dq, sp.Symbol("t", real=True), p, coordinates, len(parts),
                   find_inputs(mech))


def find_inputs(mech: MechanismSpec) -> tuple[Input, ...]:
    """Every driver function written ``input``, drivers in file order, components in order.

    Their symbols are named ``input:NAME`` (and ``_t``, ``_tt``): no parameter or coordinate
    can have such a name, so they never clash with one.
    """
    found = []
    for name, index, key, component in input_places(mech):
        u, du, ddu = (sp.Symbol(f"input:{name}{suffix}", real=True)
                      for suffix in ("", *RATE_SUFFIXES))  # distinct: spec checked the names
        found.append(Input(name, index, key, component, u, du, ddu))
    return tuple(found)
