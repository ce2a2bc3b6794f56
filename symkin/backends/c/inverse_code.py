"""||Phi_q^-1||_1 exactly, as straight-line C, where the sparse LU makes that cheap.

The condition estimate at every solved point needs ||Phi_q^-1||_1. Hager's estimator (the
generated ``<prefix>_inverse_norm1``) takes four or five solves that depend on each other,
each a chain of dependent operations, plus loops over the vector between them: on the
crank-slider it doubled the instructions of a whole time step. Yet the columns of
(LU)^-1 are the solves of unit vectors, and with the pivot order fixed at generation time
most of their operations act on a known 0 or 1 or on an entry of Phi_q that is a number: the
columns of a small mechanism's inverse are a few products of the factors' varying entries.

Here the forward and back substitution of the plan (the operations of lu_code's solve, in its
order) run on each unit vector with every value either a number known now or a C expression;
an operation on numbers is done here in IEEE double (as C would do it), a multiplication by 0,
1 or -1 and an addition of 0 vanish, the rest become one temporary each. The result is the
exact norm, max over columns of sum |entries|, not an estimate; it is used only where its
code stays small (``EXACT_OPS``), otherwise None and the solver keeps Hager's estimator.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from typing import Any

from symkin.codegen.lu_plan import LUPlan

EXACT_OPS = 400
"""Most arithmetic operations (products, differences, |.|) of the exact norm's code. The
estimator costs about five solves plus passes over the vector, each waiting for the one
before; the exact columns are independent, so the processor overlaps them. At 260 and 306
operations (andrews_squeezer, all_drivers) the exact code still took 20-25 % fewer
instructions a step than the estimate (bench/README.md); the limit keeps the code short, and
a large mechanism's inverse is dense, far beyond it."""

Value = float | str  # a number known at generation time, or a C expression


class _Code:
    """The straight-line code of the unit vectors' solves: known numbers folded, the rest one
    temporary per operation (the same expression once), with a count of the operations."""

    def __init__(self, real: str, literal: Callable[[float], str]) -> None:
        self.lines: list[str] = []
        self.real = real
        self.lit = literal
        self.count = itertools.count()
        self.named: dict[str, str] = {}  # expression -> its temporary: the same product once
        self.ops = 0

    def _operand(self, value: Value) -> str:
        if isinstance(value, float):
            return f"({self.lit(value)})"
        return f"({value})" if value.startswith("-") else value

    def _temporary(self, expression: str) -> str:
        if expression not in self.named:
            name = self.named[expression] = f"w{next(self.count)}"
            self.lines.append(f"const {self.real} {name} = {expression};")
            self.ops += 1
        return self.named[expression]

    def times(self, a: Value, b: Value) -> Value:
        """a * b."""
        if isinstance(a, float) and isinstance(b, float):
            return a * b
        if a == 0.0 or b == 0.0:
            return 0.0
        if a == 1.0 or b == 1.0:
            return b if a == 1.0 else a
        if a == -1.0 or b == -1.0:
            return self.negated(b if a == -1.0 else a)
        return self._temporary(f"{self._operand(a)} * {self._operand(b)}")

    def minus(self, a: Value, b: Value) -> Value:
        """a - b."""
        if isinstance(a, float) and isinstance(b, float):
            return a - b
        if b == 0.0:
            return a
        if a == 0.0:
            return self.negated(b)
        return self._temporary(f"{self._operand(a)} - {self._operand(b)}")

    def negated(self, a: Value) -> Value:
        if isinstance(a, float):
            return -a
        return a[1:] if a.startswith("-") else f"-{a}"


def _solve_unit(plan: LUPlan, start: int, slot: Callable[[int], Value],
                inverse: Callable[[int], Value], code: _Code) -> list[Value]:
    """L U x = e_start in the permuted order: the forward and back substitution of lu_code."""
    x: list[Value] = [0.0] * plan.n
    x[start] = 1.0
    for s in plan.steps:
        if x[s.k] != 0.0:
            for i, e in s.lower:
                x[i] = code.minus(x[i], code.times(slot(e), x[s.k]))
    for s in reversed(plan.steps):
        for j, e in s.upper:
            x[s.k] = code.minus(x[s.k], code.times(slot(e), x[j]))
        x[s.k] = code.times(x[s.k], inverse(s.k))
    return x


def exact_context(plan: LUPlan, values: Sequence[float | None], inverses: dict[int, float],
                  literal: Callable[[float], str], real: str, fabs: str,
                  limit: int | None = None) -> dict[str, Any] | None:
    """The exact ||Phi_q^-1||_1 for ``templates/solver.c.j2`` (key ``inverse``), or None
    when its code would exceed ``limit`` operations.

    Args:
        plan: the analysed factorization.
        values: per LU slot, its number when known at generation time (after the
            factorization; lu_code.Statements.values), else None (read from ``v[]``).
        inverses: the reciprocals of the constant pivots (lu_code.Statements.inverses).
        literal: the C literal of a number in the real type.
        real: the C real type (its typedef name).
        fabs: the C absolute value of that type.
        limit: the most operations worth generating (default EXACT_OPS).
    """
    limit = EXACT_OPS if limit is None else limit
    code = _Code(real, literal)

    def slot(e: int) -> Value:
        value = values[e]
        return f"v[{e}]" if value is None else float(value)

    def inverse(k: int) -> Value:
        return float(inverses[k]) if k in inverses else f"inv[{k}]"

    start = 0.0
    # the columns' terms -> the largest known part added to them: columns with the same
    # terms (a pair's x and y rows, or columns apart in their numbers only) need one sum, the
    # one of the largest number, since fl(x + a) <= fl(x + b) for a <= b (and a column not
    # finite makes that one not finite too)
    columns: dict[tuple[str, ...], float] = {}
    for unit in range(plan.n):
        entries = _solve_unit(plan, unit, slot, inverse, code)
        known = sum(abs(x) for x in entries if isinstance(x, float))
        terms = tuple(f"{fabs}({x.lstrip('-')})" for x in entries if isinstance(x, str))
        code.ops += len(terms)
        if code.ops > limit:
            return None
        if terms:
            columns[terms] = max(columns.get(terms, 0.0), known)
        else:
            start = max(start, known)
    sums = [" + ".join(terms + ((literal(known),) if known else ()))
            for terms, known in columns.items()]
    return {"lines": code.lines, "sums": sums,
            "start": literal(start), "ops": code.ops}
