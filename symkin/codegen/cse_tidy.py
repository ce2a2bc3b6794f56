"""Around lower's CSE: trivial temporaries put back, and op counts; apart to keep lower short."""

from __future__ import annotations

from collections.abc import Iterable

import sympy as sp


def _ops_before_cse(expressions: dict[str, list[sp.Expr]], fused: dict[str, list[sp.Expr]],
                    shared: list[sp.Expr]) -> dict[str, int]:
    """SymPy's count_ops of every routine before CSE; the fused Phi and Phi_q is the sum of
    its pieces (count_ops of a list is the sum over it), so it is not counted twice."""
    counts = {name: _count_ops(exprs) for name, exprs in expressions.items()}
    counts["phi_phi_q"] = counts["phi"] + counts["phi_q"] + _count_ops(shared)
    counts.update({name: _count_ops(exprs) for name, exprs in fused.items()
                   if name != "phi_phi_q"})
    return counts


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


def _count_ops(exprs: Iterable[sp.Expr]) -> int:
    return int(sum(sp.count_ops(e) for e in exprs))
