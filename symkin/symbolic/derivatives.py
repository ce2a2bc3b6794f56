"""``sympy.diff`` for the expressions a derivation meets, by SymPy's own rules without its
dispatch, so that the result is the same expression, node for node, only made faster.

``sympy.diff(expr, s, n)`` builds a ``Derivative`` at every node of the tree: it sympifies and
checks its arguments, sorts the variables, asks the assumptions whether the result is zero and
walks the result once more for nested derivatives. On the rows of Phi that overhead, not the
arithmetic, was the cost: 5-10 ms a row of a planar revolute, three quarters of the derivation
of a long chain. :class:`Differentiator` applies the same per-class rules SymPy would reach
(``Add``, ``Mul``'s Leibniz rule and product rule, ``Pow``, a ``Function``'s ``fdiff``, a
symbol), in the same order and with the same arithmetic, and differentiates a sub-expression
met twice once; a ``Piecewise`` by its own rule (each piece, the conditions kept). A node whose
class brings another rule of its own (``Abs``, ``Min``, an unevaluated ``Derivative``, ...)
raises :class:`Unsupported`, and the caller differentiates
the whole expression with ``sympy.diff``: it is never a different result, only a slower one.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import reduce

import sympy as sp
from sympy.core.basic import Basic
from sympy.core.expr import AtomicExpr
from sympy.core.exprtools import factor_terms
from sympy.core.function import ArgumentIndexError, Function
from sympy.ntheory.multinomial import multinomial_coefficients_iterator
from sympy.simplify.simplify import signsimp

ZERO = sp.S.Zero


class Unsupported(Exception):
    """A node whose class differentiates itself by a rule of its own: use ``sympy.diff``."""


def diff(expr: sp.Expr, symbol: sp.Symbol, order: int = 1,
         shared: dict[sp.Symbol, Differentiator] | None = None) -> sp.Expr:
    """``sympy.diff(expr, symbol, order)``, the same expression, made faster where it can be.

    ``shared`` keeps each symbol's :class:`Differentiator` from call to call, so that a
    sub-expression met in many rows (a body's rotation matrix) is differentiated once."""
    differentiator = (Differentiator(symbol) if shared is None
                      else shared.setdefault(symbol, Differentiator(symbol)))
    try:
        found = differentiator.diff(expr, order)
    except Unsupported:
        return sp.diff(expr, symbol, order)
    if found.has(sp.Derivative, sp.Subs):  # SymPy puts those in a canonical form of its own
        return sp.diff(expr, symbol, order)
    return found


class Differentiator:
    """Derivatives with respect to one symbol, each sub-expression's made once."""

    def __init__(self, symbol: sp.Symbol) -> None:
        self.symbol = symbol
        self.memo: dict[tuple[Basic, int], sp.Expr] = {}

    def diff(self, expr: sp.Expr, order: int = 1) -> sp.Expr:
        """``expr.diff((symbol, order))`` for an order of 1 or more.

        Raises:
            Unsupported: a node of ``expr`` has a derivative rule of its own.
        """
        key = (expr, order)
        found = self.memo.get(key)
        if found is None:
            # Derivative's shortcut: an expression free of the symbol has derivative 0
            found = (ZERO if self.symbol not in expr.free_symbols
                     else self._n_times(expr, order))
            if order > 1 and not (found is ZERO or found.is_zero):
                # what Derivative does to every derivative of a higher order
                found = factor_terms(signsimp(found))
            self.memo[key] = found
        return found

    def _n_times(self, expr: sp.Expr, order: int) -> sp.Expr:
        """``expr._eval_derivative_n_times(symbol, order)``."""
        method = type(expr)._eval_derivative_n_times
        if method is sp.Mul._eval_derivative_n_times:
            return self._leibniz(expr.args, order)
        if method is AtomicExpr._eval_derivative_n_times:  # the symbol itself (it is free)
            return sp.S.One if order == 1 else ZERO
        if method is not Basic._eval_derivative_n_times:
            raise Unsupported(type(expr).__name__)
        result = expr
        for _ in range(order):  # Basic's loop of first derivatives
            previous, result = result, self._once(result)
            if result == previous:
                break
        return result

    def _leibniz(self, args: tuple[sp.Expr, ...], order: int) -> sp.Expr:
        """``Mul._eval_derivative_n_times``: the general Leibniz rule, factor by factor."""
        terms = []
        for orders, coefficient in multinomial_coefficients_iterator(len(args), order):
            product = sp.Mul(*[arg if k == 0 else self.diff(arg, k)
                               for k, arg in zip(orders, args)])
            terms.append(coefficient * product)
        return sp.Add(*terms)

    def _once(self, expr: sp.Expr) -> sp.Expr:
        """``expr._eval_derivative(symbol)``, by the rule of its class."""
        rule = _RULES.get(type(expr)._eval_derivative)
        if rule is None:
            raise Unsupported(type(expr).__name__)
        return rule(self, expr)

    def _add(self, expr: sp.Expr) -> sp.Expr:
        return expr.func(*[self.diff(arg) for arg in expr.args])

    def _product(self, expr: sp.Expr) -> sp.Expr:
        """``Mul._eval_derivative``: each factor's derivative times the others, multiplied
        pairwise from the left as SymPy does."""
        args = list(expr.args)
        terms = []
        for i in range(len(args)):
            d = self.diff(args[i])
            if d:
                terms.append(reduce(lambda x, y: x * y, args[:i] + [d] + args[i + 1:], sp.S.One))
        return sp.Add.fromiter(terms)

    def _power(self, expr: sp.Expr) -> sp.Expr:
        base, exponent = expr.args
        dbase, dexp = self.diff(base), self.diff(exponent)
        if dexp is not ZERO:  # 0 * log(base) is 0: not formed
            return expr * (dexp * sp.log(base) + dbase * exponent / base)
        return expr * (dbase * exponent / base)

    def _function(self, expr: sp.Expr) -> sp.Expr:
        """``Function._eval_derivative``: the chain rule through each argument."""
        terms = []
        for i, arg in enumerate(expr.args, start=1):
            da = self.diff(arg)
            if da is ZERO or da.is_zero:
                continue
            try:
                df = expr.fdiff(i)
            except ArgumentIndexError:
                df = Function.fdiff(expr, i)
            terms.append(df * da)
        return sp.Add(*terms)

    def _atom(self, expr: sp.Expr) -> sp.Expr:
        return sp.S.One if expr == self.symbol else ZERO

    def _piecewise(self, expr: sp.Expr) -> sp.Expr:
        """``Piecewise._eval_derivative``: each piece differentiated, the conditions kept (a
        cam profile's; ``sympy.diff`` built a ``Derivative`` at every node of its pieces)."""
        return expr.func(*[(self.diff(piece), condition) for piece, condition in expr.args])


class Directional(Differentiator):
    """The derivative along a direction, D x = sum_k (dx/dq_k) v_k with v constant: each
    node by the rule of its class as :class:`Differentiator` applies it, a symbol q_k giving
    its v_k. D is a first derivative, so its rules need no ``Derivative`` of its own: applied
    twice, D(D(x)) is x's second derivative along v (Gamma's convective part, v = dq). A
    node's D is made once and kept for every row that meets it."""

    def __init__(self, direction: dict[sp.Symbol, sp.Expr]) -> None:
        super().__init__(sp.S.Zero)
        self.direction = direction
        self.variables = frozenset(direction)
        self.touches: dict[Basic, bool] = {}

    def diff(self, expr: sp.Expr, order: int = 1) -> sp.Expr:
        """D(expr); ``order`` must be 1 (apply D again for the next).

        Raises:
            Unsupported: a node of ``expr`` has a derivative rule of its own.
        """
        found = self.memo.get((expr, 1))
        if found is None:
            found = self._n_times(expr, 1) if self._touches(expr) else ZERO
            self.memo[expr, 1] = found
        return found

    def _touches(self, node: Basic) -> bool:
        """Whether ``node`` holds one of the variables, remembered per subtree (SymPy walks
        the whole subtree for free_symbols at every call)."""
        found = self.touches.get(node)
        if found is None:
            if node.is_Symbol:
                found = node in self.variables
            elif _union_of_args(type(node)):
                found = any(self._touches(arg) for arg in node.args)
            else:
                found = not self.variables.isdisjoint(node.free_symbols)
            self.touches[node] = found
        return found

    def _n_times(self, expr: sp.Expr, order: int) -> sp.Expr:
        if expr.is_Symbol:
            return self.direction.get(expr, ZERO)
        method = type(expr)._eval_derivative_n_times
        if method is sp.Mul._eval_derivative_n_times:
            return self._leibniz(expr.args, 1)
        if method is not Basic._eval_derivative_n_times:
            raise Unsupported(type(expr).__name__)
        return self._once(expr)


_UNION_OF_ARGS: dict[type, bool] = {}


def _union_of_args(kind: type) -> bool:
    """The class takes free_symbols from Basic (the union over its args). Looked up in the
    classes' own dictionaries: a function class's metaclass has a free_symbols of its own."""
    found = _UNION_OF_ARGS.get(kind)
    if found is None:
        owner = next(k for k in kind.__mro__ if "free_symbols" in k.__dict__)
        found = _UNION_OF_ARGS[kind] = owner is sp.Basic
    return found


_RULES: dict[Callable[..., object], Callable[[Differentiator, sp.Expr], sp.Expr]] = {
    sp.Add._eval_derivative: Differentiator._add,
    sp.Mul._eval_derivative: Differentiator._product,
    sp.Pow._eval_derivative: Differentiator._power,
    Function._eval_derivative: Differentiator._function,
    AtomicExpr._eval_derivative: Differentiator._atom,
    sp.Piecewise._eval_derivative: Differentiator._piecewise,
}
"""The classes whose rule is SymPy's own, keyed by the method (a subclass that overrides it,
such as Abs, is not found here)."""
