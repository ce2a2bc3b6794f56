"""Forward dynamics in the file: the keys ``initial`` and ``integrator`` and their checks.

A mechanism whose drivers fix fewer freedoms than it has moves under its ``forces``; it needs
masses (a ``mass`` or an ``inertia`` on some body), else its motion is undetermined. Two
optional top-level keys belong to such a file only:

    initial:
      velocities: {crank.phi: 1.0, slider.x: 0.0}    # planar: body.x, body.y, body.phi
                                                     # (and a pair's own NAME.s);
                                                     # spatial: body.x/.y/.z and
                                                     # body.omega_x/_y/_z (global)
    integrator: {rtol: 1e-8, atol: 1e-10}

A velocity is an expression of the parameters. The runtime makes the initial velocity
consistent with the constraints (runtime.dynamics.initial); here only names and values are
checked, so that a wrong name is refused at its line before anything is derived.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import sympy as sp
from pydantic import Field

from symkin import pairs
from symkin.errors import ExpressionError, MechanismError
from symkin.limits import listed
from symkin.pairs.fields import Expr, Strict
from symkin.spec import constants, expressions

# The integrator's defaults (runtime.dynamics reads them from here through the System):
# tight enough that positions stay within 1e-6 of a benchmark's largest displacement.
DEFAULT_RTOL = 1e-8
DEFAULT_ATOL = 1e-10

# The velocity names of a spatial body: the rates of its frame's origin and its angular
# velocity in global components (the Euler parameters' rates follow from it).
SPATIAL_VELOCITY_PARTS = ("x", "y", "z", "omega_x", "omega_y", "omega_z")


class Initial(Strict):
    """The state at t0 beyond the assembled position: velocities by coordinate name."""

    velocities: dict[str, Expr] = Field(default_factory=dict)


class Integrator(Strict):
    """The integrator's error control: relative and absolute tolerance per step."""

    rtol: float = DEFAULT_RTOL
    atol: float = DEFAULT_ATOL


def has_masses(mech: Any) -> bool:
    """True when some body states a mass or an inertia (the motion can then be integrated)."""
    return any(getattr(body, "mass", None) is not None
               or getattr(body, "inertia", None) is not None for body in mech.bodies.values())


def velocity_names(mech: Any) -> tuple[str, ...]:
    """Every name ``initial.velocities`` may use, in coordinate order."""
    parts = SPATIAL_VELOCITY_PARTS if mech.is_spatial else mech.body_coordinates
    names = [f"{body}.{part}" for body in mech.bodies for part in parts]
    for joint in mech.joints:
        names += [name for name, _ in pairs.of(joint).extra_coordinates(joint)]
    return tuple(names)


def moves(rows: int, coordinates: int) -> bool:
    """Whether the forces move a mechanism: the rows of Phi left after the redundant ones are
    removed (symbolic.redundancy) are fewer than its coordinates. The one criterion of the
    derivation (symbolic.motion.moves_under_forces) and of these keys."""
    return rows < coordinates


def refuse_keys(mech: Any, moves: bool) -> None:
    """Refuse ``initial`` and ``integrator`` unless the mechanism ``moves`` under its forces.
    The derivation decides that (rows of Phi left after the redundant ones are removed, fewer
    than coordinates: symbolic.motion.moves_under_forces); the spec refuses them earlier only
    where no body has a mass, since a degree-of-freedom count cannot see redundant rows."""
    for key in ("initial", "integrator"):
        if getattr(mech, key) is not None and not moves:
            raise MechanismError(
                f"'{key}' applies to a mechanism that moves under its forces, but this file's "
                "drivers fix every freedom", (key,),
                f"Remove '{key}', or remove drivers so that the forces move the mechanism.")


def check(mech: Any, parameters: Mapping[str, sp.Symbol],
          nominal: Mapping[sp.Symbol, float]) -> None:
    """Refuse ``initial`` and ``integrator`` in a file without masses whose drivers fix its
    motion (refuse_keys), an unknown velocity name, a velocity that is not a finite constant,
    a tolerance that is not positive."""
    refuse_keys(mech, has_masses(mech))
    if mech.initial is not None:
        _check_velocities(mech, parameters, nominal)
    if mech.integrator is not None:
        for key in ("rtol", "atol"):
            value = getattr(mech.integrator, key)
            if not (math.isfinite(value) and value > 0):
                raise MechanismError(f"the tolerance {key} = {value!r} is not a positive number",
                                     ("integrator", key),
                                     f"Give a positive {key}, e.g. {_default(key):g}.")
        if mech.integrator.rtol >= 1:
            raise MechanismError(f"the relative tolerance rtol = {mech.integrator.rtol!r} is "
                                 "not below 1: no digit would be controlled",
                                 ("integrator", "rtol"), "Give e.g. rtol: 1e-8.")


def _default(key: str) -> float:
    return DEFAULT_RTOL if key == "rtol" else DEFAULT_ATOL


def _check_velocities(mech: Any, parameters: Mapping[str, sp.Symbol],
                      nominal: Mapping[sp.Symbol, float]) -> None:
    known = velocity_names(mech)
    for name, raw in mech.initial.velocities.items():
        path = ("initial", "velocities", name)
        if name not in known:
            shown = listed(known)
            raise MechanismError(f"{name!r} is not a velocity of this mechanism", path,
                                 f"Use one of: {shown}.")
        try:
            constants.value(expressions.parse(raw, parameters), nominal)
        except ExpressionError as error:
            raise MechanismError(f"the initial velocity of {name} is not a finite constant: "
                                 f"{error.message}", path,
                                 "A velocity is a number or an expression of the parameters "
                                 "(not of t or of coordinates).") from None


def velocity_expressions(mech: Any, parameters: Mapping[str, sp.Symbol]
                         ) -> dict[str, sp.Expr]:
    """The given initial velocities as expressions of the parameters (checked already):
    a run with other parameter values evaluates them there."""
    given = mech.initial.velocities if mech.initial is not None else {}
    return {name: expressions.parse(raw, parameters) for name, raw in given.items()}
