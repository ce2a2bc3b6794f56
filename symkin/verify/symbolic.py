"""The symbolic route: SymPy expressions or matrices compared entry by entry.

Equal when their difference simplifies to zero, with a numeric fallback where simplification
gives up.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from symkin.errors import SymkinError
from symkin.symbolic.derivation import System

# ----- the symbolic route ---------------------------------------------------------------------

@dataclass(frozen=True)
class EntryComparison:
    """The verdict on one entry: equal (and how it was decided) or different (and where)."""

    row: int
    column: int
    derived: sp.Expr
    hand: sp.Expr
    equal: bool | None  # None: neither simplification nor sampling could decide
    method: str  # "identical", "simplification", "numeric" or "counterexample"
    point: dict[sp.Symbol, float] | None = None  # a point where they differ
    derived_value: complex | None = None
    hand_value: complex | None = None


@dataclass(frozen=True)
class Comparison:
    """The outcome of :func:`compare`, entry by entry."""

    shape: tuple[int, int]
    entries: tuple[EntryComparison, ...]
    row_labels: tuple[str, ...] | None = None  # the owners of the rows, given a System
    column_labels: tuple[str, ...] | None = None  # the coordinates of the columns

    @property
    def equal(self) -> bool:
        return all(entry.equal for entry in self.entries)

    @property
    def differences(self) -> tuple[EntryComparison, ...]:
        return tuple(entry for entry in self.entries if not entry.equal)

    def __bool__(self) -> bool:
        return self.equal

    def text(self) -> str:
        if self.equal:
            return f"all {len(self.entries)} entries are equal\n"
        lines = []
        for e in self.differences:
            where = f"[{e.row}]" if self.shape[1] == 1 else f"[{e.row}, {e.column}]"
            if self.row_labels:
                where += f" {self.row_labels[e.row]}"
            if self.column_labels and self.shape[1] > 1:
                where += f", d/d {self.column_labels[e.column]}"
            if e.equal is None:
                lines.append(f"{where}: undecided: {sp.sstr(e.derived)} vs {sp.sstr(e.hand)}")
                continue
            point = ", ".join(f"{s}={v:.6g}" for s, v in (e.point or {}).items())
            lines.append(f"{where}: derived {sp.sstr(e.derived)} = {_num(e.derived_value)}, "
                         f"hand {sp.sstr(e.hand)} = {_num(e.hand_value)} at {point}")
        return "\n".join(lines) + "\n"


def _num(value: complex | None) -> str:
    if value is None:
        return "?"
    return f"{value.real:.12g}" if value.imag == 0 else f"{value:.6g}"


def compare(derived: Any, hand: Any, *, system: System | None = None, samples: int = 8,
            seed: int = 0, tolerance: float = 1e-12) -> Comparison:
    """Compare two SymPy expressions or matrices entry by entry.

    An entry is equal when the difference is identically zero or simplifies to zero; when
    simplification does not get there, it is evaluated at ``samples`` random points (30 digits):
    a point where the two differ by more than ``tolerance`` (relative) proves them different,
    agreement at every point counts as equal ("numeric"). Symbols of ``hand`` that have the
    name of a symbol of ``derived`` but other assumptions (``Symbol("a")`` against
    ``Symbol("a", real=True)``) are taken to be that symbol. Given the ``system`` the
    matrices come from, differences are labelled with the row's joint or driver and the
    column's coordinate.

    Raises:
        SymkinError: the shapes differ or an argument is not a SymPy expression or matrix.
    """
    left, right = _as_matrix(derived, "derived"), _as_matrix(hand, "hand")
    if left.shape != right.shape:
        raise SymkinError(f"the derived matrix is {left.shape[0]} x {left.shape[1]} but the "
                          f"hand one is {right.shape[0]} x {right.shape[1]}")
    right = right.xreplace(_same_names(left, right))
    rng = np.random.default_rng(seed)
    entries = tuple(_compare_entry(r, k, left[r, k], right[r, k], rng, samples, tolerance)
                    for r in range(left.rows) for k in range(left.cols))
    rows = columns = None
    if system is not None and left.rows == len(system.rows):
        rows = tuple(str(row) for row in system.rows)
        columns = system.coordinates if left.cols == len(system.q) else None
    return Comparison(left.shape, entries, rows, columns)


def _as_matrix(value: Any, which: str) -> sp.ImmutableMatrix:
    if isinstance(value, sp.MatrixBase):
        return sp.ImmutableMatrix(value)
    if isinstance(value, (sp.Basic, int, float)):
        return sp.ImmutableMatrix([[sp.sympify(value)]])
    raise SymkinError(f"the {which} argument is a {type(value).__name__}; give a SymPy "
                      "expression or matrix")


def _same_names(left: sp.MatrixBase, right: sp.MatrixBase) -> dict[sp.Symbol, sp.Symbol]:
    ours = {s.name: s for s in left.free_symbols if isinstance(s, sp.Symbol)}
    return {s: ours[s.name] for s in right.free_symbols
            if isinstance(s, sp.Symbol) and s.name in ours and ours[s.name] != s}


def _compare_entry(row: int, column: int, d: sp.Expr, h: sp.Expr, rng: np.random.Generator,
                   samples: int, tolerance: float) -> EntryComparison:
    def entry(equal: bool | None, method: str, **found: Any) -> EntryComparison:
        return EntryComparison(row, column, d, h, equal, method, **found)

    difference = sp.sympify(d - h)
    if difference == 0:
        return entry(True, "identical")
    evidence = _counterexample(d, h, rng, samples, tolerance)
    if evidence is not None and evidence[0] is not None:
        point, dv, hv = evidence
        return entry(False, "counterexample", point=point, derived_value=dv, hand_value=hv)
    if sp.simplify(difference) == 0:
        return entry(True, "simplification")
    # Every sampled point agreed (or none could be evaluated): a numeric verdict.
    return entry(True if evidence is not None else None, "numeric")


def _counterexample(d: sp.Expr, h: sp.Expr, rng: np.random.Generator, samples: int,
                    tolerance: float) -> tuple[Any, Any, Any] | None:
    """(point, derived value, hand value) where they differ; (None,)*3 if all agree; None if
    no sample could be evaluated."""
    symbols = sorted((d - h).free_symbols | d.free_symbols | h.free_symbols, key=str)
    evaluated = 0
    for _ in range(samples):
        point = {s: _random_value(s, rng) for s in symbols}
        exact = {s: sp.Float(v, 30) for s, v in point.items()}
        try:
            dv = complex(sp.sympify(d).evalf(30, subs=exact))
            hv = complex(sp.sympify(h).evalf(30, subs=exact))
        except (TypeError, ValueError, ZeroDivisionError):
            continue
        if not (np.isfinite(dv) and np.isfinite(hv)):
            continue
        evaluated += 1
        if abs(dv - hv) > tolerance * max(abs(dv), abs(hv), 1.0):
            return point, dv, hv
    return (None, None, None) if evaluated else None


def _random_value(symbol: sp.Symbol, rng: np.random.Generator) -> float:
    if symbol.is_integer:
        return float(rng.integers(1, 5))
    if symbol.is_positive or symbol.is_nonnegative:
        return float(rng.uniform(0.2, 2.0))
    if symbol.is_negative or symbol.is_nonpositive:
        return float(-rng.uniform(0.2, 2.0))
    return float(rng.uniform(-2.0, 2.0))
