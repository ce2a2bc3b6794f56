"""||Phi_q||_1 as straight-line C: the column sums of |non-zeros| with the known entries folded.

The generated solver needs the 1-norm of Phi_q at every solved point (the condition estimate).
A loop over the non-zeros that adds into column sums through an index table costs a load, an
indexed read-modify-write and a branch per entry; here each column's sum is one expression in
the order of the non-zeros (the order of the loop and of runtime.solving.accuracy.norm1), so the
bits are the same. An entry that is a number at every state contributes its known |value|: a run of
them at the start of a column is added here in IEEE double (the operations C would do), the
others are literals in place; a column of numbers only is known outright and joins the starting
value of the maximum.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

PART_TERMS = 250
"""Terms per generated C function (as lu_code.PART_OPS: gcc's optimiser is superlinear in
function size)."""


def _column(terms: list[int], constants: Sequence[float | None], literal: Callable[[float], str],
            fabs: str) -> tuple[float, str | None]:
    """(known sum, None) for a column of numbers, else (0, its C expression)."""
    known = 0.0
    start = 0
    while start < len(terms):
        c = constants[terms[start]]
        if c is None:
            break
        known = known + abs(c)
        start += 1
    if start == len(terms):
        return known, None
    parts = [literal(known)] if known != 0.0 else []
    for e in terms[start:]:
        c = constants[e]
        parts.append(f"{fabs}(nz[{e}])" if c is None else literal(abs(c)))
    return 0.0, " + ".join(parts)


def norm1_context(cols: Sequence[int], nq: int, constants: Sequence[float | None] | None,
                  literal: Callable[[float], str], real: str,
                  part_terms: int = PART_TERMS) -> dict[str, Any]:
    """The column sums of Phi_q for ``templates/solver.c.j2`` (key ``norm1``).

    Args:
        cols: the column of each non-zero, in pattern order.
        nq: the number of columns.
        constants: per non-zero, its value when it is a number at every state (None: not
            known); used in double precision only (a float build rounds literals differently).
        literal: the C literal of a number in the real type.
        real: the C real type.
        part_terms: terms per generated function.
    """
    known = constants if constants is not None and real == "double" else [None] * len(cols)
    fabs = "fabsf" if real == "float" else "fabs"
    terms: list[list[int]] = [[] for _ in range(nq)]
    for e, j in enumerate(cols):
        terms[j].append(e)
    start = 0.0
    columns: list[tuple[int, str, int]] = []
    for j in range(nq):
        value, expression = _column(terms[j], known, literal, fabs)
        if expression is None:
            start = max(start, value)
        else:
            columns.append((j, expression, len(terms[j])))
    parts: list[list[tuple[int, str]]] = []
    size = 0
    for j, expression, count in columns:
        if not parts or (parts[-1] and size + count > part_terms):
            parts.append([])
            size = 0
        parts[-1].append((j, expression))
        size += count
    return {"start": literal(start), "parts": parts}
