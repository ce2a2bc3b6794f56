"""Facts about a derived System that the lowering hands on as plain data: which coordinates
enter Phi_q (the error model's), where Phi_p is non-zero, the named points and their local
vectors."""

from __future__ import annotations

import sympy as sp

from symkin.symbolic.derivation import System


def nonlinear_coordinates(system: System) -> tuple[int, ...]:
    """The indices of the coordinates Phi_q or Phi_t depends on."""
    entered = system.phi_q.free_symbols | system.phi_t.free_symbols
    return tuple(k for k, symbol in enumerate(system.q) if symbol in entered)


def parameter_pattern(system: System) -> list[tuple[int, int]]:
    """Structural non-zeros of Phi_p as (row, parameter), row-major."""
    return [] if system.phi_p is None else sorted(system.phi_p.todok())


def point_names(system: System) -> tuple[tuple[str, str], ...]:
    """Every named point as (body, point), bodies and points in file order."""
    return tuple((body, name) for body, name, _ in system.points)


def point_vectors(system: System) -> list[tuple[sp.Expr, sp.Expr]]:
    """The local vector s of every named point, as expressions of the parameters."""
    return [tuple(vector) for _, _, vector in system.points]


def mass_pattern(system: System) -> list[tuple[int, int]]:
    """Structural non-zeros of the mass matrix M(q) as (row, column), row-major; empty when
    the file gives no body a mass or an inertia (then it has no forward dynamics)."""
    if system.dynamics is None:
        return []
    mass = system.dynamics.mass_matrix
    return [(r, c) for r in range(mass.rows) for c in range(mass.cols) if mass[r, c] != 0]
