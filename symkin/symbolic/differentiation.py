"""The derivatives a derivation takes row by row: a row's structural non-zeros of Phi_q (or of
Phi_p, with respect to the parameters), and its row of

    Gamma = -(Phi_q dq)_q dq - 2 Phi_qt dq - Phi_tt                       (2.74)

Gamma's convective part (Phi_q dq)_q dq is derived as each row's second derivative along dq,
d^2/de^2 Phi(q + e dq, t) at e = 0 (its time derivatives Phi_qt and Phi_tt in t as written):
the derivative of the row's own tree keeps its shape, so a spatial row's A(e) s becomes A(de) s
and its rate, shared by every row of the body, where the sum over pairs of columns spreads each
into its monomials (Gamma's operations after CSE: stewart_fk 1778 -> 729, delta 6826 -> 1856,
the prismatic rows of planar files a few per cent fewer). A row with a piecewise function (a
cam's profile) keeps the sum over columns, where CSE shared more (cam_cycloidal 541, 1180 the
other way), and so does a row whose derivative along dq SymPy leaves unevaluated.

The second derivative is D(D(row)), D the derivative along dq (symbolic.derivatives.Directional:
D q_k = dq_k), with no symbol e substituted and removed, and SymPy's tidying of a second
derivative, factor_terms(signsimp(...)), applied once to the row instead of at every node of
order two (factor_terms as symbolic.tidy makes it: each subtree's once for all the rows): the
spherical four-bar's Gamma 1.1 s -> 0.4 s, stewart_fk's 1.5 s -> 0.4 s, the same operations
after CSE but on delta and delta_fk (+24, 1.3 %: CSE meets other signs of the same factors).
A row with a node that has a derivative rule of its own (Abs) is taken along e.
"""

from __future__ import annotations

import sympy as sp
from sympy.simplify.simplify import signsimp

from symkin.symbolic.derivatives import Differentiator, Directional, Unsupported, diff
from symkin.symbolic.symbols import Symbols
from symkin.symbolic.tidy import Factored


def row_jacobian(row: sp.Expr, column: dict[sp.Symbol, int],
                 q: tuple[sp.Symbol, ...]) -> dict[int, sp.Expr]:
    """The structural non-zeros of one row of Phi_q, keyed by column."""
    touched = sorted(column[s] for s in row.free_symbols if s in column)
    derivatives = {k: diff(row, q[k]) for k in touched}
    return {k: value for k, value in derivatives.items() if value != 0}


def parameter_jacobian(phi: list[sp.Expr], p: tuple[sp.Symbol, ...]
                       ) -> sp.ImmutableSparseMatrix:
    """Phi_p: per row, the derivatives with respect to the parameters the row contains."""
    column = {symbol: k for k, symbol in enumerate(p)}
    entries: dict[tuple[int, int], sp.Expr] = {}
    for r, row in enumerate(phi):
        entries.update({(r, k): value for k, value in
                        row_jacobian(row, column, p).items()})
    return sp.ImmutableSparseMatrix(len(phi), len(p), entries)


class Memory:
    """What the rows of one derivation share: the derivatives along dq of sub-expressions
    met in several rows (a spatial body's rotation matrix in each of its joints' rows), and,
    for the rows D cannot take, the derivatives along one symbol e per symbol. One e serves
    every row: it is the only dummy of its kind in a row, so no ordering of terms depends on
    which it is."""

    def __init__(self) -> None:
        self.along = sp.Dummy("along", real=True)  # as q and dq: Abs(x + e v) has a sign
        self.differentiators: dict[sp.Symbol, Differentiator] = {}
        self.directional: Directional | None = None
        self.factored = Factored()  # factor_terms, each subtree's result kept for every row

    def direction(self, symbols: Symbols) -> Directional:
        """D along dq, made on first use."""
        if self.directional is None:
            self.directional = Directional(dict(zip(symbols.q, symbols.dq)))
        return self.directional


def row_gamma(row: sp.Expr, entries: dict[int, sp.Expr], row_t: sp.Expr,
              symbols: Symbols, memory: Memory | None = None) -> sp.Expr:
    """One row of Gamma = -(Phi_q dq)_q dq - 2 Phi_qt dq - Phi_tt (2.74)."""
    dq, t = symbols.dq, symbols.t
    mixed = sp.Add(*(diff(value, t) * dq[k] for k, value in entries.items()))
    return -convective(row, entries, symbols, memory) - 2 * mixed - diff(row_t, t)


def convective(row: sp.Expr, entries: dict[int, sp.Expr], symbols: Symbols,
               memory: Memory | None = None) -> sp.Expr:
    """(Phi_q dq)_q dq of one row: its second derivative along dq at fixed t, D(D(row))
    with D the derivative along dq, where SymPy gives it in closed form (module docstring);
    else, and for a row with a piecewise function, the sum over its columns.
    ``memory`` shares the derivatives of sub-expressions with the derivation's other rows."""
    q, dq = symbols.q, symbols.dq
    if not row.has(sp.Piecewise):
        memory = memory or Memory()
        second = _twice_along(row, memory.direction(symbols), memory.factored)
        if second is not None:
            return second
        # a node with a rule of its own (Abs, ...): d^2/de^2 Phi(q + e dq, t) by SymPy's
        along = memory.along
        second = diff(row.xreplace({q[k]: q[k] + along * dq[k] for k in entries}), along, 2,
                      memory.differentiators)
        if not second.has(sp.Derivative, sp.Subs):
            return second.xreplace({along: 0})
    velocity = sp.Add(*(value * dq[k] for k, value in entries.items()))
    return sp.Add(*(diff(velocity, q[k]) * dq[k] for k in entries))


def _twice_along(row: sp.Expr, along: Directional, factored: Factored) -> sp.Expr | None:
    """D(D(row)), tidied once as SymPy tidies a second derivative (common factors and signs
    taken out of the sums: fewer operations after CSE); None where a node of the row has a
    derivative rule of its own or SymPy leaves a derivative unevaluated."""
    try:
        second = along.diff(along.diff(row))
    except Unsupported:
        return None
    if second.has(sp.Derivative, sp.Subs):
        return None
    return second if second.is_zero else factored(signsimp(second))
