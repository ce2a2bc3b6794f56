"""Inverse dynamics of a spatial mechanism (``space: 3d``): bodies in x, y, z and Euler
parameters p = [e0, e1, e2, e3], the same equations as the planar ones (symbolic.dynamics),

    Φ_qᵀ λ = Q - M q̈ - h,

with every body's normalisation row pᵀp - 1 = 0 among the rows of Φ: its multiplier is
solved for with the others and reported nowhere (it carries no load of a joint).

Kinetic energy (Nikravesh, Haug): with G(p) = [-e, -ẽ + e0 I] the body's angular velocity in
its own frame is ω' = 2 G ṗ, and with its centre of mass at the local vector c (r_c = r + A c)

    T = ½ m |ṙ_c|² + ½ ω'ᵀ J' ω' = ½ m |ṙ_c|² + 2 ṗᵀ Gᵀ J' G ṗ,

so M = ∂²T/∂q̇² (its rotational block 4 Gᵀ J' G when c = 0) and h = (∂²T/∂q̇∂q) q̇ - ∂T/∂q
(Lagrange's equations, worked out in :func:`_body_terms`). T is written for any p; where it
differs from another extension off the sphere pᵀp = 1 the difference lies along p, which only
the normalisation multiplier sees.

Applied forces by virtual work: a force F at a point P gives Q_k = F·∂r_P/∂q_k (gravity: m g
at the centre of mass; a spring: -tension ∂L/∂q_k, symbolic.dynamics), and a torque n (global)
Q_p = 2 Eᵀ n with E(p) = [-e, ẽ + e0 I], since the global angular velocity is ω = 2 E ṗ
(2 Eᵀ n = 2 Gᵀ Aᵀ n with A = E Gᵀ).

Reactions: the generalized constraint force of a joint's rows on body j, -Φ_{q_j}ᵀ λ, is
[F; Q_p] with F the force (global) and Q_p = 2 Eᵀ n + (a multiple of p), n the moment about
j's frame origin; since E p = 0 and E Eᵀ = I, n = ½ E Q_p. Moved to the joint's point P on
body i: M = n - (P - r_j) x F; [Fx, Fy, Fz, Mx, My, Mz] is what body i exerts on body j
(with j the ground: the same from body i, negated).

Efforts: the power of a driver row's constraint force is -λ Φ_q q̇ = λ Φ_t = λ (∂Φ/∂f) ḟ for
its driven function f(t), so the effort that does work along f is λ ∂Φ/∂f: for an ``angle``
driver (Φ = sin(θ - ψ)) λ, the torque about the axis on body j (-effort on i); for a
``distance`` actuator -λ f / L0, the force along the leg pushing A and B apart; for a
``slide`` -λ, the force on j along the axis.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import sympy as sp

from symkin import pairs
from symkin.pairs.fields import GROUND
from symkin.spec import forces3d
from symkin.spec.validate import Mechanism
from symkin.symbolic import dynamics
from symkin.symbolic.planar import TAU
from symkin.symbolic.spatial import Pose, SpatialContext

SIZE = 7  # coordinates of a spatial body: x, y, z, e0, e1, e2, e3


def body_frame_rates(e: tuple[sp.Expr, ...]) -> sp.Matrix:
    """G(p) = [-e, -ẽ + e0 I]: ω' = 2 G ṗ in the body frame."""
    e0, e1, e2, e3 = e
    return sp.Matrix([[-e1, e0, e3, -e2], [-e2, -e3, e0, e1], [-e3, e2, -e1, e0]])


def global_rates(e: tuple[sp.Expr, ...]) -> sp.Matrix:
    """E(p) = [-e, ẽ + e0 I]: ω = 2 E ṗ in the global frame."""
    e0, e1, e2, e3 = e
    return sp.Matrix([[-e1, e0, -e3, e2], [-e2, e3, e0, -e1], [-e3, -e2, e1, e0]])


def derive(mech: Mechanism, ctx: SpatialContext, phi_q: sp.SparseMatrix, rows: Any,
           placed: Any, drivers: list[Any],
           removed: tuple[tuple[Any, sp.Matrix], ...] = ()) -> dynamics.Dynamics:
    """The dynamics of a spatial ``mech`` whose Jacobian is ``phi_q`` (rows labelled by
    ``rows``); ``drivers``: the file's drivers as their rows were written (inputs in place);
    ``removed``: the rows removed as redundant, as for :func:`dynamics.derive`."""
    symbols = ctx.symbols
    n = len(symbols.q)
    ddq = tuple(sp.Symbol(name + "_tt", real=True) for name in symbols.coordinates)
    lam = tuple(sp.Symbol(f"lambda{k}", real=True) for k in range(n + len(removed)))
    kinetic, applied = sp.Integer(0), sp.zeros(n, 1)
    mass, velocity_terms, inertial = sp.zeros(n, n), sp.zeros(n, 1), sp.zeros(n, 1)
    for body, spec in mech.bodies.items():
        terms = _body_terms(ctx, body, spec, ddq)
        columns = _columns(ctx, body)
        for a, row in enumerate(columns):
            velocity_terms[row] += terms.velocity[a]
            inertial[row] += terms.inertial[a]
            for b, column in enumerate(columns):
                mass[row, column] += terms.mass[a, b]
        kinetic += terms.kinetic
    for load in mech.forces:
        applied += (_torque(ctx, load) if load.type == "torque"
                    else dynamics.generalized_force(mech, ctx, load))
    rhs = applied - inertial  # Q - (M q̈ + h), M q̈ + h as Newton-Euler (_body_terms)
    every_label = (*rows, *(label for label, _ in removed))
    return dynamics.assemble(
        mech, ctx, phi_q, rows, placed, removed, lam, _reaction,
        _effort_scales(ctx, every_label, drivers), ddq=ddq, mass_matrix=sp.ImmutableMatrix(mass),
        applied=sp.ImmutableMatrix(applied), velocity_terms=sp.ImmutableMatrix(velocity_terms),
        rhs=sp.ImmutableMatrix(rhs), kinetic=kinetic)


def _columns(ctx: SpatialContext, body: str) -> list[int]:
    start = ctx.symbols.coordinates.index(f"{body}.x")
    return list(range(start, start + SIZE))


def _com(ctx: SpatialContext, body: str, spec: Any) -> sp.Matrix:
    return ctx.local(body, spec.com) if spec.com is not None else sp.zeros(3, 1)


@dataclass(frozen=True)
class _BodyTerms:
    """One body's share of the equations of motion, on its own seven columns."""

    mass: sp.Matrix  # 7 x 7
    velocity: sp.Matrix  # h, 7 x 1
    inertial: sp.Matrix  # M q̈ + h, 7 x 1, written as Newton-Euler (see _body_terms)
    kinetic: sp.Expr


def _body_terms(ctx: SpatialContext, body: str, spec: Any, ddq: tuple[sp.Symbol, ...]
                ) -> _BodyTerms:
    """One body's mass matrix, velocity terms and M q̈ + h on its own columns, and its T.

    With B(p) = ∂(A c)/∂p (3 x 4, linear in p, so Ḃ = B(ṗ)) the velocity of the centre is
    ṙ + B ṗ and Lagrange's equations of T (module docstring) give, worked out once by hand
    (∂(B ṗ)/∂p = B(ṗ) and ∂(G ṗ)/∂p = -G(ṗ) = -Ġ, Ġ ṗ = 0):

        M = [[m I, m B], [m Bᵀ, m BᵀB + 4 GᵀJ'G]],   h = [m Ḃ ṗ; m Bᵀ Ḃ ṗ + 8 ĠᵀJ'G ṗ].

    M q̈ + h is not formed from M (a 7 x 7 block of quadratics in p times q̈, which common
    subexpressions cannot undo) but grouped as Newton-Euler per body, the same terms for
    any p: the centre's acceleration a = r̈ + B p̈ + Ḃ ṗ and the force f = m a, the body-frame
    ω' = 2 G ṗ and alpha' = 2 G p̈ (Ġ ṗ = 0), then [f; Bᵀ f + 2 Gᵀ J' alpha' + 4 Ġᵀ J' ω']. M and h
    are grouped the same way (Bᵀ B, Gᵀ (J' G)), so each of B, Ḃ ṗ, ω', J' ω' appears once
    for the code's common subexpressions to share.
    """
    pose = ctx.pose(body)
    columns = _columns(ctx, body)
    rates = [ctx.symbols.dq[k] for k in columns]
    v, de = sp.Matrix(rates[:3]), sp.Matrix(rates[3:])
    accelerations = sp.Matrix([ddq[k] for k in columns])
    m = ctx.expr(spec.mass or 0)
    inertia = sp.Matrix([[ctx.expr(item) for item in row]
                         for row in forces3d.matrix(spec.inertia or 0)])
    e = sp.Matrix(pose.e)
    arm = (pose.A * _com(ctx, body, spec)).jacobian(e)
    arm_rate = arm.xreplace(dict(zip(pose.e, rates[3:])))
    G, G_rate = body_frame_rates(pose.e), body_frame_rates(tuple(rates[3:]))
    # the factors 4 and 8 go into J' (numbers or parameters) before it meets G: a number
    # times a sum is distributed over its terms, so outside it would multiply each one
    inertia_G = (4 * inertia) * G  # 4 J' G
    rate_G = G * de  # ω' / 2
    spin_momentum = (8 * inertia) * rate_G  # 4 J' ω'
    drift = arm_rate * de  # Ḃ ṗ: the centre's acceleration at p̈ = 0, r̈ = 0
    force = m * (accelerations[:3, :] + arm * accelerations[3:, :] + drift)
    turning = inertia_G * accelerations[3:, :]  # 2 J' alpha'
    inertial = sp.Matrix.vstack(force, arm.T * force + G.T * turning + G_rate.T * spin_momentum)
    mass = sp.BlockMatrix([[m * sp.eye(3), m * arm],
                           [m * arm.T, m * (arm.T * arm) + G.T * inertia_G]]).as_explicit()
    velocity = sp.Matrix.vstack(m * drift, m * (arm.T * drift) + G_rate.T * spin_momentum)
    speed = v + arm * de
    kinetic = m * (speed.T * speed)[0, 0] / 2 + (rate_G.T * spin_momentum)[0, 0] / 4
    return _BodyTerms(mass, velocity, inertial, kinetic)


def _torque(ctx: SpatialContext, load: Any) -> sp.Matrix:
    """Q_p = 2 Eᵀ n for a torque n (global components) on one body."""
    total = sp.zeros(len(ctx.symbols.q), 1)
    moment = sp.Matrix([dynamics.load_expr(ctx, raw) for raw in load.m])
    generalized = 2 * global_rates(ctx.pose(load.body).e).T * moment
    for k, column in enumerate(_columns(ctx, load.body)[3:]):
        total[column] = generalized[k]
    return total


def _reaction(ctx: SpatialContext, phi_q: sp.SparseMatrix, own: list[int],
              bodies: tuple[str, ...], lam: tuple[sp.Symbol, ...],
              local: sp.Matrix | None) -> list[sp.Expr]:
    """[Fx, Fy, Fz, Mx, My, Mz]: what body i exerts on body j, M about the joint's point on
    body i (module docstring)."""
    i, j = (bodies + (GROUND,))[:2] if len(bodies) < 2 else bodies[:2]
    point = ctx.pose(i).point(local if local is not None else sp.zeros(3, 1))

    def about_point(body: str) -> list[sp.Expr]:
        pose: Pose = ctx.pose(body)
        values = [-sum(phi_q[r, k] * lam[r] for r in own) for k in _columns(ctx, body)]
        force = sp.Matrix(values[:3])
        moment = global_rates(pose.e) * sp.Matrix(values[3:]) / 2
        return [*force, *(moment - (point - pose.r).cross(force))]

    if j != GROUND:
        return about_point(j)
    return [-value for value in about_point(i)]


@dataclass(frozen=True)
class _Probe(SpatialContext):
    """A context that writes each time function f as a fresh symbol, recording f."""

    found: dict[sp.Symbol, sp.Expr] = field(default_factory=dict)

    def time_function(self, raw: Any) -> sp.Expr:
        symbol = sp.Dummy(f"f{len(self.found)}", real=True)
        self.found[symbol] = super().time_function(raw)
        return symbol


def _effort_scales(ctx: SpatialContext, rows: Any, drivers: list[Any]) -> dict[int, sp.Expr]:
    """∂Φ/∂f of each driver row that has one driven function f (the others: -1)."""
    scales: dict[int, sp.Expr] = {}
    for r, row in enumerate(rows):
        if row.section != "drivers":
            continue
        constraint = drivers[row.index]
        kind = pairs.of(constraint)
        probe = _Probe(ctx.mech, ctx.symbols)
        equations = kind.equations(constraint, probe)
        parts = kind.rows or tuple(f"equation {k}" for k in range(len(equations)))
        equation = equations[parts.index(row.part)]
        driven = [symbol for symbol in probe.found if equation.has(symbol)]
        if len(driven) == 1:
            slope = equation.diff(driven[0]).xreplace({driven[0]: probe.found[driven[0]]})
            scales[r] = slope.xreplace({TAU: ctx.symbols.t})
    return scales
