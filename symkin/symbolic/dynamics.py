"""Inverse dynamics in absolute coordinates: the mass terms, the applied forces Q(q, dq, t),
and the efforts and reactions that follow from the Lagrange multipliers.

With the motion known (q, dq, ddq from the kinematic solve), the equations of motion
M ddq + Φ_qᵀ λ = Q - h(q, dq) give the multipliers from one linear solve with the transposed
Jacobian (sign convention, REFERENCE.md "forces"):

    Φ_qᵀ λ = Q - M ddq - h  =: rhs(q, dq, ddq, t)

M and h come from the kinetic energy T of each body with its centre of mass at the local
vector c (not necessarily the frame's origin): r_c = r + R c, T = ½ m |ṙ_c|² + ½ J φ̇², so
M = ∂²T/∂q̇², and h = (∂²T/∂q̇∂q) q̇ - ∂T/∂q (Lagrange's equations; zero when c = 0).
Q is the virtual work of the loads: a force F at point P gives Q_k = F·∂r_P/∂q_k, a torque m
gives Q_φ = m, gravity is the force m g at the centre of mass, and a spring of length L with
tension k (L - L0) + d L̇ gives Q_k = -tension ∂L/∂q_k.

The constraint forces on the bodies are -Φ_qᵀ λ; the rows of one joint give its reaction:
[Fx, Fy, n] = -(Φ_q rows of the joint, columns of body j)ᵀ λ_joint is what body i exerts on
body j (n about j's frame origin), moved to the joint's point P on body i:
M = n - (P - r_j) x F. When j is the ground the same is taken from body i and negated
(action and reaction). A driver row's effort is -λ: the generalized force its actuator
applies along the driven function (work = effort · δf) — for an ``angle`` driver the torque
on body i, for ``slide`` the force on body j along u (unit u).

Where rows were removed as redundant (symbolic.redundancy) the loads are derived from the
multipliers of every row the file writes: lam holds the kept rows' then the removed rows',
``loads`` reads the kept ones only (the removed rows' multipliers taken as zero, one of the
many solutions) and ``loads_full`` all of them, with ``removed_q`` the removed rows' Jacobian:
the runtime (runtime.loads.indeterminate) finds from these which loads are determinate and the
minimum-norm multipliers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy as sp

from symkin import pairs
from symkin.pairs.fields import GROUND
from symkin.spec import expressions
from symkin.spec import forces as loads_spec
from symkin.spec.validate import Mechanism
from symkin.symbolic.planar import Context, Pose


@dataclass(frozen=True)
class Dynamics:
    """The inverse-dynamics expressions of one mechanism.

    Attributes:
        ddq: the acceleration symbols (``body.x_tt``...), same order as q.
        lam: the multiplier symbols, one per row of Φ, then one per removed row.
        mass_matrix: M(q), N x N.
        applied: Q(q, dq, t), N x 1.
        velocity_terms: h(q, dq), N x 1 (zero when every frame is at its centre of mass).
        rhs: Q - M ddq - h, the right-hand side of Φ_qᵀ λ = rhs.
        kinetic: T(q, dq), for the power balance.
        loads: the efforts (one per driver row) then 3 values per joint (Fx, Fy, M), as
            functions of q, λ, t and p.
        driver_names, joint_names: labels of the efforts and of the joints' reactions.
        loads_full: the loads from the multipliers of the kept and the removed rows (lam
            whole); None when no row was removed.
        removed_q: the removed rows' Jacobian, R x N; None when no row was removed.
    """

    ddq: tuple[sp.Symbol, ...]
    lam: tuple[sp.Symbol, ...]
    mass_matrix: sp.ImmutableMatrix
    applied: sp.ImmutableMatrix
    velocity_terms: sp.ImmutableMatrix
    rhs: sp.ImmutableMatrix
    kinetic: sp.Expr
    loads: sp.ImmutableMatrix
    driver_names: tuple[str, ...]
    joint_names: tuple[str, ...]
    loads_full: sp.ImmutableMatrix | None = None
    removed_q: sp.ImmutableMatrix | None = None


def derive(mech: Mechanism, ctx: Context, phi_q: sp.SparseMatrix, rows: Any,
           placed: Any, removed: tuple[tuple[Any, sp.Matrix], ...] = ()) -> Dynamics:
    """The dynamics of ``mech`` whose Jacobian is ``phi_q`` (rows labelled by ``rows``);
    ``removed``: the rows removed as redundant, each (its label, its 1 x N Jacobian)."""
    symbols = ctx.symbols
    ddq = tuple(sp.Symbol(name + "_tt", real=True) for name in symbols.coordinates)
    n = len(symbols.q)
    lam = tuple(sp.Symbol(f"lambda{k}", real=True) for k in range(n + len(removed)))
    kinetic, applied = sp.Integer(0), sp.zeros(n, 1)
    mass, velocity_terms = sp.zeros(n, n), sp.zeros(n, 1)
    for body, spec in mech.bodies.items():
        columns = _columns(symbols, body)
        m, inertia = (ctx.expr(spec.mass or 0), ctx.expr(spec.inertia or 0))
        com = ctx.local(body, spec.com) if spec.com is not None else sp.zeros(2, 1)
        energy = _body_energy(ctx, body, columns, m, inertia, com)
        kinetic += energy
        _lagrange_terms(energy, columns, symbols, mass, velocity_terms)
    for load in mech.forces:
        applied += generalized_force(mech, ctx, load)
    rhs = applied - mass * sp.Matrix(ddq) - velocity_terms
    return assemble(mech, ctx, phi_q, rows, placed, removed, lam, _reaction, {},
                    ddq=ddq, mass_matrix=sp.ImmutableMatrix(mass),
                    applied=sp.ImmutableMatrix(applied),
                    velocity_terms=sp.ImmutableMatrix(velocity_terms),
                    rhs=sp.ImmutableMatrix(rhs), kinetic=kinetic)


def assemble(mech: Mechanism, ctx: Any, phi_q: sp.SparseMatrix, rows: Any, placed: Any,
             removed: tuple[tuple[Any, sp.Matrix], ...], lam: tuple[sp.Symbol, ...],
             reaction: Any, scale: dict[int, sp.Expr], **terms: Any) -> Dynamics:
    """The Dynamics of the equations of motion ``terms``, with the loads of the multipliers
    ``lam`` of every row the file writes: the kept rows' (``phi_q``) then the ``removed``
    rows' (planar and spatial alike; ``reaction`` and ``scale`` as for :func:`loads`)."""
    n = phi_q.shape[1]
    removed_q = sp.Matrix.vstack(sp.zeros(0, n), *(jacobian for _, jacobian in removed))
    every_row = sp.Matrix.vstack(sp.Matrix(phi_q), removed_q)
    every_label = (*rows, *(label for label, _ in removed))
    efforts, reactions, driver_names, joint_names = loads(mech, ctx, every_row, every_label,
                                                         placed, lam, reaction, scale)
    full = sp.ImmutableMatrix([*efforts, *reactions])
    kept = full.xreplace({symbol: 0 for symbol in lam[n:]})
    return Dynamics(
        lam=lam, loads=kept, driver_names=driver_names, joint_names=joint_names, **terms,
        loads_full=full if removed else None,
        removed_q=sp.ImmutableMatrix(removed_q) if removed else None)


def _columns(symbols: Any, body: str) -> list[int]:
    start = symbols.coordinates.index(f"{body}.x")
    return [start, start + 1, start + 2]


def velocity(expr: sp.Matrix, symbols: Any) -> sp.Matrix:
    """d/dt of an expression of q (no explicit t): Σ ∂expr/∂q_k dq_k."""
    used = [k for k, q in enumerate(symbols.q) if expr.has(q)]
    return sum((expr.diff(symbols.q[k]) * symbols.dq[k] for k in used),
               sp.zeros(*expr.shape))


def _body_energy(ctx: Context, body: str, columns: list[int], m: sp.Expr, inertia: sp.Expr,
                 com: sp.Matrix) -> sp.Expr:
    """T = ½ m |ṙ_c|² + ½ J φ̇² with r_c = r + R c."""
    speed = velocity(ctx.pose(body).point(com), ctx.symbols)
    rate = ctx.symbols.dq[columns[2]]
    return sp.expand(m * (speed.T * speed)[0, 0] / 2 + inertia * rate ** 2 / 2)


def _lagrange_terms(energy: sp.Expr, columns: list[int], symbols: Any, mass: sp.Matrix,
                    velocity_terms: sp.Matrix) -> None:
    """Add one body's M = ∂²T/∂q̇² and h = (∂²T/∂q̇∂q) q̇ - ∂T/∂q (its own columns only)."""
    for a in columns:
        momentum = energy.diff(symbols.dq[a])
        for b in columns:
            mass[a, b] += _tidy(momentum.diff(symbols.dq[b]))
        convective = sum(momentum.diff(symbols.q[b]) * symbols.dq[b] for b in columns)
        velocity_terms[a] += _tidy(convective - energy.diff(symbols.q[a]))


# simplify only compacts; with an exact number of this many digits (a point at 1e-200 read
# as 1/10**200) it runs for minutes, so such a term is kept as it is (still exact).
MAX_SIMPLIFY_DIGITS = 60


def _tidy(expr: sp.Expr) -> sp.Expr:
    """``expr`` simplified, unless an exact number in it is too long for simplify to finish."""
    if any(len(str(abs(r.p))) + len(str(r.q)) > MAX_SIMPLIFY_DIGITS
           for r in expr.atoms(sp.Rational)):
        return expr
    return sp.simplify(expr)


def _names(ctx: Context) -> tuple[dict[str, sp.Symbol], dict[tuple[str, str], sp.Symbol]]:
    """What a load's expression may name: parameters, t, coordinates and their rates."""
    symbols = ctx.symbols
    mapping = dict(zip(symbols.coordinates, symbols.q)) | dict(
        zip((c + loads_spec.RATE_SUFFIX for c in symbols.coordinates), symbols.dq))
    coordinates = loads_spec.coordinate_names(ctx.mech.bodies, mapping.__getitem__,
                                              ctx.mech.body_coordinates)
    return {**symbols.parameters, "t": symbols.t}, coordinates


def load_expr(ctx: Context, raw: Any) -> sp.Expr:
    """An expression of a load: t, parameters, coordinates and their rates."""
    names, coordinates = _names(ctx)
    return expressions.parse(raw, names, coordinates)


def _point_force(ctx: Context, position: sp.Matrix, force: sp.Matrix) -> sp.Matrix:
    """Q_k = F · ∂r_P/∂q_k (virtual work of a force at P)."""
    return sp.Matrix([(force.T * position.diff(q))[0, 0] for q in ctx.symbols.q])


def generalized_force(mech: Mechanism, ctx: Context, load: Any) -> sp.Matrix:
    """Q of one load by virtual work (a planar torque; symbolic.dynamics3d: a spatial one)."""
    symbols, n = ctx.symbols, len(ctx.symbols.q)
    if load.type == "gravity":
        g = sp.Matrix([load_expr(ctx, raw) for raw in load.g])
        total = sp.zeros(n, 1)
        for body, spec in mech.bodies.items():
            if spec.mass is not None:
                com = (ctx.local(body, spec.com) if spec.com is not None
                       else sp.zeros(len(ctx.pose(body).r), 1))
                total += _point_force(ctx, ctx.pose(body).point(com), ctx.expr(spec.mass) * g)
        return total
    if load.type == "force":
        position = ctx.pose(load.body).point(ctx.local(load.body, load.at))
        return _point_force(ctx, position, sp.Matrix([load_expr(ctx, raw) for raw in load.f]))
    if load.type == "torque":
        total = sp.zeros(n, 1)
        total[_columns(symbols, load.body)[2]] = load_expr(ctx, load.m)
        return total
    # a spring-damper: Q = -tension dL/dq
    a = spring_end(ctx, load.i, load.A)
    b = spring_end(ctx, load.j, load.B)
    d = b - a
    length = sp.sqrt((d.T * d)[0, 0])
    rate = velocity(sp.Matrix([length]), symbols)[0, 0]
    tension = (load_expr(ctx, load.k) * (length - load_expr(ctx, load.length0))
               + load_expr(ctx, load.damping) * rate)
    return sp.Matrix([-tension * length.diff(q) for q in symbols.q])


def spring_end(ctx: Context, body: str, ref: Any) -> sp.Matrix:
    if body == GROUND:
        return ctx.vector(ref)
    return ctx.pose(body).point(ctx.local(body, ref))


def _cross(a: sp.Matrix, b: sp.Matrix) -> sp.Expr:
    return a[0] * b[1] - a[1] * b[0]


def loads(mech: Mechanism, ctx: Context, phi_q: sp.SparseMatrix, rows: Any, placed: Any,
          lam: tuple[sp.Symbol, ...], reaction: Any,
          scale: dict[int, sp.Expr]) -> tuple[list[sp.Expr], list[sp.Expr],
                                              tuple[str, ...], tuple[str, ...]]:
    """Efforts (``scale`` λ of each driver row, -λ where it has none) and each joint's
    reaction (``reaction``, called like :func:`_reaction`) from its rows' λ."""
    efforts: list[sp.Expr] = []
    reactions: list[sp.Expr] = []
    driver_names: list[str] = []
    joint_names: list[str] = []
    by_owner: dict[tuple[str, int], list[int]] = {}
    for r, row in enumerate(rows):
        by_owner.setdefault((row.section, row.index), []).append(r)
    for section in pairs.SECTIONS:
        for index, constraint in enumerate(getattr(mech, section)):
            own = by_owner.get((section, index), [])
            name = constraint.name or f"{section[:-1]}{index}"
            if section == "drivers":
                efforts += [scale.get(r, sp.Integer(-1)) * lam[r] for r in own]
                parts = [rows[r].part for r in own]
                driver_names += [name] if len(own) == 1 else [f"{name}.{p}" for p in parts]
                continue
            joint_names.append(name)
            reactions += reaction(ctx, phi_q, own, rows[own[0]].bodies, lam,
                                  _point_on_i(placed, index))
    return efforts, reactions, tuple(driver_names), tuple(joint_names)


def _point_on_i(placed: Any, index: int) -> sp.Matrix | None:
    for item in placed:
        if (item.section, item.index, item.side, item.kind) == ("joints", index, "i", "point"):
            return sp.Matrix(item.vector)
    return None


def _reaction(ctx: Context, phi_q: sp.SparseMatrix, own: list[int], bodies: tuple[str, ...],
              lam: tuple[sp.Symbol, ...], local: sp.Matrix | None) -> list[sp.Expr]:
    """[Fx, Fy, M]: what body i exerts on body j, M about the joint's point on body i."""
    i, j = (bodies + (GROUND,))[:2] if len(bodies) < 2 else bodies[:2]
    point = ctx.pose(i).point(local if local is not None else sp.zeros(2, 1))

    def generalized(body: str) -> tuple[sp.Matrix, sp.Expr, Pose]:
        values = [-sum(phi_q[r, k] * lam[r] for r in own) for k in _columns(ctx.symbols, body)]
        return sp.Matrix(values[:2]), values[2], ctx.pose(body)

    if j != GROUND:
        force, moment, pose = generalized(j)
        return [force[0], force[1], moment - _cross(point - pose.r, force)]
    force, moment, pose = generalized(i)
    return [-force[0], -force[1], -(moment - _cross(point - pose.r, force))]
