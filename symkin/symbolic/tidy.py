"""SymPy's ``factor_terms`` (its defaults: no radicals, nothing cleared, no fractions, the sign
taken out), the same expression node for node, with each subtree's result remembered.

``factor_terms`` tidies a tree from the top: a node's content is taken out, each term of a sum
tidied in turn, and the sum's common factors gathered by ``gcd_terms``. What it makes of a
subtree depends on that subtree alone, yet it starts again at every occurrence, and the rows of
Gamma's convective part share many (a body's rotation matrix and its rate in each of its
joints' rows): on the leg-body Stewart model 4.6 s of its 9 s derivation. :class:`Factored`
applies the same steps in the same order with SymPy's own helpers, and keeps each subtree's
result for every row of the derivation that meets it again (3.0 s there).
"""

from __future__ import annotations

import sympy as sp
from sympy.core.basic import Basic
from sympy.core.exprtools import _keep_coeff, gcd_terms


class Factored:
    """``factor_terms(expr)`` for the expressions of one derivation, each subtree's once."""

    def __init__(self) -> None:
        self.known: dict[Basic, Basic] = {}

    def __call__(self, expr: Basic) -> Basic:
        found = self.known.get(expr)
        if found is None:
            found = self.known[expr] = self._node(expr)
        return found

    def _node(self, expr: Basic) -> Basic:
        if expr.is_Atom:
            return expr
        if expr.is_Pow or expr.is_Function or not hasattr(expr, "args_cnc"):
            # the arguments tidied, the node itself as it is
            args = expr.args
            tidied = tuple(self(arg) for arg in args)
            return expr if tidied == args else expr.func(*tidied)
        if isinstance(expr, (sp.Sum, sp.Integral)):
            return sp.factor_terms(expr)  # a rule of their own; not met in a derivation
        content, rest = expr.as_content_primitive(radical=False, clear=False)
        if rest.is_Add:
            rest, negated = self._sum(rest)
            content = -content if negated else content
        elif rest.args:
            rest = rest.func(*(self(arg) for arg in rest.args))
        return _keep_coeff(content, rest, clear=False, sign=True)

    def _sum(self, total: sp.Add) -> tuple[Basic, bool]:
        """The terms tidied and their common factors gathered; whether a sign common to all
        the terms was taken out (gcd_terms keeps it in)."""
        terms = [self(term) for term in sp.Add.make_args(total)]
        negated = all(term.as_coeff_Mul()[0].extract_multiplicatively(-1) is not None
                      for term in terms)
        if negated:
            terms = [-term for term in terms]
        # gcd_terms would rewrite exp(-(x + 2)) as exp(-x - 2): such terms wait aside
        aside: dict[sp.Dummy, Basic] = {}
        for k, term in enumerate(terms):
            exponent = term.as_base_exp()[1]
            if exponent.is_Mul and exponent != sp.Mul(*exponent.args):
                placeholder = sp.Dummy()
                aside[placeholder] = term
                terms[k] = placeholder
        gathered = gcd_terms(sp.Add._from_args(terms), isprimitive=True, clear=False,
                             fraction=False)
        return gathered.xreplace(aside), negated
