"""Facts about a derived System that the lowering hands on as plain data: which coordinates
enter Phi_q (the error model's), where Phi_p and M are non-zero, the named points and their
local vectors, and each routine's expressions."""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from symkin.symbolic.derivation import System


def nonlinear_coordinates(system: System) -> tuple[int, ...]:
    """The indices of the coordinates Phi_q or Phi_t depends on."""
    entered = system.phi_q.free_symbols | system.phi_t.free_symbols
    return tuple(k for k, symbol in enumerate(system.q) if symbol in entered)


def parameter_pattern(system: System) -> list[tuple[int, int]]:
    """Structural non-zeros of Phi_p as (row, parameter), row-major."""
    return [] if system.phi_p is None else sorted((int(r), int(c))  # ints, as in System.pattern
                                                  for r, c in system.phi_p.todok())


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


def routine_expressions(system: System, pattern: Sequence[tuple[int, int]],
                        p_pattern: Sequence[tuple[int, int]],
                        m_pattern: Sequence[tuple[int, int]]) -> dict[str, list[sp.Expr]]:
    """Each routine's expressions by name (Phi_q, Phi_p and M as their patterns' non-zeros);
    the optional routines only where the System has what they need."""
    dynamics = system.dynamics
    return {
        "phi": list(system.phi),
        "phi_q": [system.phi_q[r, c] for r, c in pattern],
        "phi_t": list(system.phi_t),
        "gamma": list(system.gamma),
        "points": [component for vector in point_vectors(system) for component in vector],
        "phi_p": [] if system.phi_p is None else [system.phi_p[r, k] for r, k in p_pattern],
        # Only where rows were removed: every other file's generated code stays as it was.
        **({"removed": [removed.phi for removed in system.removed]} if system.removed else {}),
        **({"senses": [expr for _, expr in system.senses]} if system.senses else {}),
        **({"dynamics_rhs": list(system.dynamics.rhs), "loads": list(system.dynamics.loads)}
           if system.dynamics is not None else {}),
        **({"removed_q": list(system.dynamics.removed_q),
            "loads_full": list(system.dynamics.loads_full)}
           if system.dynamics is not None and system.dynamics.removed_q is not None
           and system.dynamics.loads_full is not None else {}),
        # Only with masses: a file with forces alone has no equations of motion to integrate.
        **({"mass": [dynamics.mass_matrix[r, c] for r, c in m_pattern],
            "applied": list(dynamics.applied - dynamics.velocity_terms)}
           if dynamics is not None and m_pattern else {}),
    }
