"""Gear pair: two gears i and j whose centres are held by a carrier (the ground by default)
roll on their pitch circles without slipping. Relative to the carrier (Willis):

    external:  r_i (phi_i - phi_c) + r_j (phi_j - phi_c) = offset
    internal:  r_i (phi_i - phi_c) - r_j (phi_j - phi_c) = offset   (j the ring gear)

One row, a length (the arc rolled). ``offset`` defaults to its value at q0 (the drawing in
the drawn layout, whose q0 is the drawing). The pair holds only the rolling: the centres are
held by the joints the file gives, revolute joints of both gears to the carrier. Refused, as
they would make the rolling equation describe gears that do not mesh: a gear not pinned to
the carrier (nothing holds its centre distance), and pivots on the carrier whose distance is
not r_i + r_j (external) or r_j - r_i (internal) at the nominal parameters (the pitch circles
would not touch). A carrier at rest (the ground, or an arm held still) or driven needs
nothing more: Willis' relation holds relative to it either way.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Literal

import sympy as sp

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import GROUND, Expr, Strict, Vec2

MESH_TOLERANCE = 1e-6
"""Relative: the drawing tolerance, so a drawn centre distance read to six digits passes."""


class Gear(Strict):
    """Gears i and j with pitch radii ``radii`` on ``carrier``; ``internal``: j is a ring."""

    type: Literal["gear"]
    name: str | None = None
    i: str
    j: str
    radii: Vec2
    carrier: str = GROUND
    internal: bool = False
    offset: Expr | None = None


def _rolled(c: Gear, pose_of: Callable[[str], kit.Pose], geometry: kit.Geometry) -> sp.Expr:
    """r_i (phi_i - phi_c) +- r_j (phi_j - phi_c) for the poses ``pose_of`` gives."""
    ri, rj = (geometry.expr(raw) for raw in c.radii)
    phi_c = pose_of(c.carrier).phi
    turn_i, turn_j = pose_of(c.i).phi - phi_c, pose_of(c.j).phi - phi_c
    return ri * turn_i + (-1 if c.internal else 1) * rj * turn_j


def equations(c: Gear, geometry: kit.Geometry) -> list[sp.Expr]:
    """The arc rolled on the pitch circles, less its value at q0 (or ``offset``)."""
    offset = (_rolled(c, geometry.initial_pose, geometry) if c.offset is None
              else geometry.expr(c.offset))
    return [_rolled(c, geometry.pose, geometry) - offset]


def check(c: Gear, checks: kit.Checks, path: kit.Path) -> None:
    """Positive radii; three different bodies; an internal pair's ring the larger gear."""
    if c.i == c.j:
        raise MechanismError(f"a gear pair meshes body {c.i!r} with itself", path + ("j",),
                             "Name two different gears.")
    values = []
    for k, raw in enumerate(c.radii):
        value = checks.value(checks.expression(raw, path + ("radii", k)), path + ("radii", k))
        if not value > 0:
            raise MechanismError(f"the pitch radius {value:g} is not positive",
                                 path + ("radii", k), "Give each gear's pitch radius, > 0.")
        values.append(value)
    if c.carrier in (c.i, c.j):
        raise MechanismError(f"the carrier {c.carrier!r} is one of the two gears",
                             path + ("carrier",), "The carrier is the body holding both "
                             "gears' centres (the arm of a planetary set; ground by default).")
    if c.internal and not values[1] > values[0]:
        raise MechanismError(f"an internal pair's ring j (radius {values[1]:g}) must be "
                             f"larger than the pinion i (radius {values[0]:g})",
                             path + ("radii", 1), "Give the ring gear as j, or set "
                             "internal: false.")
    _check_carrier(c, checks, path, values)


def _centre_on_carrier(gear: str, carrier: str, checks: kit.Checks,
                       ) -> tuple[float, ...] | None:
    """The gear's centre as a point of the carrier: where a revolute pins the gear to the
    carrier, or to a third body at the very point where the carrier is pinned to it too (a
    sun and an arm on one ground pivot). None when nothing holds it there."""
    direct = checks.pins(carrier, gear)
    if direct:
        return direct[0][0]
    for other in (GROUND, *checks.body_names()):
        for on_other, _ in checks.pins(other, gear):
            for shared, on_carrier in checks.pins(other, carrier):
                if math.dist(on_other, shared) <= MESH_TOLERANCE * (1 + math.hypot(*shared)):
                    return on_carrier
    return None


def _check_carrier(c: Gear, checks: kit.Checks, path: kit.Path, radii: list[float]) -> None:
    """Both gears pinned to the carrier, their pivots there as far apart as the radii say."""
    pivots = []
    for key, gear in (("i", c.i), ("j", c.j)):
        pivot = _centre_on_carrier(gear, c.carrier, checks)
        if pivot is None:
            raise MechanismError(
                f"the gear {gear!r} is not pinned to the carrier {c.carrier!r} by a revolute "
                "joint: nothing holds its centre at the meshing distance, so the rolling "
                "equation would turn gears that do not touch", path + (key,),
                f"Add a revolute joint between {c.carrier!r} and {gear!r} at the gear's "
                "centre, or name as carrier the body that holds both gears' centres.")
        pivots.append(pivot)
    distance = math.dist(pivots[0][:2], pivots[1][:2])
    expected = radii[1] - radii[0] if c.internal else radii[0] + radii[1]
    if abs(distance - expected) > MESH_TOLERANCE * max(expected, distance):
        rule = "r_j - r_i" if c.internal else "r_i + r_j"
        raise MechanismError(
            f"the gears' pivots on the carrier {c.carrier!r} are {distance:.6g} apart, not "
            f"{rule} = {expected:.6g}: the pitch circles would not touch", path + ("radii",),
            f"Make the pitch radii fit the centre distance ({rule}), or move the revolute "
            "joints that hold the gears on the carrier.")


def marks(c: Gear, geometry: kit.Geometry) -> list[kit.Mark]:
    """Each gear's pitch circle about its frame origin, with a radius that turns with it."""
    s, found = kit.S_MARK, []
    for body, raw in zip((c.i, c.j), c.radii):
        r = geometry.expr(raw)
        found.append((body, "pitch circle", sp.Matrix([r * sp.cos(s), r * sp.sin(s)]),
                      (sp.Integer(0), 2 * sp.pi)))
        found.append((body, "pitch circle", sp.Matrix([s, 0]), (sp.Integer(0), r)))
    return found


def pitch(c: Gear, geometry: kit.Geometry) -> tuple[str, str, sp.Expr, sp.Expr]:
    """Where the pitch circles touch: r_i from i's centre towards j's (away from a ring's)."""
    ri, rj = (geometry.expr(raw) for raw in c.radii)
    return c.i, c.j, ri, -rj if c.internal else rj


TYPE = kit.PairType(
    name="gear", model=Gear, sections=("joints",), equations=equations, rows=("rolling",),
    bodies=("i", "j", "carrier"), constants=("offset",), check=check, marks=marks,
    pitch=pitch)
