"""Forward dynamics: the equations of motion of a mechanism that its forces move.

Everything the motion needs is already derived by the System — M(q), Q(q, q̇, t) and
h(q, q̇) by symbolic.dynamics (planar) or symbolic.dynamics3d (space: 3d), Φ, Φ_q, Φ_t and
Γ by symbolic.derivation — and is reused here, not derived again:

    M q̈ + Φ_qᵀ λ = Q - h,     Φ_q q̈ = Γ.

What this module adds is the split of the applied forces that the energy balance needs: the
potential V(q) of gravity and of the springs' elastic parts (where g, k and length0 are
constants), and the rest, Q_nc = Q + ∂V/∂q (dampers, forces, torques, anything that depends
on t), whose power Q_ncᵀ q̇ plus the drivers' λᵀ Φ_t is the rate of the non-conservative
work W. With T = ½ q̇ᵀ M q̇, dT/dt = q̇ᵀ(M q̈ + h), so T + V - W stays constant along an
exact motion: the balance a user checks.

Interfaces (kept stable for the generated code's side):

- :class:`EquationsOfMotion` — SymPy matrices: ``mass_matrix`` (M), ``applied`` (Q - h),
  ``kinetic`` (T), ``potential`` (V), ``nonconservative`` (Q_nc), plus the initial
  velocities the file gives (:class:`Given`) and the integrator's tolerances.
- :func:`derive` (System -> EquationsOfMotion | None): None for a file whose drivers fix its
  motion.
- symbolic.motion_numeric.numeric (System -> Functions): NumPy callables of the same, for
  the runtime (runtime.dynamics) until the kernels carry M and Q - h themselves.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp

from symkin.errors import MechanismError
from symkin.spec import motion as motion_spec
from symkin.symbolic import dynamics
from symkin.symbolic.planar import Context
from symkin.symbolic.spatial import SpatialContext
from symkin.symbolic.symbols import make_symbols

OMEGA_AXES = {"omega_x": 0, "omega_y": 1, "omega_z": 2}


@dataclass(frozen=True)
class Given:
    """One initial velocity component the file gives.

    Attributes:
        name: as written (``crank.phi``, ``body.omega_z``).
        columns: the coordinates it involves: one for a rate, a body's four Euler
            parameters for a spatial angular velocity.
        axis: None for a coordinate's rate; 0, 1, 2 for the global ω_x, ω_y, ω_z = 2 E(p) ṗ.
        value: an expression of the parameters (the System's p): a run evaluates it with
            the parameters it uses.
    """

    name: str
    columns: tuple[int, ...]
    axis: int | None
    value: sp.Expr


@dataclass(frozen=True)
class EquationsOfMotion:
    """The equations of motion and the energies of one mechanism (module docstring)."""

    mass_matrix: sp.ImmutableMatrix
    applied: sp.ImmutableMatrix
    kinetic: sp.Expr
    potential: sp.Expr
    nonconservative: sp.ImmutableMatrix
    given: tuple[Given, ...]
    rtol: float
    atol: float


def moves_under_forces(system: Any) -> bool:
    """True when Φ has fewer rows than coordinates: the forces move the free freedoms
    (spec.motion.moves, which also decides the file's ``initial`` and ``integrator``)."""
    return motion_spec.moves(int(system.phi_q.shape[0]), len(system.q))


def derive(system: Any) -> EquationsOfMotion | None:
    """The equations of motion of ``system`` (a symbolic.derivation.System), or None when its
    drivers fix its motion."""
    if not moves_under_forces(system):
        return None
    mech = system.mechanism
    if system.inputs:
        raise MechanismError("a mechanism moved by its forces cannot have input drivers yet",
                             ("drivers",), "Drive it by functions of t, or remove the driver.")
    found = system.dynamics
    symbols = make_symbols(mech)
    ctx = (SpatialContext if mech.is_spatial else Context)(mech, symbols)
    potential = sum((_potential(mech, ctx, load) for load in mech.forces), sp.Integer(0))
    gradient = sp.Matrix([potential.diff(q) for q in system.q])
    integrator = mech.integrator or motion_spec.Integrator()
    return EquationsOfMotion(
        mass_matrix=found.mass_matrix,
        applied=sp.ImmutableMatrix(found.applied - found.velocity_terms),
        kinetic=found.kinetic, potential=potential,
        nonconservative=sp.ImmutableMatrix(found.applied + gradient),
        given=_given(system), rtol=integrator.rtol, atol=integrator.atol)


def _constant(expr: sp.Expr, ctx: Any) -> bool:
    """True when ``expr`` depends on the parameters only (no t, no coordinate)."""
    return bool(expr.free_symbols <= set(ctx.symbols.p))


def _potential(mech: Any, ctx: Any, load: Any) -> sp.Expr:
    """V of one load: -m g·r_c for constant gravity, ½ k (L - L0)² for a spring with
    constant k and L0; 0 for every other load (its power counts as work instead)."""
    if load.type == "gravity":
        g = sp.Matrix([dynamics.load_expr(ctx, raw) for raw in load.g])
        if not all(_constant(component, ctx) for component in g):
            return sp.Integer(0)
        total = sp.Integer(0)
        for body, spec in mech.bodies.items():
            if spec.mass is not None:
                com = (ctx.local(body, spec.com) if spec.com is not None
                       else sp.zeros(len(ctx.pose(body).r), 1))
                total -= ctx.expr(spec.mass) * (g.T * ctx.pose(body).point(com))[0, 0]
        return total
    if load.type != "spring":
        return sp.Integer(0)
    k, length0 = (dynamics.load_expr(ctx, raw) for raw in (load.k, load.length0))
    if not (_constant(k, ctx) and _constant(length0, ctx)):
        return sp.Integer(0)
    d = dynamics.spring_end(ctx, load.j, load.B) - dynamics.spring_end(ctx, load.i, load.A)
    return k * (sp.sqrt((d.T * d)[0, 0]) - length0) ** 2 / 2


def _given(system: Any) -> tuple[Given, ...]:
    """The file's initial velocities, each with the coordinates it involves."""
    mech = system.mechanism
    symbols = make_symbols(mech)
    values = motion_spec.velocity_expressions(mech, symbols.parameters)
    found = []
    for name, value in values.items():
        body, _, part = name.partition(".")
        if part in OMEGA_AXES:
            start = system.coordinates.index(f"{body}.e0")
            found.append(Given(name, tuple(range(start, start + 4)), OMEGA_AXES[part], value))
        else:
            found.append(Given(name, (system.coordinates.index(name),), None, value))
    return tuple(found)

