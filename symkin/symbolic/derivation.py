"""Stage 2 — derivation: Phi(q, t), its sparse Jacobian Phi_q, Phi_t and Gamma with SymPy.

Each row is derived from the few coordinates it touches (at most six for the chapter's pairs),
so the cost grows linearly with the number of joints:

    Gamma = -(Phi_q dq)_q dq - 2 Phi_qt dq - Phi_tt                       (2.74)

and Phi_p, the derivative with respect to the parameters, for design sensitivities: along a
solution Phi(q(p), t, p) = 0, so Phi_q q_p = -Phi_p.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import sympy as sp

from symkin import pairs
from symkin.spec import validate
from symkin.spec.validate import Mechanism
from symkin.symbolic import spatial
from symkin.symbolic.planar import Context
from symkin.symbolic.symbols import Symbols, make_symbols

# A spatial body's own row: its Euler parameters' normalisation (section, part).
NORMALISATION = ("bodies", "normalisation")


@dataclass(frozen=True)
class Row:
    """Which joint or driver owns a row of Phi, and which of its equations the row is."""

    section: str  # "joints" or "drivers"
    index: int
    type: str
    bodies: tuple[str, ...]
    part: str
    name: str | None = None

    @property
    def owner(self) -> str:
        """``joints[1] revolute crank-rod`` (or the constraint's own name); a spatial body's
        normalisation row: ``bodies[0] crank``."""
        if self.section == NORMALISATION[0]:
            return f"{self.section}[{self.index}] {self.name}"
        who = f" {self.name}" if self.name else ""
        return f"{self.section}[{self.index}]{who} {self.type} {'-'.join(self.bodies)}".rstrip()

    def __str__(self) -> str:
        return f"{self.owner} ({self.part})"


@dataclass(frozen=True)
class Placed:
    """A local vector of a joint or driver, resolved: a point (or direction, ``kind``) of
    ``body`` that the constraint's ``key`` gives, as expressions of the parameters; ``side``
    is the key naming that body (``i`` or ``j``)."""

    section: str
    index: int
    key: str
    body: str
    side: str
    vector: sp.ImmutableMatrix
    kind: str = "point"  # or "direction"


@dataclass(frozen=True)
class System:
    """The symbolic kinematics of one mechanism: Phi, its derivatives, the row labels and
    the resolved vectors of points, joints and drivers."""

    mechanism: Mechanism
    q: tuple[sp.Symbol, ...]
    dq: tuple[sp.Symbol, ...]
    t: sp.Symbol
    p: tuple[sp.Symbol, ...]
    p_values: tuple[float, ...]
    coordinates: tuple[str, ...]
    phi: sp.ImmutableMatrix
    phi_q: sp.ImmutableSparseMatrix
    phi_t: sp.ImmutableMatrix
    gamma: sp.ImmutableMatrix
    rows: tuple[Row, ...]
    q0: tuple[float, ...]
    points: tuple[tuple[str, str, sp.ImmutableMatrix], ...]
    """Every named point as (body, name, local vector), bodies and points in file order."""
    placed: tuple[Placed, ...]
    """The points and directions of every joint and driver, resolved once for all stages."""
    time_grid: tuple[float, float, float]
    """(t0, t1, dt) at the nominal parameter values."""
    phi_p: sp.ImmutableSparseMatrix | None = None
    """dPhi/dp, N x NP (sparse): Phi_q q_p = -Phi_p gives the sensitivities q_p."""

    @property
    def name(self) -> str:
        return self.mechanism.name

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(symbol.name for symbol in self.p)

    @property
    def dof(self) -> int:
        return validate.degrees_of_freedom(self.mechanism)

    def pattern(self) -> list[tuple[int, int]]:
        """Structural non-zeros of Phi_q as (row, column), row-major."""
        return sorted(self.phi_q.todok())


def derive(mech: Mechanism | str | Path) -> System:
    """Derive Phi, Phi_q, Phi_t and Gamma of a mechanism (a Mechanism or a file path)."""
    if not isinstance(mech, Mechanism):
        mech = validate.load(mech)
    symbols = make_symbols(mech)
    ctx = (spatial.SpatialContext if mech.is_spatial else Context)(mech, symbols)
    phi, rows = _constraint_rows(mech, ctx)
    if mech.is_spatial:
        phi, rows = _normalised(mech, ctx, phi, rows)
    column = {q: k for k, q in enumerate(symbols.q)}
    jacobian: dict[tuple[int, int], sp.Expr] = {}
    phi_t, gamma = [], []
    for r, row in enumerate(phi):
        entries = _row_jacobian(row, column, symbols.q)
        jacobian.update({(r, k): value for k, value in entries.items()})
        row_t = sp.diff(row, symbols.t)
        phi_t.append(row_t)
        gamma.append(_row_gamma(entries, row_t, symbols))
    size = len(symbols.q)
    values = mech.parameter_values()
    p_values = tuple(values[s.name] for s in symbols.p)
    nominal = dict(zip(symbols.p, p_values))
    return System(
        mechanism=mech, q=symbols.q, dq=symbols.dq, t=symbols.t, p=symbols.p,
        p_values=p_values, coordinates=symbols.coordinates,
        phi=sp.ImmutableMatrix(phi), phi_q=sp.ImmutableSparseMatrix(size, size, jacobian),
        phi_t=sp.ImmutableMatrix(phi_t), gamma=sp.ImmutableMatrix(gamma), rows=rows,
        q0=_initial_guess(mech, ctx, nominal),
        points=tuple((body, name, sp.ImmutableMatrix(ctx.local(body, name)))
                     for body, spec in mech.bodies.items() for name in spec.points),
        placed=_placed(mech, ctx), time_grid=_time_grid(mech, ctx, nominal),
        phi_p=_parameter_jacobian(phi, symbols.p),
    )


def _constraint_rows(mech: Mechanism, ctx: Context) -> tuple[list[sp.Expr], tuple[Row, ...]]:
    """Phi and its row labels: joints in file order, then drivers (README, "Row order")."""
    phi: list[sp.Expr] = []
    rows: list[Row] = []
    for section in pairs.SECTIONS:
        for index, constraint in enumerate(getattr(mech, section)):
            kind = pairs.of(constraint)
            equations = kind.equations(constraint, ctx)
            parts = kind.rows or tuple(f"equation {k}" for k in range(len(equations)))
            bodies = kind.joined_bodies(constraint) or _bodies_touched(equations, ctx)
            phi.extend(equations)
            rows.extend(Row(section, index, constraint.type, bodies, part, constraint.name)
                        for part in parts)
    return phi, tuple(rows)


def _normalised(mech: Mechanism, ctx: Context, phi: list[sp.Expr], rows: tuple[Row, ...]
                ) -> tuple[list[sp.Expr], tuple[Row, ...]]:
    """Phi and its labels with one normalisation row per spatial body, after the drivers."""
    section, part = NORMALISATION
    own = [(spatial.normalisation(ctx.pose(body)),  # type: ignore[arg-type]
            Row(section, k, "", (body,), part, body)) for k, body in enumerate(mech.bodies)]
    return phi + [row for row, _ in own], rows + tuple(label for _, label in own)


def _placed(mech: Mechanism, ctx: Context) -> tuple[Placed, ...]:
    """The local vectors of every joint and driver: its points, then its directions."""
    found = []
    for section in pairs.SECTIONS:
        for index, constraint in enumerate(getattr(mech, section)):
            kind = pairs.of(constraint)
            for key, body_key in kind.points:
                body = getattr(constraint, body_key)
                vector = ctx.local(body, getattr(constraint, key))
                found.append(Placed(section, index, key, body, body_key,
                                    sp.ImmutableMatrix(vector)))
            for key, body_key in kind.directions:
                vector = ctx.vector(getattr(constraint, key))
                found.append(Placed(section, index, key, getattr(constraint, body_key),
                                    body_key, sp.ImmutableMatrix(vector), "direction"))
    return tuple(found)


def _time_grid(mech: Mechanism, ctx: Context,
               values: dict[sp.Symbol, float]) -> tuple[float, float, float]:
    grid = mech.time
    t0, t1, dt = (float(ctx.expr(raw).subs(values)) for raw in (grid.t0, grid.t1, grid.dt))
    return t0, t1, dt


def _bodies_touched(equations: list[sp.Expr], ctx: Context) -> tuple[str, ...]:
    used = set().union(*(e.free_symbols for e in equations))
    return tuple(dict.fromkeys(name.split(".")[0] for name, q in
                               zip(ctx.symbols.coordinates, ctx.symbols.q) if q in used))


def _row_jacobian(row: sp.Expr, column: dict[sp.Symbol, int],
                  q: tuple[sp.Symbol, ...]) -> dict[int, sp.Expr]:
    """The structural non-zeros of one row of Phi_q, keyed by column."""
    touched = sorted(column[s] for s in row.free_symbols if s in column)
    derivatives = {k: sp.diff(row, q[k]) for k in touched}
    return {k: value for k, value in derivatives.items() if value != 0}


def _parameter_jacobian(phi: list[sp.Expr], p: tuple[sp.Symbol, ...]
                        ) -> sp.ImmutableSparseMatrix:
    """Phi_p: per row, the derivatives with respect to the parameters the row contains."""
    column = {symbol: k for k, symbol in enumerate(p)}
    entries: dict[tuple[int, int], sp.Expr] = {}
    for r, row in enumerate(phi):
        entries.update({(r, k): value for k, value in
                        _row_jacobian(row, column, p).items()})
    return sp.ImmutableSparseMatrix(len(phi), len(p), entries)


def _row_gamma(entries: dict[int, sp.Expr], row_t: sp.Expr,
               symbols: Symbols) -> sp.Expr:
    """One row of Gamma = -(Phi_q dq)_q dq - 2 Phi_qt dq - Phi_tt, from this row's columns."""
    q, dq, t = symbols.q, symbols.dq, symbols.t
    velocity = sp.Add(*(value * dq[k] for k, value in entries.items()))
    convective = sp.Add(*(sp.diff(velocity, q[k]) * dq[k] for k in entries))
    mixed = sp.Add(*(sp.diff(value, t) * dq[k] for k, value in entries.items()))
    return -convective - 2 * mixed - sp.diff(row_t, t)


def _initial_guess(mech: Mechanism, ctx: Context,
                   values: dict[sp.Symbol, float]) -> tuple[float, ...]:
    return tuple(float(ctx.expr(raw).subs(values)) for body in mech.bodies.values()
                 for raw in body.q0)
