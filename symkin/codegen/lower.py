"""Stage 3 — codegen: common subexpressions and printing, from a System to plain strings.

Everything after this module works on plain data (strings, index lists, op counts): the
templates never see a SymPy object. A backend is a printer subclass of one of SymPy's code
printers; the printers map the mechanism's symbols to the argument arrays of the generated
functions (``q[i]``, ``dq[i]``, ``p[k]``, ``t``) in ``_print_Symbol``, never by editing printed
text. Names from the mechanism file are first replaced by internal symbols (``_q3``...), so a
user's name can never collide with a temporary (``w0``...) or reach the generated code.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import sympy as sp
from sympy.printing.codeprinter import CodePrinter

from symkin.codegen import backends, sample, symbols
from symkin.codegen.lu_plan import LUPlan
from symkin.codegen.symbols import symbol_text
from symkin.errors import BuildError
from symkin.symbolic import planar as constraints
from symkin.symbolic import symbols as symbols_module
from symkin.symbolic.derivation import System

REAL_TYPES = ("double", "float")
# The linear algebra behind the C solver: templates/c/linalg.*.j2 (dense LU with partial
# pivoting) or templates/c/sparse_lu.*.j2 (a sparse LU whose pivot order is fixed here).
LINALG = ("dense", "sparse")
DEFAULT_LINALG = "sparse"

# The routines every backend emits, in output order, and the arguments each one takes.
ROUTINE_ARGUMENTS: dict[str, tuple[str, ...]] = {
    "phi": ("q", "t", "p"),
    "phi_q": ("q", "t", "p"),
    "phi_t": ("q", "t", "p"),
    "gamma": ("q", "dq", "t", "p"),
    "points": ("p",),
    "phi_p": ("q", "t", "p"),
}

# Characters allowed in a comment of generated code; anything else becomes '?'.
_COMMENT_UNSAFE = re.compile(r"[^A-Za-z0-9_.,:;()\[\] +=-]")


@dataclass(frozen=True)
class Routine:
    """One generated function as plain text.

    Attributes:
        name: ``phi``, ``phi_q`` (the non-zeros in pattern order), ``phi_t``, ``gamma``,
            ``points``.
        arguments: the argument names, in order.
        unused: the arguments its body does not read (C marks them ``(void)``).
        temporaries: ``(name, expression)`` pairs, in evaluation order.
        outputs: one expression per output slot.
        ops: operation count after CSE (SymPy's ``count_ops``).
    """

    name: str
    arguments: tuple[str, ...]
    unused: tuple[str, ...]
    temporaries: tuple[tuple[str, str], ...]
    outputs: tuple[str, ...]
    ops: int


@dataclass(frozen=True)
class Code:
    """Everything the templates of one backend need, as plain data."""

    backend: str
    real: str
    cse: bool
    name: str
    spec_sha256: str
    nq: int
    n_params: int
    coordinates: tuple[str, ...]
    parameter_names: tuple[str, ...]
    p_values: tuple[float, ...]
    q0: tuple[float, ...]
    time_grid: tuple[float, float, float]
    rows: tuple[str, ...]
    pattern_rows: tuple[int, ...]
    pattern_cols: tuple[int, ...]
    points: tuple[tuple[str, str], ...]
    routines: tuple[Routine, ...]
    ops_before_cse: dict[str, int]
    linalg: str = DEFAULT_LINALG
    lu_plan: LUPlan | None = None
    """The sparse LU's pivot order and steps (C with sparse linear algebra only)."""
    phi_p_rows: tuple[int, ...] = ()
    phi_p_cols: tuple[int, ...] = ()
    """The structural non-zeros of Phi_p (row, parameter), row-major."""

    @property
    def nnz(self) -> int:
        return len(self.pattern_rows)

    @property
    def nnz_p(self) -> int:
        return len(self.phi_p_rows)

    @property
    def npoints(self) -> int:
        return len(self.points)

    @property
    def ops(self) -> dict[str, int]:
        """Operation count of each routine after CSE (when enabled)."""
        return {routine.name: routine.ops for routine in self.routines}

    def routine(self, name: str) -> Routine:
        return next(routine for routine in self.routines if routine.name == name)


def _printer(backend: str, real: str) -> CodePrinter:
    return backends.get(backend).printer(real)


# ----- lowering ------------------------------------------------------------------------------

def lower(system: System, backend: str = "c", real: str = "double", cse: bool = True,
          linalg: str = DEFAULT_LINALG) -> Code:
    """Turn a System into the plain data the templates of ``backend`` render.

    Args:
        system: the derived kinematics.
        backend: ``"c"`` or ``"numpy"``.
        real: ``"double"`` or ``"float"`` (C only).
        cse: eliminate common subexpressions within each routine.
        linalg: ``"sparse"`` (default) or ``"dense"``, the LU behind the C solver.

    Raises:
        BuildError: an unknown backend or real type, or an expression the printer cannot print.
    """
    _check_options(backend, real, linalg)
    internal = symbols.internal_symbols(system)
    pattern = system.pattern()
    p_pattern = parameter_pattern(system)
    expressions = _routine_expressions(system, pattern, p_pattern)
    printer = _printer(backend, real)
    routines = tuple(
        _routine(name, [symbols.prepare(e, internal) for e in exprs], printer, cse)
        for name, exprs in expressions.items())
    return Code(
        backend=backend, real=real, cse=cse, name=system.name,
        spec_sha256=system.mechanism.spec_hash(), nq=len(system.q), n_params=len(system.p),
        coordinates=system.coordinates, parameter_names=system.parameter_names,
        p_values=tuple(float(v) for v in system.p_values), q0=tuple(system.q0),
        time_grid=system.time_grid, rows=tuple(str(row) for row in system.rows),
        pattern_rows=tuple(r for r, _ in pattern), pattern_cols=tuple(c for _, c in pattern),
        points=point_names(system), routines=routines,
        ops_before_cse={name: _count_ops(exprs) for name, exprs in expressions.items()},
        linalg=linalg,
        phi_p_rows=tuple(r for r, _ in p_pattern), phi_p_cols=tuple(c for _, c in p_pattern),
        lu_plan=(sample.sparse_lu_plan(system, pattern)
                 if backend == "c" and linalg == "sparse" else None),
    )


def _check_options(backend: str, real: str, linalg: str) -> None:
    if linalg not in LINALG:
        raise BuildError(f"unknown linear algebra {linalg!r}; choose 'dense' or 'sparse'")
    if backend not in backends.NAMES:
        raise BuildError(f"unknown backend {backend!r}; choose one of {', '.join(backends.NAMES)}")
    if real not in REAL_TYPES:
        raise BuildError(f"unknown real type {real!r}; choose 'double' or 'float'")
    if backend == "numpy" and real != "double":
        raise BuildError("the NumPy backend computes in double precision; use real='double' "
                         "(real='float' is for the C backend)")


def parameter_pattern(system: System) -> list[tuple[int, int]]:
    """Structural non-zeros of Phi_p as (row, parameter), row-major."""
    return [] if system.phi_p is None else sorted(system.phi_p.todok())


def _routine_expressions(system: System, pattern: Sequence[tuple[int, int]],
                         p_pattern: Sequence[tuple[int, int]]) -> dict[str, list[sp.Expr]]:
    return {
        "phi": list(system.phi),
        "phi_q": [system.phi_q[r, c] for r, c in pattern],
        "phi_t": list(system.phi_t),
        "gamma": list(system.gamma),
        "points": [component for vector in point_vectors(system) for component in vector],
        "phi_p": [] if system.phi_p is None else [system.phi_p[r, k] for r, k in p_pattern],
    }


def point_names(system: System) -> tuple[tuple[str, str], ...]:
    """Every named point as (body, point), bodies and points in file order."""
    return tuple((body_name, point) for body_name, body in system.mechanism.bodies.items()
                 for point in body.points)


def point_vectors(system: System) -> list[tuple[sp.Expr, sp.Expr]]:
    """The local vector s of every named point, as expressions of the parameters."""
    ctx = constraints.Context(system.mechanism, symbols_module.make_symbols(system.mechanism))
    # make_symbols creates equal symbols (same names and assumptions) to the System's.
    return [tuple(ctx.local(body, point)) for body, point in point_names(system)]


def _routine(name: str, exprs: list[sp.Expr], printer: Any, cse: bool) -> Routine:
    temporaries: list[tuple[sp.Symbol, sp.Expr]] = []
    if cse and exprs:
        temporaries, exprs = sp.cse(exprs, symbols=sp.numbered_symbols("w", real=True),
                                    order="canonical")
        temporaries, exprs = _inline_trivial(temporaries, exprs)
    used = set().union(*(e.free_symbols for e in [*exprs, *(v for _, v in temporaries)]))
    used_names = {symbol_text(s.name).split("[")[0] for s in used}
    return Routine(
        name=name, arguments=ROUTINE_ARGUMENTS[name],
        unused=tuple(a for a in ROUTINE_ARGUMENTS[name] if a not in used_names),
        temporaries=tuple((str(s), _print(printer, v)) for s, v in temporaries),
        outputs=tuple(_print(printer, e) for e in exprs),
        ops=_count_ops([*exprs, *(v for _, v in temporaries)]),
    )


def _inline_trivial(temporaries: list[tuple[sp.Symbol, sp.Expr]], exprs: list[sp.Expr]
                    ) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """Put back temporaries that only name a symbol or its negative (``w0 = -q[7]``)."""
    kept: list[tuple[sp.Symbol, sp.Expr]] = []
    trivial: dict[sp.Symbol, sp.Expr] = {}
    for symbol, value in temporaries:
        value = value.xreplace(trivial)
        # (a relational temporary, e.g. from Max(t, 1 - t), has no negative)
        if value.is_Atom or (isinstance(value, sp.Expr) and (-value).is_Atom):
            trivial[symbol] = value
        else:
            kept.append((symbol, value))
    return kept, [e.xreplace(trivial) for e in exprs]


def _print(printer: Any, expr: sp.Expr) -> str:
    try:
        return str(printer.doprint(expr))
    except (TypeError, ValueError, NotImplementedError) as error:
        raise BuildError(f"cannot generate code for the expression {expr}: {error}") from None


def _count_ops(exprs: Iterable[sp.Expr]) -> int:
    return int(sum(sp.count_ops(e) for e in exprs))


def comment(text: str) -> str:
    """Text from a mechanism file made safe for a C or Python comment (one line, no ``*/``)."""
    return _COMMENT_UNSAFE.sub("?", text)[:120]
