"""The fast paths of constant folding and of lambdify_floats give what the plain definitions
give: fold's remembered "has free symbols" per subtree replaces exactly the largest constant
parts that asking SymPy at every node does; the arguments renamed in one pass evaluate as
lambdify's own dummify does, and a name that could collide falls back to it."""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from symkin.spec import constants

x, y = sp.symbols("x y", real=True)
f = sp.Function("f")


def _fold_by_definition(expr: sp.Expr) -> sp.Expr:
    """The rule as written: each node asked for its free symbols, top down."""
    replacements: dict[sp.Basic, sp.Basic] = {}

    def visit(node: sp.Basic) -> None:
        if isinstance(node, sp.Expr) and not node.free_symbols:
            if not constants.is_plain_number(node):
                replacements[node] = sp.Float(constants.value(node), 17)
            return
        for arg in node.args:
            visit(arg)

    visit(expr)
    return expr.xreplace(replacements)


def test_fold_replaces_the_same_parts_as_the_definition() -> None:
    shared = sp.sin(x + sp.pi / 7) * sp.sqrt(3)  # a subtree met three times
    cases = [
        sp.sqrt(2) * x + sp.sin(x + sp.pi) + sp.Integer(2**70),
        shared + shared**2 + sp.cos(shared) * sp.exp(sp.Rational(1, 3)),
        # bound variables: a Derivative's own free_symbols, not the union over its args
        sp.Derivative(f(x), x) * sp.sqrt(5) + sp.Derivative(f(x, y), y).subs(y, 2) * x,
        sp.Piecewise((sp.sqrt(2) * x, x > sp.pi), (sp.log(3), True)),
        sp.Max(x, sp.Integer(18446744073709551617)),
        sp.sqrt(2) * sp.pi,  # wholly constant
    ]
    for expr in cases:
        assert constants.fold(expr) == _fold_by_definition(expr)
    assert constants.fold(sp.sqrt(2) * x) == sp.Float(math.sqrt(2), 17) * x


def test_renamed_arguments_evaluate_as_sympys_dummify() -> None:
    q = sp.symbols("crank.phi rocker.x", real=True)  # no Python identifiers
    t, p = sp.Symbol("t", real=True), sp.Symbol("p.L", positive=True)
    exprs = [q[0] * sp.sin(t) + p * q[1] ** 2, sp.sqrt(2) * sp.cos(q[1] - p), t / p]
    ours = constants.lambdify_floats((list(q), t, [p]), exprs, dummify=True)
    folded = [constants.fold(e) for e in exprs]
    theirs = sp.lambdify((list(q), t, [p]), folded, modules="numpy", dummify=True)
    arguments = (np.array([0.3, -1.2]), np.float64(0.7), np.array([2.5]))
    assert np.array_equal(np.array(ours(*arguments)), np.array(theirs(*arguments)))
    matrix = constants.lambdify_floats((list(q), t, [p]), sp.Matrix([exprs]), dummify=True)
    assert np.array(matrix(*arguments)).shape == (1, 3)


def test_a_symbol_named_like_a_renamed_argument_keeps_its_own_value() -> None:
    """``_a0`` in the expression but not among the arguments: renaming q to ``_a0`` would
    capture it, so lambdify dummifies as before (and the stray name stays a symbol)."""
    stray, q = sp.Symbol("_a0"), sp.Symbol("q")
    function = constants.lambdify_floats([q], [q + 1, stray * 0 + q], dummify=True)
    assert function(2.0) == [3.0, 2.0]
    function = constants.lambdify_floats([q], q + stray, dummify=True)
    assert function(2.0) == stray + 2.0  # _a0 stays a symbol: never the argument's 2
