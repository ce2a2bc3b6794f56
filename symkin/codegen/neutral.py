"""What lowering does the same for every backend, done once per System.

Before a printer sees anything, lowering prepares the expressions (internal symbols, constants
folded), fuses Phi and Phi_q with the shared sines and cosines, eliminates common
subexpressions in parts and counts operations. None of that depends on the backend or its
options, and it is most of a lowering's CPU: generating a second backend of the same System
(the C and NumPy goldens, ``symkin.compile`` for C then NumPy) did it all again. It is kept
here for as long as the System lives (keyed by the object, dropped when it is collected), so
the second backend only prints.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import sympy as sp

from symkin.codegen.cse_tidy import OpCounter, _inline_trivial

Eliminated = tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]
"""One part's temporaries (symbol, value) and its outputs after CSE."""


@dataclass
class Neutral:
    """The backend-neutral lowering of one System.

    Attributes:
        expressions: each routine's expressions as derived (before CSE).
        prepared: the same, prepared for printing (codegen.symbol_printing).
        fused: the fused routines' expressions (codegen.fusion).
        shared: the sines and cosines the fused routine passes on.
        count: one memory of subtrees' operation counts for every routine.
        eliminated: each part's CSE, by routine name, output positions and whether CSE is on.
    """

    expressions: dict[str, list[sp.Expr]]
    prepared: dict[str, list[sp.Expr]]
    fused: dict[str, list[sp.Expr]]
    shared: list[sp.Expr]
    count: OpCounter = field(default_factory=OpCounter)
    eliminated: dict[tuple[str, tuple[int, ...], bool], Eliminated] = field(
        default_factory=dict)

    def part(self, name: str, positions: Sequence[int], values: list[sp.Expr],
             cse: bool) -> Eliminated:
        """The temporaries and outputs of one part (``values``: the routine's expressions
        at ``positions``), its CSE made on first use."""
        key = (name, tuple(positions), cse)
        found = self.eliminated.get(key)
        if found is None:
            temporaries: list[tuple[sp.Symbol, sp.Expr]] = []
            if cse and values:
                temporaries, values = sp.cse(values, symbols=sp.numbered_symbols("w", real=True),
                                             order="canonical")
                temporaries, values = _inline_trivial(temporaries, values)
            found = self.eliminated[key] = (temporaries, values)
        # the caller's own lists: a cached part is never changed through them
        return list(found[0]), list(found[1])


_KEPT: dict[int, Neutral] = {}


def of(system: object, build: Callable[[], Neutral]) -> Neutral:
    """The System's neutral lowering, built by ``build`` on first use and kept until the
    System is collected (its id cannot be reused before then)."""
    key = id(system)
    found = _KEPT.get(key)
    if found is None:
        found = _KEPT[key] = build()
        weakref.finalize(system, _KEPT.pop, key, None)
    return found
