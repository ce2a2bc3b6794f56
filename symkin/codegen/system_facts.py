"""Facts about a derived System that the lowering hands on as plain data: which coordinates
enter Phi_q (the error model's), where Phi_p is non-zero, the named points and their local
vectors; and whether the System can be generated at all (not yet one its forces move)."""

from __future__ import annotations

import sympy as sp

from symkin.errors import BuildError
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


def refuse_motion(system: System) -> None:
    """A BuildError for a mechanism its forces move (fewer rows of Φ than coordinates): its
    code is not generated yet (symkin.solve integrates it, runtime.dynamics)."""
    if system.phi_q.shape[0] < len(system.q):
        raise BuildError("the mechanism has fewer driving equations than freedoms: its "
                         "forces move it, and code generation for such a mechanism is not "
                         "available yet; integrate it with symkin run or symkin.solve")
