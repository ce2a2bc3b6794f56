"""Cam and follower: a closed profile c(s) of the cam i touched by the follower j, either a
roller of radius rr centred at a point R of j, or a flat face through a point F of j with a
normal m fixed in j. The contact parameter s is a coordinate of its own, ``NAME.s`` (first
guess ``s0``). With t = c'(s) and the outward unit normal n(s) = sigma [t_y, -t_x] / |t|:

    roller:  r_j + R_j s_R - r_i - R_i (c(s) + rr n(s)) = 0         (2 rows: x, y)
    flat:    m^T R_j^T (r_i + R_i c(s) - r_j - R_j s_F) / |m| = 0   (the face through c(s))
             m^T R_j^T R_i t(s) / |m| = 0                           (tangent to it there)

For a closed profile (no ``range``, or one whose ends meet) sigma = +1 when the profile runs
counter-clockwise about the cam's frame origin at s0 (c x t > 0), -1 otherwise, so a roller
lies outside the profile whatever its orientation (a disk cam turns about its frame origin,
which lies inside its profile). For an open one (a ``range: [a, b]`` whose ends differ: a
wedge, a plate cam's flank) sigma puts the normal on the side of the follower's point at q0
(as drawn, in the drawn layout). A profile is [x(s), y(s)] or {polar: rho(s)},
x = rho cos s, y = rho sin s. A flat face touches at the tangent point nearest s0.

Checked over the profile's own parameter range (``range``; else one turn of s from s0, 2 pi,
the period of a closed profile): a cusp (t = 0), a roller larger than the radius of
curvature of a part hollow on the follower's side (undercutting: the roller cannot follow
the profile there), a flat face on such a part (it would bridge the hollow and lose contact)
are refused with the value of s where they occur.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal

import numpy as np
import sympy as sp

from symkin.errors import MechanismError
from symkin.pairs import kit
from symkin.pairs.fields import Expr, PointRef, Strict, Vec2
from symkin.pairs.planar.point_on_curve import check_range

SAMPLES = 2048  # points of s checked over the profile's range (or one turn)
OPEN_GAP = 1e-9  # relative: a range whose ends are farther apart than this is open


class Polar(Strict):
    """rho(s): the profile's radius at the polar angle s, in the cam's frame."""

    polar: Expr


class Roller(Strict):
    """A roller of radius ``roller`` centred at ``at`` (a point of j)."""

    roller: Expr
    at: PointRef = (0, 0)  # the frame origin of its body


class Flat(Strict):
    """A flat face through ``at`` (a point of j) with ``normal`` fixed in j."""

    flat: Literal[True]
    at: PointRef = (0, 0)  # the frame origin of its body
    normal: Vec2


class Cam(Strict):
    """Cam i with ``profile``, follower j (a roller or a flat face); s starts at ``s0``."""

    type: Literal["cam"]
    name: str | None = None
    i: str
    j: str
    profile: Vec2 | Polar
    follower: Roller | Flat
    s0: Expr = 0
    range: Vec2 | None = None  # where the profile is meant to be followed: [a, b] of s


def profile_texts(profile: list[Any] | Polar) -> list[Any]:
    """[x(s), y(s)] as written, or from rho(s)."""
    if isinstance(profile, Polar):
        rho = f"({profile.polar})"
        return [f"{rho}*cos(s)", f"{rho}*sin(s)"]
    return list(profile)


def _profile(c: Cam, s: sp.Symbol, geometry: kit.Geometry) -> sp.Matrix:
    return sp.Matrix([geometry.curve(item, s) for item in profile_texts(c.profile)])


def outward_normal(c: Cam, curve: sp.Matrix, s: sp.Symbol, geometry: kit.Geometry
                   ) -> sp.Matrix:
    """sigma [t_y, -t_x] / |t| (sigma: :func:`follower_side`)."""
    t = curve.diff(s)
    return follower_side(c, curve, s, geometry) * sp.Matrix([t[1], -t[0]]) / sp.sqrt((t.T * t)[0])


def follower_side(c: Cam, curve: sp.Matrix, s: sp.Symbol, geometry: kit.Geometry) -> int:
    """sigma, at the nominal parameter values: an open profile's follower side at q0, else
    (or when q0 puts the follower's point on the profile) the turning sense about the cam's
    frame origin at s0."""
    s0 = geometry.expr(c.s0)
    t = curve.diff(s).subs(s, s0)
    if c.range is not None:
        a, b = (curve.subs(s, geometry.expr(end)) for end in c.range)
        gap, size = a - b, 1 + (a.T * a)[0]
        if geometry.sign_at_nominal((gap.T * gap)[0] - OPEN_GAP**2 * size) > 0:
            cam, follower = geometry.initial_pose(c.i), geometry.initial_pose(c.j)
            away = follower.point(geometry.local(c.j, c.follower.at)) - cam.point(
                curve.subs(s, s0))
            side = geometry.sign_at_nominal((away.T * cam.R * sp.Matrix([t[1], -t[0]]))[0])
            if side:
                return side
    return geometry.sign_at_nominal(curve[0].subs(s, s0) * t[1] - curve[1].subs(s, s0) * t[0])


def equations(c: Cam, geometry: kit.Geometry) -> list[sp.Expr]:
    """The roller's centre on the offset profile, or the face tangent to the profile."""
    s = geometry.coordinate(f"{c.name}.s")
    curve = _profile(c, s, geometry)
    cam, follower = geometry.pose(c.i), geometry.pose(c.j)
    at = follower.point(geometry.local(c.j, c.follower.at))
    if isinstance(c.follower, Roller):
        normal = outward_normal(c, curve, s, geometry)
        centre = cam.point(curve + geometry.expr(c.follower.roller) * normal)
        return list(at - centre)
    m = geometry.vector(c.follower.normal)
    face = follower.R * m / sp.sqrt((m.T * m)[0])
    return [(face.T * (cam.point(curve) - at))[0], (face.T * cam.R * curve.diff(s))[0]]


def outputs(c: Cam, geometry: kit.Geometry) -> dict[str, tuple[sp.Expr, sp.Expr | None]]:
    """What a cam designer checks along the motion, at the contact s:

    - ``pressure_angle``: the angle (radians, 0 to pi/2) between the contact normal and the
      velocity of the follower's point (the roller's centre, or the face's point F);
      undefined (NaN) where that point is at rest (a dwell), which has no direction;
    - ``curvature_radius``: the profile's signed radius of curvature, positive where the
      profile is convex, negative where it is hollow (a roller needs a radius smaller than
      the hollow's): sigma |c'|^3 / (c' x c'') for a roller; for a flat face
      (c' . tau)^3 / (c' x c''), tau the face's unit direction in the cam's frame, which is
      p + p'' of the face's support function p (r_b + L + L'' for a lift law L): its sign
      follows c' through a cusp, where |c'|^3 would stay positive;
    - ``contact_x``, ``contact_y``: the contact point c(s) in the global frame (marked in the
      pictures)."""
    s = geometry.coordinate(f"{c.name}.s")
    curve = _profile(c, s, geometry)
    cam, follower = geometry.pose(c.i), geometry.pose(c.j)
    t, t2 = curve.diff(s), curve.diff(s, 2)
    sense = follower_side(c, curve, s, geometry)
    if isinstance(c.follower, Roller):
        normal = cam.R * sp.Matrix([t[1], -t[0]])
    else:
        normal = follower.R * geometry.vector(c.follower.normal)
    velocity = geometry.rate(follower.point(geometry.local(c.j, c.follower.at)))
    across = normal[0] * velocity[1] - normal[1] * velocity[0]
    along = (normal.T * velocity)[0]
    # Unevaluated: SymPy's Abs and atan2 would expand the long profile's terms to look for
    # signs and factors (10 of 13 s of the cam example's outputs), for a function evaluated
    # numerically anyway.
    angle = sp.atan2(sp.Abs(across, evaluate=False), sp.Abs(along, evaluate=False),
                     evaluate=False)
    return {"pressure_angle": (angle, sp.sqrt((velocity.T * velocity)[0])),
            "curvature_radius": (_radius(c, t, t2, sense, geometry), None),
            **kit.contact_outputs(cam.point(curve))}


def _radius(c: Cam, t: sp.Matrix, t2: sp.Matrix, sense: int, geometry: kit.Geometry
            ) -> sp.Expr:
    """The signed radius of curvature at the contact (t, t2: c'(s) and c''(s))."""
    cross = t[0] * t2[1] - t[1] * t2[0]
    if isinstance(c.follower, Roller):
        return sense * sp.sqrt((t.T * t)[0]) ** 3 / cross
    # The tangency row keeps c' along the face, so c' . tau = +-|c'|; unlike |c'| it changes
    # sign where the envelope of the face turns back (p + p'' < 0), so the radius does too.
    # tau is oriented so that the profile at s0 as drawn is convex (the checks refuse a flat
    # face on a hollow).
    m = geometry.vector(c.follower.normal)
    s = geometry.coordinate(f"{c.name}.s")

    def along(cam: kit.Pose, follower: kit.Pose) -> sp.Expr:
        face = cam.R.T * follower.R * m / sp.sqrt((m.T * m)[0])
        return t[0] * -face[1] + t[1] * face[0]

    drawn = along(geometry.initial_pose(c.i), geometry.initial_pose(c.j))
    orient = geometry.sign_at_nominal(drawn.subs(s, geometry.expr(c.s0))) or 1
    return orient * along(geometry.pose(c.i), geometry.pose(c.j)) ** 3 / cross


def check(c: Cam, checks: kit.Checks, path: kit.Path) -> None:
    """The follower's point and sizes; the profile smooth, and followable over one turn."""
    s0 = checks.value(checks.expression(c.s0, path + ("s0",)), path + ("s0",))
    check_range(c.range, s0, checks, path)
    checks.point(c.j, c.follower.at, path + ("follower", "at"))
    key = ("profile", "polar") if isinstance(c.profile, Polar) else ("profile",)
    texts = profile_texts(c.profile)
    located = [path + key if isinstance(c.profile, Polar) else path + ("profile", k)
               for k in range(2)]
    # Gamma differentiates the rows (which hold c'(s)) twice: c''' must print
    exprs = [checks.curve(text, where, order=3) for text, where in zip(texts, located)]
    for expr, where in zip(exprs, located):
        checks.curve_value(expr, s0, where)
    if isinstance(c.follower, Roller):
        where = path + ("follower", "roller")
        size = checks.value(checks.expression(c.follower.roller, where), where)
        if not size > 0:
            raise MechanismError(f"the roller's radius {size:g} is not positive", where,
                                 "Give the roller's radius, > 0 (or a flat face).")
    else:
        where = path + ("follower", "normal")
        normal = [checks.value(checks.expression(raw, where + (k,)), where + (k,))
                  for k, raw in enumerate(c.follower.normal)]
        if not any(normal):
            raise MechanismError("the face's normal is zero", where, "Give a non-zero "
                                 "vector, e.g. [0, 1].")
        size = 0.0
    _check_followable(c, exprs, checks, s0, size, path + key)


def _samples(c: Cam, checks: kit.Checks, s0: float, path: kit.Path) -> np.ndarray:
    """The values of s checked: the profile's range, else one turn from s0."""
    if c.range is None:
        return s0 + np.linspace(0.0, 2 * math.pi, SAMPLES, endpoint=False)
    low, high = (checks.value(checks.expression(raw, path + ("range", k)),
                              path + ("range", k)) for k, raw in enumerate(c.range))
    return np.linspace(low, high, SAMPLES)


def _side(c: Cam, exprs: list[sp.Expr], checks: kit.Checks, s0: float,
          grid: np.ndarray) -> float:
    """:func:`follower_side` in numbers (nominal values, q0)."""
    s = sp.Symbol("s", real=True)
    at = [sp.lambdify(s, checks.at_nominal(e), "math") for e in exprs]
    slope = [sp.lambdify(s, sp.diff(checks.at_nominal(e), s), "math") for e in exprs]
    (x0, y0), (x1, y1) = ([float(f(s0)) for f in fs] for fs in (at, slope))
    if c.range is not None:
        ends = [np.array([float(f(end)) for f in at]) for end in (grid[0], grid[-1])]
        if np.linalg.norm(ends[0] - ends[1]) > OPEN_GAP * math.sqrt(1 + ends[0] @ ends[0]):
            contact = np.array(checks.point_at_q0(c.i, [x0, y0]))
            normal = np.array(checks.point_at_q0(c.i, [x0 + y1, y0 - x1])) - contact
            away = np.array(checks.point_at_q0(c.j, c.follower.at)) - contact
            if away @ normal:
                return 1.0 if away @ normal > 0 else -1.0
    return 1.0 if x0 * y1 - y0 * x1 > 0 else -1.0


def _curvature_along(exprs: list[sp.Expr], checks: kit.Checks, grid: np.ndarray,
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """s over the grid, |c'(s)|, the signed curvature and c'(s) itself, one row a sample
    (nominal values)."""
    s = sp.Symbol("s", real=True)
    values = [checks.at_nominal(expr) for expr in exprs]
    derivatives = [sp.diff(v, s, k) for k in (1, 2) for v in values]
    with np.errstate(all="ignore"):
        x1, y1, x2, y2 = (np.broadcast_to(np.asarray(sp.lambdify(s, e, "numpy")(grid),
                                                     dtype=float), grid.shape)
                          for e in derivatives)
        speed = np.hypot(x1, y1)
        curvature = (x1 * y2 - y1 * x2) / speed**3
    return grid, speed, curvature, np.column_stack([x1, y1])


def _cusp(grid: np.ndarray, speed: np.ndarray, tangent: np.ndarray, finite: np.ndarray
          ) -> float | None:
    """Where the profile has a cusp: c'(s) zero at a sample, or c'(s) reversed between two
    neighbouring samples (a simple cusp's c' passes through zero between them and changes
    sign, which no sample sees as small; a smooth profile sampled this finely turns far
    less than a right angle from one sample to the next). None where it has none."""
    scale = float(np.max(speed[finite])) if finite.any() else 1.0
    zero = finite & (speed <= 1e-9 * scale)
    if zero.any():
        return float(grid[zero][0])
    reversed_ = (finite[:-1] & finite[1:]
                 & (np.einsum("ij,ij->i", tangent[:-1], tangent[1:]) < 0))
    if reversed_.any():
        k = int(np.flatnonzero(reversed_)[0])
        return float(0.5 * (grid[k] + grid[k + 1]))
    return None


def _check_followable(c: Cam, exprs: list[sp.Expr], checks: kit.Checks, s0: float,
                      roller: float, path: kit.Path) -> None:
    """No cusp; no concave part tighter than the roller; no concave part under a face."""
    grid, speed, curvature, tangent = _curvature_along(exprs, checks,
                                                       _samples(c, checks, s0, path))
    finite = np.isfinite(speed) & np.isfinite(curvature)
    at = _cusp(grid, speed, tangent, finite)
    if at is not None:
        raise MechanismError(f"the profile has a cusp (c'(s) = 0) at s = {at:.6g}", path,
                             "Smooth the profile there: a follower cannot keep a defined "
                             "contact at a cusp. A flat-faced follower's profile drawn from "
                             "a lift law L(s) needs r_b + L + L'' > 0 all round.")
    sense = _side(c, exprs, checks, s0, grid)
    # with the normal on the follower's side, a part convex towards it has sense * curvature > 0
    concave = finite & (sense * curvature < 0)
    if not concave.any():
        return
    if isinstance(c.follower, Flat):
        where = grid[concave][0]
        raise MechanismError(f"the profile is concave at s = {where:.6g} (radius of "
                             f"curvature {1 / abs(curvature[concave][0]):.6g}): a flat face "
                             "would bridge the hollow and lose contact there", path,
                             "A flat-faced follower needs a convex profile; use a roller "
                             "smaller than the hollow's radius of curvature.")
    tightest = int(np.argmax(np.where(concave, np.abs(curvature), 0.0)))
    radius = 1 / abs(curvature[tightest])
    if roller >= radius:
        raise MechanismError(f"undercutting: the roller's radius {roller:g} is not smaller "
                             f"than the radius of curvature {radius:.6g} of the concave "
                             f"profile at s = {grid[tightest]:.6g}", path,
                             "A roller that large cannot reach the hollow (its centre's "
                             "path has a cusp there); use a smaller roller, or a gentler "
                             "profile.")


def to_local(data: Mapping[str, Any], drawing: kit.Drawing, path: kit.Path) -> kit.DrawnResult:
    """The profile (global, as drawn, carried by i) to i's frame; the follower's point to
    j's frame, its normal to j's axes; a roller's gap from the offset profile at s0 is left to
    the solver (the drawing is the first guess)."""
    local = dict(data)
    i, j = drawing.body(data, "i", path), drawing.body(data, "j", path)
    profile, follower = data.get("profile"), data.get("follower")
    if isinstance(profile, Mapping) and set(profile) == {"polar"}:
        local["profile"] = drawing.polar(i, profile["polar"], path + ("profile", "polar"))
    elif profile is not None:
        local["profile"], _ = drawing.curve(i, profile, path + ("profile",))
    if isinstance(follower, Mapping):
        converted = dict(follower)
        if "at" in follower:
            converted["at"], _ = drawing.point(j, follower["at"], path + ("follower", "at"))
        if "normal" in follower:
            converted["normal"] = drawing.direction(j, follower["normal"],
                                                    path + ("follower", "normal"))
        local["follower"] = converted
    return local, None


def marks(c: Cam, geometry: kit.Geometry) -> list[kit.Mark]:
    """The profile over its range, else one turn of s from s0."""
    s0 = geometry.expr(c.s0)
    span = ((s0, s0 + 2 * sp.pi) if c.range is None
            else tuple(geometry.expr(end) for end in c.range))
    return [(c.i, "cam profile", _profile(c, kit.S_MARK, geometry), span)]


TYPE = kit.PairType(
    name="cam", model=Cam, sections=("joints",), equations=equations,
    rows=("contact 1", "contact 2"), check=check, to_local=to_local, coordinate="s0",
    outputs=outputs, marks=marks, coordinate_range="range")
