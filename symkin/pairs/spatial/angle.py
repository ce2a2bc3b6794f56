"""Angle driver in space: body j turns relative to body i by theta(t), right-handed about the
unit axis of a revolute or cylindrical joint, 0 as drawn.

With (a, u, v) the joint's orthonormal triad fixed in i (v = a x u) and w = u fixed in j (as
drawn), turning j by theta carries w to cos(theta) u + sin(theta) v, so one row

    (u_i^T w_j) sin(theta) - (v_i^T w_j) cos(theta) = 0

holds: with psi the actual turn it is sin(theta - psi), whose slope is -1 at the solution at
every theta, so it never locks, over any number of turns (its other root, psi = theta + pi,
is half a turn away: a Newton step from the previous time point does not reach it).
"""

from __future__ import annotations

from typing import Any, Literal

import sympy as sp

from symkin.pairs import kit
from symkin.pairs.fields import Strict, TimeFunction, Vec3
from symkin.pairs.spatial import basic, cylindrical, revolute

# The joints whose axis an angle driver may turn about.
TURNING = (revolute.TYPE.name, cylindrical.TYPE.name)


class Angle(Strict):
    """Local form: the joint's bodies and its axis (in i's frame and j's, equal as drawn)."""

    type: Literal["angle"]
    name: str | None = None
    i: str
    j: str
    axis: Vec3
    theta: TimeFunction


class DrawnAngle(Strict):
    type: Literal["angle"]
    name: str | None = None
    joint: str
    theta: TimeFunction


def equations(c: Angle, geometry: basic.Geometry) -> list[sp.Expr]:
    _, u, v = basic.frame_of(geometry.vector(c.axis), geometry)
    bi, bj = geometry.pose(c.i), geometry.pose(c.j)
    theta = geometry.time_function(c.theta)
    return [basic.perpendicular_vectors(bi, u, bj, u) * sp.sin(theta)
            - basic.perpendicular_vectors(bi, v, bj, u) * sp.cos(theta)]


def turned(c: Angle, geometry: basic.Geometry) -> list[sp.Expr]:
    """cos(theta - psi): +1 at the turn theta, -1 at the row's other root theta + pi."""
    _, u, v = basic.frame_of(geometry.vector(c.axis), geometry)
    bi, bj = geometry.pose(c.i), geometry.pose(c.j)
    theta = geometry.time_function(c.theta)
    return [basic.perpendicular_vectors(bi, u, bj, u) * sp.cos(theta)
            + basic.perpendicular_vectors(bi, v, bj, u) * sp.sin(theta)]


def to_local(data: Any, drawing: basic.Drawing, path: kit.Path) -> kit.DrawnResult:
    """The named joint's bodies and axis."""
    joint = drawing.joint(data.get("joint"), path + ("joint",), TURNING)
    local = {key: data[key] for key in ("type", "name", "theta") if key in data}
    local.update(i=joint["i"], j=joint["j"], axis=joint["axis"])
    return local, None


TYPE = kit.PairType(name="angle", model=Angle, drawn_model=DrawnAngle, sections=("drivers",),
                    equations=equations, rows=("angle",), directions=(("axis", "i"),),
                    time_functions=("theta",), to_local=to_local,
                    senses=turned)
