"""The file's masses and applied forces (inverse dynamics): the ``forces`` section's models
and their semantic checks.

A body may carry ``mass``, ``inertia`` (about its centre of mass) and ``com`` (a point name or
a vector in the body frame; the drawn layout gives it globally and :mod:`symkin.spec.drawn`
converts it). The ``forces`` section lists

    {type: gravity, g: [gx, gy]}
    {type: force,  name, body, at: POINT | [x, y], f: [fx, fy]}     f in global components
    {type: torque, name, body, m}
    {type: spring, name, i, A, j, B, k, length0, damping}

Expressions in forces may use t, parameters, coordinates (``body.x``, ``body.y``,
``body.phi``) and their rates (``body.x_t``, ``body.phi_t``); they are parsed by the
whitelist parser only (:mod:`symkin.spec.expressions`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any, Literal

import sympy as sp
from pydantic import Field

from symkin.pairs.fields import Expr, PointRef, Strict, Vec2
from symkin.spec.constants import MAX_MAGNITUDE

RATE_SUFFIX = "_t"
COORDINATE_PARTS = ("x", "y", "phi")


class Gravity(Strict):
    """A uniform field: the force m g at every body's centre of mass."""

    type: Literal["gravity"]
    g: Vec2


class PointForce(Strict):
    """A force f (global components) applied at a point of one body."""

    type: Literal["force"]
    name: str | None = None
    body: str
    at: PointRef = Field(default_factory=lambda: [0, 0])
    f: Vec2


class Torque(Strict):
    """A pure moment m (counter-clockwise positive) on one body."""

    type: Literal["torque"]
    name: str | None = None
    body: str
    m: Expr


class Spring(Strict):
    """A linear spring-damper between point A of body i and point B of body j: tension
    k (L - length0) + damping dL/dt, pulling the points together when positive."""

    type: Literal["spring"]
    name: str | None = None
    i: str
    A: PointRef = Field(default_factory=lambda: [0, 0])
    j: str
    B: PointRef = Field(default_factory=lambda: [0, 0])
    k: Expr = 0
    length0: Expr = 0
    damping: Expr = 0


Load = Annotated[Gravity | PointForce | Torque | Spring, Field(discriminator="type")]

# Which keys of each type name a body, and which name a point of which body (key, body key).
BODY_KEYS = {"gravity": (), "force": ("body",), "torque": ("body",), "spring": ("i", "j")}
POINT_KEYS = {"gravity": (), "force": (("at", "body"),), "torque": (),
              "spring": (("A", "i"), ("B", "j"))}
# Keys holding one expression (constants and functions of t, q, dq alike) or a vector of them.
EXPRESSION_KEYS = {"gravity": ("g",), "force": ("f",), "torque": ("m",),
                   "spring": ("k", "length0", "damping")}


def coordinate_names(bodies: Mapping[str, Any], symbol: Any = None,
                     parts: tuple[str, ...] = COORDINATE_PARTS
                     ) -> dict[tuple[str, str], sp.Symbol]:
    """``(body, "x"|"y"|"phi"|"x_t"|...) -> Symbol`` named ``body.x`` / ``body.x_t``, the
    coordinates and rates an expression in ``forces`` may use (the symbolic stage's names);
    ``parts``: a body's coordinates (a spatial file's in :mod:`symkin.spec.forces3d`)."""
    make = symbol or (lambda name: sp.Symbol(name, real=True))
    found = {}
    for body in bodies:
        for part in parts:
            found[(body, part)] = make(f"{body}.{part}")
            found[(body, part + RATE_SUFFIX)] = make(f"{body}.{part}{RATE_SUFFIX}")
    return found


def has_dynamics(mech: Any) -> bool:
    """True when the file states a mass, an inertia or a force: then efforts and reactions
    are computed (a file of kinematics alone generates exactly the code it did before)."""
    # (a spatial body has no mass keys: getattr)
    return bool(mech.forces) or any(getattr(body, "mass", None) is not None or
                                    getattr(body, "inertia", None) is not None
                                    for body in mech.bodies.values())


def load_name(load: Any, index: int) -> str:
    """A load's label: its own name, or ``forces[k]``."""
    return getattr(load, "name", None) or f"forces[{index}]"


def weight_problem(mass: float, gravity: float) -> tuple[str, str] | None:
    """Why a mass is beyond what the generated code can weigh: its weight m |g| (``gravity``:
    the largest |g| component of the file's gravity loads, 0 without) is no double, or its
    mass times the unit lengths of M and h is beyond symkin's evaluator (constants:
    MAX_MAGNITUDE); (message, hint), or None."""
    if mass * max(1.0, gravity) <= MAX_MAGNITUDE:
        return None
    return (f"the mass {mass:.6g} is too large: its weight or its terms in the mass matrix "
            f"exceed {MAX_MAGNITUDE:g}, beyond what double-precision code computes with",
            "Give masses in a unit that brings them nearer 1 (e.g. tonnes).")


def massless_problem(body: Any) -> tuple[str, str] | None:
    """A body that gives ``com`` (or ``com`` and ``inertia``) but no ``mass`` would be
    silently massless in translation: refused, since a centre of mass only says where a
    mass acts; (message, hint), or None."""
    if getattr(body, "com", None) is None or getattr(body, "mass", None) is not None:
        return None
    return ("the body gives a centre of mass (com) but no mass: it would be massless in "
            "translation, its weight and inertial forces zero",
            "Give its mass (mass: 0 if it truly has none), or remove com.")

