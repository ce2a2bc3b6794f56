"""Rack and pinion: the pinion i rolls without slipping on the rack j. The displacement of
the pinion's centre P (``at``, a point of i; i's frame origin by default) along the rack's
``axis`` (fixed in j) follows the pinion's turn relative to the rack:

    u^T (r_P - r_j) = -sigma radius (phi_i - phi_j) + offset,   u = R_j axis / |axis|

sigma = +1 when P lies on the left of the axis through j's frame origin (above a rack whose
axis is [1, 0]: turning counter-clockwise rolls it backwards), -1 on the right; the side is
read at q0 (the drawing, in the drawn layout). One row, a length. ``offset`` defaults to its
value at q0. The pair holds only the rolling: the centre distance is held by the joints the
file gives (the pinion's revolute and the rack's prismatic joint).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import sympy as sp

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import Expr, PointRef, Strict, Vec2

OMEGA = sp.Matrix([[0, -1], [1, 0]])


class Rack(Strict):
    """Pinion i (pitch ``radius``, centre ``at``) on rack j (pitch line along ``axis``)."""

    type: Literal["rack"]
    name: str | None = None
    i: str
    j: str
    radius: Expr
    axis: Vec2
    at: PointRef = (0, 0)  # the frame origin of its body
    offset: Expr | None = None


def _along_and_side(c: Rack, pose_of: Any, geometry: kit.Geometry) -> tuple[sp.Expr, sp.Expr]:
    """u^T (r_P - r_j) and n^T (r_P - r_j), n = Omega u (the left normal)."""
    pinion, rack = pose_of(c.i), pose_of(c.j)
    axis = geometry.vector(c.axis)
    u = rack.R * axis / sp.sqrt((axis.T * axis)[0])
    d = pinion.point(geometry.local(c.i, c.at)) - rack.r
    return (u.T * d)[0], ((OMEGA * u).T * d)[0]


def _rolling(c: Rack, pose_of: Any, geometry: kit.Geometry) -> sp.Expr:
    along, _ = _along_and_side(c, pose_of, geometry)
    _, side = _along_and_side(c, geometry.initial_pose, geometry)
    turn = pose_of(c.i).phi - pose_of(c.j).phi
    return along + geometry.sign_at_nominal(side) * geometry.expr(c.radius) * turn


def equations(c: Rack, geometry: kit.Geometry) -> list[sp.Expr]:
    """u^T (r_P - r_j) + sigma radius (phi_i - phi_j) - offset."""
    offset = (_rolling(c, geometry.initial_pose, geometry) if c.offset is None
              else geometry.expr(c.offset))
    return [_rolling(c, geometry.pose, geometry) - offset]


def check(c: Rack, checks: kit.Checks, path: kit.Path) -> None:
    """A positive radius; the pinion's centre off the rack's axis line at q0."""
    radius = checks.value(checks.expression(c.radius, path + ("radius",)), path + ("radius",))
    if not radius > 0:
        raise MechanismError(f"the pitch radius {radius:g} is not positive",
                             path + ("radius",), "Give the pinion's pitch radius, > 0.")
    px, py = checks.point_at_q0(c.i, c.at)
    ox, oy = checks.point_at_q0(c.j, [0, 0])
    # the axis turned into the global frame at q0: the point r_j + R_j axis, less r_j
    qx, qy = checks.point_at_q0(c.j, c.axis)
    gx, gy = qx - ox, qy - oy
    if gx * (py - oy) - gy * (px - ox) == 0:
        raise MechanismError("the pinion's centre lies on the rack's axis line at q0, so the "
                             "side it rolls on is unknown", path + ("at",),
                             "Place the rack's frame origin on its pitch line, a radius away "
                             "from the pinion's centre (or the pinion where it meshes).")


def to_local(data: Mapping[str, Any], drawing: kit.Drawing, path: kit.Path) -> kit.DrawnResult:
    """``at`` (a point of i, or global coordinates) to i's frame; ``axis`` to j's."""
    local = dict(data)
    i, j = drawing.body(data, "i", path), drawing.body(data, "j", path)
    if "at" in data:
        local["at"], _ = drawing.point(i, data["at"], path + ("at",))
    if "axis" in data:
        local["axis"] = drawing.direction(j, data["axis"], path + ("axis",))
    return local, None


def marks(c: Rack, geometry: kit.Geometry) -> list[kit.Mark]:
    """The rack's line along its axis through its frame origin (20 radii long)."""
    axis = geometry.vector(c.axis)
    u = axis / sp.sqrt((axis.T * axis)[0])
    reach = 10 * geometry.expr(c.radius)
    return [(c.j, "rack", kit.S_MARK * u, (-reach, reach))]


TYPE = kit.PairType(
    name="rack", model=Rack, sections=("joints",), equations=equations, rows=("rolling",),
    points=(("at", "i"),), directions=(("axis", "j"),), constants=("offset", "radius"),
    check=check, to_local=to_local, marks=marks)
