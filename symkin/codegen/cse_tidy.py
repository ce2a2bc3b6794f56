"""Around lower's CSE: trivial temporaries put back, and op counts; apart to keep lower short."""

from __future__ import annotations

from collections.abc import Iterable

import sympy as sp
from sympy.core.function import _coeff_isneg
from sympy.core.operations import LatticeOp
from sympy.simplify.radsimp import fraction


def _ops_before_cse(expressions: dict[str, list[sp.Expr]], fused: dict[str, list[sp.Expr]],
                    shared: list[sp.Expr], count: OpCounter) -> dict[str, int]:
    """SymPy's count_ops of every routine before CSE; the fused Phi and Phi_q is the sum of
    its pieces (count_ops of a list is the sum over it), so it is not counted twice."""
    counts = {name: count.many(exprs) for name, exprs in expressions.items()}
    counts["phi_phi_q"] = counts["phi"] + counts["phi_q"] + count.many(shared)
    counts.update({name: count.many(exprs) for name, exprs in fused.items()
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


class OpCounter:
    """``sympy.count_ops`` (``visual=False``), the same numbers, each distinct subtree counted
    once and remembered across every expression it is given.

    SymPy pops the nodes of the tree from a stack, notes the operations of each as symbols
    (``ADD``, ``NEG``, ``MUL``...) and sums them as one SymPy expression; the count is the sum
    of their coefficients. That sum is linear and what a node adds depends on the node alone,
    so the count of a subtree is its own operations plus its arguments' counts: a subtree met
    again (a rotation matrix in every row of a body) is looked up, not walked, and no SymPy
    arithmetic is done on the operation symbols. An expression that is not an ``Expr`` (a
    relational temporary) is counted by SymPy itself."""

    def __init__(self) -> None:
        self._known: dict[sp.Basic, int] = {}

    def many(self, exprs: Iterable[sp.Expr]) -> int:
        """The count of a list: the sum over it, as ``count_ops`` of a list."""
        return sum(self(expr) for expr in exprs)

    def __call__(self, expr: sp.Expr) -> int:
        if not isinstance(expr, sp.Expr) or expr.is_Relational:
            return int(sp.count_ops(expr))
        return self._subtree(expr)

    def _subtree(self, node: sp.Basic) -> int:
        known = self._known.get(node)
        if known is None:
            own, pushed = _popped(node)
            known = own + sum(self._subtree(arg) for arg in pushed)
            self._known[node] = known
        return known


def _popped(a: sp.Basic) -> tuple[int, tuple[sp.Basic, ...]]:
    """What ``count_ops`` does with one node it pops from its stack, its branches in its
    order: the operations it notes (``SUB - ADD`` nets to none) and the nodes it pushes."""
    if a.is_Rational:
        if a is not sp.S.One:
            return (1 if a.p < 0 else 0) + (1 if a.q != 1 else 0), ()
    elif a.is_Mul:
        own = 0
        if _coeff_isneg(a):
            own += 1  # NEG
            a = a.as_two_terms()[1] if a.args[0] is sp.S.NegativeOne else -a
        if _numerator_only(a):
            rest, pushed = _rest(a)
            return own + rest, pushed
        n, d = fraction(a)
        if n.is_Integer:
            return own + 1 + (1 if n < 0 else 0), (d,)  # DIV, and NEG for a negative numerator
        if d is not sp.S.One:
            return own + 1, ((n,) if d.is_Integer else (d, n))
        rest, pushed = _rest(a)
        return own + rest, pushed
    elif a.is_Add:
        args = a.args
        negative = [_coeff_isneg(arg) for arg in args]
        # ADD or SUB between terms; all negative: one NEG more
        own = len(args) - 1 + int(all(negative))
        return own, tuple(-arg if neg else arg for arg, neg in zip(args, negative))
    return _rest(a)


def _numerator_only(a: sp.Basic) -> bool:
    """``fraction(a)`` is ``(a, 1)``: no factor goes to a denominator (no power with an
    exponent that is not a positive number, no exp, no fraction). Most products of a
    derivation are such, and ``fraction`` rebuilds both products to say so."""
    if a.is_Integer:
        return False
    for term in sp.Mul.make_args(a):
        if term.is_Pow:
            if not (term.exp.is_Number and term.exp.is_positive):
                return False
        elif isinstance(term, sp.exp) or (term.is_Rational and not term.is_Integer):
            return False
    return True


def _rest(a: sp.Basic) -> tuple[int, tuple[sp.Basic, ...]]:
    """``count_ops`` after its Rational, Mul and Add branches (a Mul that is no fraction
    comes here too)."""
    if a.is_Pow and a.exp is sp.S.NegativeOne:
        return 1, (a.base,)  # DIV
    if a == sp.S.Exp1:
        return 1, ()  # EXP
    if a.is_Pow and a.base == sp.S.Exp1:
        return 1, (a.exp,)
    own = 0
    if a.is_Mul or isinstance(a, LatticeOp):
        own = len(a.args) - 1
    elif a.args and (a.is_Pow or a.is_Function or isinstance(a, _COUNTED)):
        own = 1
    return own, (() if a.is_Symbol else a.args)


_COUNTED = (sp.Derivative, sp.Integral, sp.Sum)
"""Classes that count_ops counts as one operation besides powers and functions."""
