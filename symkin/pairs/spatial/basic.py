"""The basic constraints every spatial joint is built from, each written once as rows of Phi
(Phi_q, Phi_t and Gamma are derived from them by SymPy, never typed in):

- :func:`perpendicular_vectors` (dot-1): a vector fixed in i stays perpendicular to one fixed
  in j, (A_i a)^T (A_j b) = 0;
- :func:`perpendicular_separation` (dot-2): a vector fixed in i stays perpendicular to the
  separation d = X_j - X_i of two points, (A_i a)^T d = 0;
- :func:`coincident` (spherical): the points coincide, d = 0 (three rows);
- :func:`distance`: |d| keeps a length, written (d^T d - L^2) / (2 L) so that its row of Phi_q
  has the size of a unit vector, like the others.

A spatial pair module sees the symbolic stage through :class:`Geometry`, the spatial form of
:class:`symkin.pairs.kit.Geometry`: a body's pose is its position r and rotation matrix A(e)
from its Euler parameters; local vectors are 3-vectors.
"""

from __future__ import annotations

from typing import Any, Protocol

import sympy as sp


class Pose(Protocol):
    """A body's position r and rotation matrix A (SymPy)."""

    @property
    def r(self) -> sp.Matrix: ...

    @property
    def A(self) -> sp.Matrix: ...

    def point(self, s: sp.Matrix) -> sp.Matrix: ...


class Geometry(Protocol):
    """What the spatial symbolic stage gives an equation writer."""

    def pose(self, body: str) -> Pose: ...
    def initial_pose(self, body: str) -> Pose: ...
    def local(self, body: str, ref: Any) -> sp.Matrix: ...
    def expr(self, raw: Any) -> sp.Expr: ...
    def vector(self, raw: list[Any]) -> sp.Matrix: ...
    def time_function(self, raw: Any) -> sp.Expr: ...
    def equation(self, text: str) -> sp.Expr: ...
    def value(self, expr: sp.Expr) -> float: ...


def separation(c: Any, geometry: Geometry, a: str = "sA", b: str = "sB") -> sp.Matrix:
    """d = (r_j + A_j s_B) - (r_i + A_i s_A): from the joint's point on i to its point on j."""
    return (geometry.pose(c.j).point(geometry.local(c.j, getattr(c, b)))
            - geometry.pose(c.i).point(geometry.local(c.i, getattr(c, a))))


def coincident(c: Any, geometry: Geometry) -> list[sp.Expr]:
    """The spherical constraint: the joint's points on i and j coincide (three rows)."""
    return list(-separation(c, geometry))


def perpendicular_vectors(bi: Pose, a: sp.Matrix, bj: Pose, b: sp.Matrix) -> sp.Expr:
    """dot-1: (A_i a)^T (A_j b) = 0."""
    return ((bi.A * a).T * (bj.A * b))[0]


def perpendicular_separation(bi: Pose, a: sp.Matrix, d: sp.Matrix) -> sp.Expr:
    """dot-2: (A_i a)^T d = 0."""
    return ((bi.A * a).T * d)[0]


def distance(d: sp.Matrix, length: sp.Expr) -> sp.Expr:
    """(d^T d - L^2) / (2 L) = 0, which agrees with |d| - L to first order."""
    return ((d.T * d)[0] - length**2) / (2 * length)


def unit(v: sp.Matrix) -> sp.Matrix:
    """v / |v| (a direction given at any length)."""
    return v / sp.sqrt((v.T * v)[0])


def frame_of(axis: sp.Matrix, geometry: Geometry) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """A right-handed orthonormal triad (a, u, v) with a along ``axis``: u = a x e_k with e_k
    the coordinate axis least aligned with a at the nominal parameters (so u never vanishes),
    v = a x u. Expressions of the parameters; constant for the generated code."""
    a = unit(axis)
    values = [abs(geometry.value(component)) for component in a]
    k = values.index(min(values))
    u = unit(a.cross(sp.Matrix([int(m == k) for m in range(3)])))
    return a, u, a.cross(u)


class Drawing(Protocol):
    """What the spatial drawn layout gives a type's ``to_local`` (:mod:`symkin.spec.drawn3d`)."""

    def joined(self, data: Any, path: tuple[str | int, ...]) -> dict[str, Any]: ...
    def point(self, body: str, raw: Any, path: tuple[str | int, ...]) -> Any: ...
    def body(self, data: Any, key: str, path: tuple[str | int, ...]) -> str: ...
    def direction(self, raw: Any, path: tuple[str | int, ...]) -> list[Any]: ...
    def joint(self, name: Any, path: tuple[str | int, ...],
              kinds: tuple[str, ...]) -> dict[str, Any]: ...
