"""Stage 2 — derivation: Phi(q, t), its sparse Jacobian Phi_q, Phi_t and Gamma with SymPy.

Each row is derived from the few coordinates it touches (at most six for the chapter's pairs),
so the cost grows linearly with the number of joints:

    Gamma = -(Phi_q dq)_q dq - 2 Phi_qt dq - Phi_tt                       (2.74)

and Phi_p, the derivative with respect to the parameters, for design sensitivities: along a
solution Phi(q(p), t, p) = 0, so Phi_q q_p = -Phi_p.

Gamma's convective part: :mod:`symkin.symbolic.differentiation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import sympy as sp

from symkin import pairs
from symkin.errors import ExpressionError, MechanismError
from symkin.spec import motion as motion_spec
from symkin.spec import name_checks, validate
from symkin.spec.forces import has_dynamics
from symkin.spec.validate import Mechanism
from symkin.symbolic import dynamics, dynamics3d, pickling, redundancy, spatial
from symkin.symbolic.derivatives import diff
from symkin.symbolic.differentiation import Memory, parameter_jacobian, row_gamma, row_jacobian
from symkin.symbolic.input_rows import at_tau, input_values, with_inputs
from symkin.symbolic.planar import Context
from symkin.symbolic.symbols import Input, Symbols, extra_coordinates, make_symbols

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
class Removed:
    """A row of Phi found dependent at the assembled t0 and removed for the run
    (symbolic.redundancy); its equation is kept, to be checked along the motion."""

    row: Row
    phi: sp.Expr
    index: int
    """Its place among all the rows the file writes (joints, then drivers)."""
    dependency: float
    """Its relative component outside the span of the kept rows at t0 (below the tolerance)."""

    def __str__(self) -> str:
        return str(self.row)


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
    removed: tuple[Removed, ...] = ()
    """Rows of an over-constrained file dependent at t0, removed so that Phi is square."""
    mobility: int | None = None
    """An over-constrained file's freedoms at t0 by the rank of its joints' rows and its
    bodies' normalisation rows (the count, ``dof``, cannot judge it); None for every other
    file."""
    dynamics: dynamics.Dynamics | None = None
    """Mass terms, applied forces, efforts and reactions; None for a file without masses
    and forces (inverse dynamics, symbolic.dynamics)."""
    inputs: tuple[Input, ...] = ()
    """The driver functions written ``input``: Phi holds their values u, Phi_t their rates du,
    Gamma their accelerations ddu (symbols of each Input)."""
    input_values: tuple[float, ...] = ()
    """Each input's value that the file's q0 satisfies (for generation-time samples)."""
    senses: tuple[tuple[str, sp.Expr], ...] = ()
    """(label, expression) of what the rows leave ambiguous (PairType.senses): positive at
    every genuine assembly (the runtime's search counts no other)."""

    @property
    def input_names(self) -> tuple[str, ...]:
        return tuple(item.name for item in self.inputs)

    @property
    def input_lengths(self) -> tuple[int, ...]:
        """The inputs (indices into u[]) that are a length (PairType.lengths: a distance
        driver's f), never negative: the row holds its square."""
        lengths = name_checks.length_inputs(self.mechanism)
        return tuple(k for k, name in enumerate(self.input_names) if name in lengths)

    @property
    def input_places(self) -> tuple[str, ...]:
        """Where each input is in the file: ``drivers[0] angle theta``, ``... f[1]``."""
        drivers = self.mechanism.drivers
        return tuple(f"drivers[{i.driver}] {drivers[i.driver].type} {i.key}"
                     + ("" if i.component is None else f"[{i.component}]") for i in self.inputs)

    @property
    def code_parameters(self) -> tuple[sp.Symbol, ...]:
        """The generated functions' p[]: the parameters, then every input's u, du, ddu."""
        return (self.p + tuple(i.u for i in self.inputs) + tuple(i.du for i in self.inputs)
                + tuple(i.ddu for i in self.inputs))

    @property
    def code_p_values(self) -> tuple[float, ...]:
        """Nominal values of code_parameters: inputs at input_values, at rest."""
        return self.p_values + self.input_values + (0.0,) * (2 * len(self.inputs))

    @property
    def name(self) -> str:
        return self.mechanism.name

    def __reduce__(self) -> tuple[Any, tuple[bytes]]:  # SymPy's evaluation off on load
        return pickling.restore, (pickling.dumps(self),)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(symbol.name for symbol in self.p)

    @property
    def dof(self) -> int:
        return validate.degrees_of_freedom(self.mechanism)

    def pattern(self) -> list[tuple[int, int]]:
        """Structural non-zeros of Phi_q as (row, column), row-major, as ints (not Integers)."""
        return sorted((int(r), int(c)) for r, c in self.phi_q.todok())


def derive(mech: Mechanism | str | Path) -> System:
    """Derive Phi, Phi_q, Phi_t and Gamma of a mechanism (a Mechanism or a file path)."""
    if not isinstance(mech, Mechanism):
        try:
            return derive(validate.load(mech))
        except MechanismError as error:
            raise validate.locate(error, mech) from None
    symbols = make_symbols(mech)
    ctx = (spatial.SpatialContext if mech.is_spatial else Context)(mech, symbols)
    phi, rows = _constraint_rows(mech, ctx)
    if mech.is_spatial:
        phi, rows = _normalised(mech, ctx, phi, rows)
    values = mech.parameter_values()
    p_values = tuple(values[s.name] for s in symbols.p)
    nominal = dict(zip(symbols.p, p_values))
    q0 = _initial_guess(mech, ctx, nominal)
    time_grid = _time_grid(mech, ctx, nominal)
    column = {q: k for k, q in enumerate(symbols.q)}
    # each row's non-zeros of Phi_q, taken once: the redundancy analysis evaluates them, the
    # rows kept keep them (a row's derivatives are its expression's, whatever its place)
    nonzeros = {row: row_jacobian(row, column, symbols.q) for row in phi}
    phi, rows, removed, mobility = _remove_redundant(phi, rows, symbols, p_values, q0,
                                                     time_grid, motion_spec.has_masses(mech),
                                                     [nonzeros[row] for row in phi])
    # the rank decides whether the forces move it (symbolic.motion.moves_under_forces)
    motion_spec.refuse_keys(mech, motion_spec.moves(len(phi), len(symbols.q)))
    jacobian: dict[tuple[int, int], sp.Expr] = {}
    phi_t, gamma = [], []
    memory = Memory()
    for r, row in enumerate(phi):
        entries = nonzeros[row]
        row_t = diff(row, symbols.t)
        jacobian.update({(r, k): at_tau(value, symbols) for k, value in entries.items()})
        phi_t.append(at_tau(row_t, symbols))
        gamma.append(at_tau(row_gamma(row, entries, row_t, symbols, memory), symbols))
    phi = [at_tau(row, symbols) for row in phi]
    size = len(symbols.q)
    # as many rows as equations: fewer than columns where the forces move free freedoms
    phi_q = sp.ImmutableSparseMatrix(len(phi), size, jacobian)
    placed = _placed(mech, ctx)
    return System(
        mechanism=mech, q=symbols.q, dq=symbols.dq, t=symbols.t, p=symbols.p,
        p_values=p_values, coordinates=symbols.coordinates,
        phi=sp.ImmutableMatrix(phi), phi_q=phi_q,
        phi_t=sp.ImmutableMatrix(phi_t), gamma=sp.ImmutableMatrix(gamma), rows=rows,
        q0=q0,
        points=tuple((body, name, sp.ImmutableMatrix(ctx.local(body, name)))
                     for body, spec in mech.bodies.items() for name in spec.points),
        placed=placed, time_grid=time_grid,
        phi_p=parameter_jacobian(phi, symbols.p), removed=removed, mobility=mobility,
        dynamics=(_dynamics(mech, ctx, phi_q, rows, placed,
                            _removed_jacobians(removed, column, symbols))
                  if has_dynamics(mech) else None),
        inputs=symbols.inputs, senses=_senses(mech, ctx),
        input_values=input_values(phi, symbols, {**dict(zip(symbols.q, q0)), **nominal,
                                                  symbols.t: time_grid[0]}),
    )


def _dynamics(mech: Mechanism, ctx: Context, phi_q: sp.SparseMatrix, rows: tuple[Row, ...],
              placed: tuple[Placed, ...],
              removed: tuple[tuple[Row, sp.Matrix], ...]) -> dynamics.Dynamics:
    """Inverse dynamics, planar or spatial (the latter given the drivers as their rows were
    written, to find each row's driven function)."""
    if not mech.is_spatial:
        return dynamics.derive(mech, ctx, phi_q, rows, placed, removed)
    drivers = [with_inputs(c, ctx.symbols, k) for k, c in enumerate(mech.drivers)]
    return dynamics3d.derive(mech, ctx, phi_q, rows, placed, drivers,  # type: ignore[arg-type]
                             removed)


def _remove_redundant(phi: list[sp.Expr], rows: tuple[Row, ...], symbols: Symbols,
                      p_values: tuple[float, ...], q0: tuple[float, ...],
                      grid: tuple[float, float, float], masses: bool = False,
                      entries: list[dict[int, sp.Expr]] | None = None
                      ) -> tuple[list[sp.Expr], tuple[Row, ...], tuple[Removed, ...],
                                 int | None]:
    """A file with more equations than coordinates: the rows dependent at the assembled t0
    removed (symbolic.redundancy), joint rows before the others, later before earlier. A file
    with as many (the DOF count passed) is left as it is, untouched, unless its bodies have
    ``masses`` and one of its rows is dependent: Bricard's linkage has as many equations as
    coordinates, one of them dependent, and moves under its forces."""
    square = len(phi) == len(symbols.q)
    if len(phi) < len(symbols.q) or (square and (not masses or symbols.inputs)):
        return phi, rows, (), None
    if symbols.inputs:
        # the rank is judged at an assembled t0, which inputs known only at run time lack
        raise MechanismError(
            f"over-constrained: {len(phi)} equations for {len(symbols.q)} coordinates, and "
            "the file has input drivers", ("drivers",),
            "Redundant equations are found at the assembled start, which needs drivers "
            "that are functions of t: remove the repeated joint, or drive it by a function.")
    joints = [k for k, row in enumerate(rows) if row.section == "joints"]
    priority = [k for k, row in enumerate(rows) if row.section != "joints"] + joints
    # The freedoms are what every row a coordinate is subject to leaves: the joints' and the
    # Euler parameters' normalisation (without it each body keeps its parameters' scale).
    subject = sorted(joints + [k for k, row in enumerate(rows)
                               if row.section == NORMALISATION[0]])
    try:
        # A rank short at t0 is checked again half a step later (t0 singular, or a freedom).
        t0, t1, dt = grid
        found = redundancy.analyse(phi, symbols.q, symbols.t, symbols.p, p_values, q0, t0,
                                   priority, t0 + 0.5 * min(dt, t1 - t0), subject, masses,
                                   entries=entries)
    except redundancy.Refusal as refusal:
        if square:  # judged by the run, as any square file's start is
            return phi, rows, (), None
        row = None if refusal.row is None else rows[refusal.row]
        where = (row.section, row.index) if row else ("joints",)
        named = f" ({row})" if row else ""
        raise MechanismError(f"over-constrained: {refusal.message}{named}", where,
                             refusal.hint) from None
    if square and not found.removed:
        return phi, rows, (), None
    removed = tuple(Removed(rows[k], phi[k], k, d)
                    for k, d in zip(found.removed, found.dependency))
    return ([phi[k] for k in found.kept], tuple(rows[k] for k in found.kept), removed,
            found.mobility)


def _removed_jacobians(removed: tuple[Removed, ...], column: dict[sp.Symbol, int],
                       symbols: Symbols) -> tuple[tuple[Row, sp.Matrix], ...]:
    """Each removed row's label and 1 x N Jacobian (for its share of the reactions)."""
    found = []
    for item in removed:
        jacobian = sp.zeros(1, len(symbols.q))
        for k, value in row_jacobian(item.phi, column, symbols.q).items():
            jacobian[0, k] = value
        found.append((item.row, jacobian))
    return tuple(found)


def _constraint_rows(mech: Mechanism, ctx: Context) -> tuple[list[sp.Expr], tuple[Row, ...]]:
    """Phi and its row labels: joints in file order, then drivers (README, "Row order")."""
    phi: list[sp.Expr] = []
    rows: list[Row] = []
    for section in pairs.SECTIONS:
        for index, constraint in enumerate(getattr(mech, section)):
            kind = pairs.of(constraint)
            if section == "drivers":
                constraint = with_inputs(constraint, ctx.symbols, index)
            equations = _equations(kind, constraint, ctx, (section, index))
            parts = kind.rows or tuple(f"equation {k}" for k in range(len(equations)))
            bodies = kind.joined_bodies(constraint) or _bodies_touched(equations, ctx)
            phi.extend(equations)
            rows.extend(Row(section, index, constraint.type, bodies, part, constraint.name)
                        for part in parts)
    return phi, tuple(rows)


def _senses(mech: Mechanism, ctx: Context) -> tuple[tuple[str, sp.Expr], ...]:
    """Every pair's senses (PairType.senses), labelled as its rows' owner (Row.owner) with
    ``(sense)``, in row order."""
    found: list[tuple[str, sp.Expr]] = []
    for section in pairs.SECTIONS:
        for index, constraint in enumerate(getattr(mech, section)):
            kind = pairs.of(constraint)
            if kind.senses is None:
                continue
            if section == "drivers":
                constraint = with_inputs(constraint, ctx.symbols, index)
            owner = Row(section, index, constraint.type,
                        kind.joined_bodies(constraint) or (), "sense", constraint.name)
            found.extend((str(owner), at_tau(expr, ctx.symbols))
                         for expr in kind.senses(constraint, ctx))
    return tuple(found)


def _equations(kind: Any, constraint: Any, ctx: Context, path: tuple[str, int]
               ) -> list[sp.Expr]:
    """A constraint's rows; a constant of its geometry that has no double value (an axis
    component so small or so large that its exact square is beyond a double) refused at the
    constraint, where the file is at fault."""
    try:
        return list(kind.equations(constraint, ctx))
    except ExpressionError as error:
        raise MechanismError(f"its geometry cannot be computed in double precision: "
                             f"{error.message}", path,
                             "Give its points and directions in numbers a double holds with "
                             "room to spare (between about 1e-150 and 1e150 in magnitude, or "
                             "0), e.g. in other units.") from None


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


def _initial_guess(mech: Mechanism, ctx: Context,
                   values: dict[sp.Symbol, float]) -> tuple[float, ...]:
    """The bodies' q0, then the first guesses (s0) of the pairs' own coordinates."""
    raws = [raw for body in mech.bodies.values() for raw in body.q0]
    raws += [raw for _, raw in extra_coordinates(mech)]
    return tuple(float(ctx.expr(raw).subs(values)) for raw in raws)
