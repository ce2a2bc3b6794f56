"""symbolic.tidy.Factored is SymPy's factor_terms with each subtree's result remembered: the
same expression node for node (so Gamma's printed form does not change), on the rows Gamma's
convective part tidies and on the cases factor_terms treats apart."""

from __future__ import annotations

import sympy as sp
from sympy.core.exprtools import factor_terms
from sympy.simplify.simplify import signsimp

from symkin.spec import validate
from symkin.symbolic import derivation, spatial
from symkin.symbolic.derivatives import Directional
from symkin.symbolic.planar import Context
from symkin.symbolic.symbols import make_symbols
from symkin.symbolic.tidy import Factored

# spatial rows (a body's rotation matrix in several rows) and planar ones of every pair kind
FILES = ("tests/trust/spherical_four_bar.yaml", "examples/cardan.yaml",
         "examples/all_drivers.yaml")


def _second_derivatives(path: str) -> list[sp.Expr]:
    """Each row's second derivative along dq, signs simplified: what Gamma's tidying gets."""
    mech = validate.load(path)
    symbols = make_symbols(mech)
    ctx = (spatial.SpatialContext if mech.is_spatial else Context)(mech, symbols)
    phi, _ = derivation._constraint_rows(mech, ctx)
    along = Directional(dict(zip(symbols.q, symbols.dq)))
    return [signsimp(second) for second in (along.diff(along.diff(row)) for row in phi)
            if not second.is_zero]


def test_the_same_expression_as_factor_terms_on_every_row() -> None:
    compared = 0
    for path in FILES:
        factored = Factored()  # one memory for every row, as a derivation keeps it
        for second in _second_derivatives(path):
            assert sp.srepr(factored(second)) == sp.srepr(factor_terms(second)), path
            compared += 1
    assert compared > 25


def test_the_cases_factor_terms_treats_apart() -> None:
    x, y, z = sp.symbols("x y z", real=True)
    cases = [
        -2 * x * y - 4 * x * z,  # a sign common to every term taken out
        2 * x * y - 4 * x * z,  # content and a common factor, no common sign
        sp.exp(-(x + 2)) + sp.exp(-(x + 2)) * y + x,  # an exponent gcd_terms must not expand
        sp.sin(2 * x * y + 4 * x * z) * (x * y + x),  # a function's argument tidied inside it
        (3 * x + 6 * y) ** 2 - 3 * z,  # a power's base tidied, the power kept
        sp.Eq(2 * x + 2 * y, z),  # no args_cnc: its arguments only
        sp.Rational(1, 2) * x + sp.Rational(3, 4) * x * y,
        sp.Sum(2 * x * y + 2 * x, (y, 0, z)),  # SymPy's own rule
        x,
    ]
    factored = Factored()
    for expr in cases:
        assert sp.srepr(factored(expr)) == sp.srepr(factor_terms(expr)), expr


def test_a_subtree_met_again_is_looked_up() -> None:
    x, y = sp.symbols("x y", real=True)
    shared = 2 * x * sp.cos(y) + 4 * x * sp.sin(y)
    factored = Factored()
    first = factored(shared)
    known = len(factored.known)
    assert factored(shared) is first and len(factored.known) == known
    # a function of it: one node more, its argument looked up, not tidied again
    assert factored(sp.sin(shared)) == sp.sin(first)
    assert len(factored.known) == known + 1
