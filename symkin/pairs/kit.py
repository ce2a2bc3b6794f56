"""What a pair or driver type is: the :class:`PairType` each module of :mod:`symkin.pairs`
fills in, and the three views of the pipeline it is handed.

A pair module holds everything about one type: its file keys in both layouts (pydantic models),
which of its keys name bodies, points, directions, constants and functions of time (so that the
stages validate, convert and draw it without knowing it), its drawn-layout derivation where the
generic one does not fit, and its equations, the rows of Phi in the chapter's vector form. It
sees the stages only through the protocols below, which the stages implement:

- :class:`Geometry` (the symbolic stage, :mod:`symkin.symbolic.planar`): body poses as SymPy
  symbols, the resolved local vectors and parsed expressions, to write the equations with;
- :class:`Checks` (validation, :mod:`symkin.spec.validate`): parses a field and says what is
  wrong with it, located;
- :class:`Drawing` (the drawn layout, :mod:`symkin.spec.drawn`): the joint's points as drawn.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import sympy as sp
from pydantic import BaseModel

from symkin.pairs.fields import GROUND, PointRef, Strict

Path = tuple[str | int, ...]


class Pose(Protocol):
    """A body's position r, angle phi and rotation matrix R (SymPy)."""

    @property
    def r(self) -> sp.Matrix: ...

    @property
    def phi(self) -> sp.Expr: ...

    @property
    def R(self) -> sp.Matrix: ...

    def point(self, s: sp.Matrix) -> sp.Matrix: ...


class Geometry(Protocol):
    """What the symbolic stage gives an equation writer."""

    def pose(self, body: str) -> Pose: ...
    def initial_pose(self, body: str) -> Pose: ...
    def local(self, body: str, ref: Any) -> sp.Matrix: ...
    def expr(self, raw: Any) -> sp.Expr: ...
    def vector(self, raw: list[Any]) -> sp.Matrix: ...
    def time_function(self, raw: Any) -> sp.Expr: ...
    def equation(self, text: str) -> sp.Expr: ...
    def coordinate(self, name: str) -> sp.Symbol: ...
    def sign_at_nominal(self, expr: sp.Expr) -> int: ...
    def rate(self, expr: sp.Expr) -> sp.Expr: ...
    def curve(self, raw: Any, s: sp.Symbol) -> sp.Expr: ...


class Checks(Protocol):
    """What validation gives a pair's own checks; every method raises a located
    :class:`~symkin.errors.MechanismError` for a mistake."""

    def expression(self, raw: Any, path: Path, *, time: bool = False,
                   coordinates: bool = False) -> sp.Expr: ...
    def uses_coordinates(self, expr: sp.Expr) -> bool: ...
    def over_time(self, expr: sp.Expr, count: int = 201) -> list[tuple[float, float]]: ...
    def value(self, expr: sp.Expr, path: Path) -> float: ...
    def point_at_q0(self, body: str, ref: Any) -> tuple[float, ...]: ...
    def curve(self, raw: Any, path: Path, order: int = 2) -> sp.Expr: ...
    def curve_value(self, expr: sp.Expr, s: float, path: Path) -> float: ...
    def body_names(self) -> tuple[str, ...]: ...
    def point(self, body: str, ref: Any, path: Path) -> None: ...
    def at_nominal(self, expr: sp.Expr) -> sp.Expr: ...
    def pins(self, a: str, b: str) -> list[tuple[tuple[float, ...], tuple[float, ...]]]: ...


class Drawing(Protocol):
    """What the drawn layout gives a joint written with ``at:`` (or a global sA and sB)."""

    def joined(self, data: Mapping[str, Any], path: Path,
               keys: frozenset[str] = frozenset()) -> Joined: ...
    def slide_normal(self, joined: Joined, data: Mapping[str, Any],
                     path: Path) -> tuple[list[Any], float]: ...
    def relative_angle(self, i: str, j: str) -> Any: ...
    def body(self, constraint: Mapping[str, Any], key: str, path: Path) -> str: ...
    def point(self, body: str, raw: Any, path: Path) -> tuple[Any, Any]: ...
    def direction(self, body: str, raw: Any, path: Path) -> list[Any]: ...
    def curve(self, body: str, raw: Any, path: Path) -> tuple[list[str], Callable[[float],
                                                                 tuple[float, float]]]: ...
    def polar(self, body: str, rho: Any, path: Path) -> Any: ...
    def value(self, raw: Any, path: Path) -> float: ...


@dataclass(frozen=True)
class Joined:
    """A drawn joint's two bodies and points: ``local`` holds type, name, i, j, sA and sB in
    the local form; ``A`` and ``B`` are the global points as drawn (nominal values); ``gap``
    is |B - A|."""

    local: dict[str, Any]
    i: str
    j: str
    A: tuple[float, float]
    B: tuple[float, float]

    @property
    def gap(self) -> float:
        return math.hypot(self.B[0] - self.A[0], self.B[1] - self.A[1])


# A drawn mark: (body, label, [x(s), y(s)] in the body's frame, (s from, s to)).
Mark = tuple[str, str, sp.Matrix, tuple[sp.Expr, sp.Expr]]
S_MARK = sp.Symbol("s", real=True)  # the variable of a mark's curve

# A drawn joint's local form and its closure residual (how far its drawing is from closing).
DrawnResult = tuple[dict[str, Any], float | None]


@dataclass(frozen=True)
class PairType:
    """One pair or driver type, as every stage sees it.

    Attributes:
        name: the ``type:`` of the file.
        model: the pydantic model of its keys in the local layout.
        sections: ``"joints"``, ``"drivers"`` or both, where the file may list it.
        equations: its rows of Phi, given the constraint and a :class:`Geometry`.
        rows: what each row is called (``x``, ``y``, ``angle``...); None when the file gives
            the equations (then they are ``equation 0``, ``equation 1``...).
        bodies: the keys naming the bodies it joins, i then j.
        on_ground: it joins its one body to the ground (a trajectory).
        points: (point key, body key): a point of that body, by name or local vector.
        directions: (vector key, body key): a direction fixed in that body; never zero.
        constants: keys holding constant expressions of the parameters.
        time_functions: keys holding functions of t (one, or a list of components).
        lengths: those of them that are a length, never negative (its equation holds the
            square, so a negative value would be solved as its absolute value): checked over
            the file's grid, and in an --inputs table where one is written ``input``.
        check: its own rules beyond the generic ones (given a :class:`Checks` and its path).
        drawn_model: its keys in the drawn layout (None: as in the local layout).
        to_local: its drawn-layout derivation (None: points and directions are converted to
            the local form one by one, with no closure to check).
        pivot: drawn as a pivot of the ground when it joins a body to the ground at a point.
        slide: the key of a slide's normal (the slide is drawn on body j along the normal
            turned by -90 degrees).
        rod: drawn as a line from its first point to its second (a rod with no body).
        outputs: what it reports along a motion beyond the coordinates (a cam's pressure
            angle and radius of curvature), as {key: (expression of q, dq, t and the
            parameters, guard)}: reported as ``NAME.key``, NaN where the guard (an expression
            too, or None) is below 1e-9 of its largest value over the run (undefined there).
        marks: what the drawing shows of it beyond points and slides, as (body, label,
            curve [x(s), y(s)] in that body's frame, (s from, s to)): pitch circles and their
            turning mark, a rack's line, a curve or a cam profile.
        coordinate: the key of the first guess of the coordinate ``NAME.s`` the pair adds
            (a contact or curve parameter, solved like the bodies' coordinates); None: the
            pair adds no coordinate.
        coordinate_range: the key of that coordinate's range [a, b] (optional in the file):
            the motion stops, naming the pair, where ``NAME.s`` leaves it.
        senses: what its rows leave ambiguous, as expressions of q, t and the parameters
            that are positive at the configurations it means and negative at the others its
            rows also allow (a spatial revolute's axes anti-parallel, an angle driver half a
            turn away): the runtime counts no assembly where one is not positive.
        pitch: a meshing's pitch point, drawn where the pitch circles touch: (body i, body
            j, r_i, r_j), r_j negative for a ring (internal) gear j; the point lies on the
            line of the two frame origins (the pitch circles' centres), r_i from i's.
    """

    name: str
    model: type[BaseModel]
    sections: tuple[str, ...]
    # given the Geometry of the type's family: Geometry here (planar), or
    # pairs.spatial.basic.Geometry (spatial)
    equations: Callable[[Any, Any], list[sp.Expr]]
    rows: tuple[str, ...] | None
    bodies: tuple[str, ...] = ("i", "j")
    on_ground: bool = False
    points: tuple[tuple[str, str], ...] = ()
    directions: tuple[tuple[str, str], ...] = ()
    constants: tuple[str, ...] = ()
    time_functions: tuple[str, ...] = ()
    lengths: tuple[str, ...] = ()
    check: Callable[[Any, Checks, Path], None] | None = None
    drawn_model: type[BaseModel] | None = None
    # given the family's drawing: Drawing here, or pairs.spatial.basic.Drawing
    to_local: Callable[[Mapping[str, Any], Any, Path], DrawnResult] | None = None
    pivot: bool = False
    slide: str | None = None
    rod: bool = False
    coordinate: str | None = None
    outputs: Callable[[Any, Geometry], dict[str, tuple[sp.Expr, sp.Expr | None]]] | None = None
    marks: Callable[[Any, Geometry], list[Mark]] | None = None
    coordinate_range: str | None = None
    pitch: Callable[[Any, Geometry], tuple[str, str, sp.Expr, sp.Expr]] | None = None
    senses: Callable[[Any, Any], list[sp.Expr]] | None = None

    def extra_coordinates(self, constraint: Any) -> tuple[tuple[str, Any], ...]:
        """The coordinates ``constraint`` adds, as (name, first guess): ``NAME.s``."""
        if self.coordinate is None:
            return ()
        return ((f"{constraint.name}.s", getattr(constraint, self.coordinate)),)

    def range_of(self, constraint: Any) -> list[Any] | None:
        """The range [a, b] the file gives ``NAME.s`` (raw expressions), or None."""
        return None if self.coordinate_range is None else getattr(constraint,
                                                                  self.coordinate_range)

    def equation_count(self, constraint: Any) -> int:
        """How many rows of Phi ``constraint`` owns."""
        return len(self.rows) if self.rows is not None else len(constraint.equations)

    def joined_bodies(self, constraint: Any) -> tuple[str, ...]:
        """The bodies ``constraint`` joins, ground included, i before j."""
        found = tuple(getattr(constraint, key) for key in self.bodies)
        return (GROUND, *found) if self.on_ground else found

    @property
    def drawn_keys(self) -> frozenset[str]:
        """The keys the drawn layout allows."""
        return frozenset((self.drawn_model or self.model).model_fields)


# ----- the shared shapes and geometry of two-body pairs ------------------------------------

class Pair(Strict):
    """Point A (sA) on body i, point B (sB) on body j; a name or a local vector."""

    name: str | None = None
    i: str
    j: str
    sA: PointRef
    sB: PointRef


class DrawnPair(Strict):
    """One point ``at`` shared by bodies i and j, or a global sA (on i) and sB (on j)."""

    name: str | None = None
    i: str
    j: str
    at: PointRef | None = None
    sA: PointRef | None = None
    sB: PointRef | None = None


def relative(c: Any, geometry: Geometry) -> tuple[Pose, Pose, sp.Matrix, sp.Matrix]:
    """The poses of bodies i and j and the local vectors sA and sB of a two-body pair."""
    return (geometry.pose(c.i), geometry.pose(c.j), geometry.local(c.i, c.sA),
            geometry.local(c.j, c.sB))


def perpendicular(bi: Pose, bj: Pose, sA: sp.Matrix, sB: sp.Matrix, v: sp.Matrix) -> sp.Expr:
    """(R_j v)^T (r_j + R_j s_B - r_i - R_i s_A)  (2.22)."""
    return ((bj.R * v).T * (bj.point(sB) - bi.point(sA)))[0]


def contact_outputs(point: sp.Matrix) -> dict[str, tuple[sp.Expr, sp.Expr | None]]:
    """A contact point in the global frame as the outputs ``contact_x``, ``contact_y``."""
    return {"contact_x": (point[0], None), "contact_y": (point[1], None)}


def components(raw: list[Any], geometry: Geometry) -> sp.Matrix:
    """A vector of functions of time, f(t) = [f_x(t), f_y(t)]."""
    return sp.Matrix([geometry.time_function(item) for item in raw])
