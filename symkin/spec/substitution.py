"""``xreplace`` for many expressions at once, each distinct subtree rebuilt once.

SymPy's ``xreplace`` walks an expression as a tree: a sub-expression met in many places (a
body's rotation matrix in each of its joints' rows, a cam profile in every row of Gamma) is
rebuilt at each, and each expression of a list is walked afresh. :class:`Substitution`
remembers what it rebuilt across all the expressions it is given, and can fold every largest
constant part on the way (:func:`symkin.spec.constants.fold`'s rule), so that one pass does
what a fold and a renaming did in two (:func:`lambdify_folded`, the redundancy analysis's
NumPy functions).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import sympy as sp

from symkin.spec import constants


class Substitution:
    """``expr.xreplace(mapping)`` for many expressions with one memory of the subtrees
    rebuilt; with ``fold``, also each largest constant part that is not a plain number
    replaced by its correctly rounded value (as :func:`constants.fold`)."""

    def __init__(self, mapping: dict[sp.Basic, sp.Basic], fold: bool = False) -> None:
        self._mapping = mapping
        self._fold = fold
        self._done: dict[sp.Basic, sp.Basic] = {}
        self._symbolic: dict[sp.Basic, bool] = {}

    def __call__(self, expr: sp.Basic) -> sp.Basic:
        """Raises:
            ExpressionError: (with ``fold``) a constant part has no value.
        """
        return self._visit(expr)

    def others(self) -> set[sp.Symbol]:
        """The symbols met so far that the mapping does not replace."""
        return {node for node in self._done
                if isinstance(node, sp.Symbol) and node not in self._mapping}

    def _visit(self, node: sp.Basic) -> sp.Basic:
        done = self._done.get(node)
        if done is not None:
            return done
        if node in self._mapping:
            result = self._mapping[node]
        elif self._fold and isinstance(node, sp.Expr) and self._is_constant(node):
            result = (node if constants.is_plain_number(node)
                      else sp.Float(constants.value(node), 17))
        elif not node.args:
            result = node
        else:
            args = [self._visit(arg) for arg in node.args]
            changed = any(new is not old for new, old in zip(args, node.args))
            result = node.func(*args) if changed else node
        self._done[node] = result
        return result

    def _is_constant(self, node: sp.Basic) -> bool:
        """No free symbols (constants.has_symbols: remembered, so a deep tree is walked
        once)."""
        return not constants.has_symbols(node, self._symbolic)


def lambdify_folded(arguments: Any, expressions: Sequence[sp.Expr]) -> Callable[..., Any]:
    """``constants.lambdify_floats(arguments, expressions, dummify=True)`` printed as
    :func:`constants.lambdify_analysis` prints, with the folding and the renaming of the
    argument symbols to ``_a0``, ``_a1``, ... made in one pass over all the expressions
    (fold and ``xreplace`` walk each expression on its own, a shared subtree at every place
    it occurs). Where the arguments are not distinct symbols, or a name could collide with
    another symbol of the expressions, lambdify dummifies them instead."""
    symbols = _leaves(arguments)
    if not all(isinstance(s, sp.Symbol) for s in symbols) or len(set(symbols)) < len(symbols):
        return constants.lambdify_analysis(arguments, _folded(expressions, {})[0], True)
    names: dict[sp.Basic, sp.Basic] = {s: sp.Symbol(f"_a{k}") for k, s in enumerate(symbols)}
    folded, others = _folded(expressions, names)
    if any(s.name.startswith("_a") for s in others):
        return constants.lambdify_analysis(arguments, _folded(expressions, {})[0], True)
    return constants.lambdify_analysis(_renamed(arguments, names), folded)


def _folded(expressions: Sequence[sp.Expr], names: dict[sp.Basic, sp.Basic]
            ) -> tuple[list[sp.Basic], set[sp.Symbol]]:
    """The expressions folded and renamed, and the other symbols they hold."""
    rebuild = Substitution(names, fold=True)
    return [rebuild(sp.sympify(e)) for e in expressions], rebuild.others()


def _leaves(item: Any) -> list[Any]:
    if isinstance(item, (list, tuple)):
        return [leaf for part in item for leaf in _leaves(part)]
    return [item]


def _renamed(item: Any, names: dict[sp.Basic, sp.Basic]) -> Any:
    """The arguments' structure (lists, tuples) with each symbol renamed."""
    if isinstance(item, (list, tuple)):
        return type(item)(_renamed(part, names) for part in item)
    return names[item]
