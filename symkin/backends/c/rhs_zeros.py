"""The step's rhs-sparse solves: which rows of Phi_t and Gamma are a literal 0, and which
entries of the straight-line solve are then +-0 whatever the factors hold.

The step solves Phi_q dq = -Phi_t and Phi_q ddq = Gamma with the same factors; many rows of
both right-hand sides are 0 at every state (a revolute's Phi_t, a joint on the ground's
Gamma). The generated solve takes those rows as the literal 0 instead of reading them, and the
C compiler folds what follows by IEEE rules (signed zeros kept), so each entry keeps the bits
the full solve gives it. An entry that only ever meets those zeros, signs and literal
numbers is +-0 for every factorization: its |x| adds nothing to the solve's max and sum, and
is not taken. An entry that meets a factor entry (``v[...]``, ``inv[...]``) is not: a factor
could be infinite, and 0 * inf is the NaN the finite test must see.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any

from symkin.codegen.lower import Code

_X = re.compile(r"x\[(\d+)\]")
_FACTOR = re.compile(r"\b(v|inv)\[")


def zero_rows(code: Code, name: str) -> list[int]:
    """The rows of routine ``name``'s output printed as a literal +0: a generated kernel
    writes +0 there at every state, and dividing +0 by a row's unit leaves it +0. None where
    the routine is not generated."""
    if not any(routine.name == name for routine in code.routines):
        return []
    return [row for row, text in enumerate(code.routine(name).outputs) if _plus_zero(text)]


def _plus_zero(text: str) -> bool:
    """True for a printed number that is +0 (``0``, ``0.0``, ``0.0F``), never for an
    expression or a -0."""
    digits = text.strip().rstrip("fF")
    return bool(digits) and set(digits) <= set("0.") and "0" in digits


def known_zeros(lu: Mapping[str, Any], rows: Sequence[int]) -> list[int]:
    """The positions k of the straight-line solve's x that are +-0 after the solve for every
    factorization when the rows ``rows`` of b are 0 (none where the row permutation is a
    table: the solve then reads every row)."""
    if lu["style"] != "straight" or lu["perm_tables"]:
        return []
    zero = {k for k, row in enumerate(lu["row_perm"]) if row in rows}
    for k, p in lu["swaps"]:  # a run-time interchange keeps two zeros zero, else neither
        if not (k in zero and p in zero):
            zero -= {k, p}
    for parts, key in ((lu["forward_parts"], "forward"), (lu["backward_parts"], "backward")):
        for part in parts:
            for step in part["steps"]:
                for line in step[key]:
                    _apply(line, zero)
    return sorted(zero)


def _apply(line: str, zero: set[int]) -> None:
    """One statement ``x[t] op= ...`` of the solve: x[t] stays +-0 where it was and every x
    it reads is, and it reads no factor entry."""
    target, *sources = (int(i) for i in _X.findall(line))
    if _FACTOR.search(line) or not all(s in zero for s in sources):
        zero.discard(target)
