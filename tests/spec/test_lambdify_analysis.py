"""constants.lambdify_analysis and substitution.lambdify_folded: the fast-printed NumPy
callables of generation-time analyses (folded and renamed in one pass) evaluate what
constants.lambdify_floats evaluates (to rounding); a name that could collide is left to
lambdify's dummify; an expression nested deeper than Python's parser takes in their
parenthesised form is printed by SymPy's printer instead."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
import sympy as sp
from codegen_support import ROOT, derived

from symkin.spec import constants, substitution

x, y = sp.symbols("x y", real=True)


def test_an_examples_phi_q_evaluates_as_sympys_lambdify() -> None:
    system = derived(ROOT / "examples" / "rssr.yaml")
    entries = [system.phi_q[r, c] for r, c in system.pattern()] + list(system.phi)
    arguments = (list(system.q), system.t, list(system.p))
    ours = substitution.lambdify_folded(arguments, entries)
    reference = constants.lambdify_floats(arguments, entries, dummify=True)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = np.array(system.q0) + rng.uniform(-0.5, 0.5, len(system.q))
        values = (q, np.float64(rng.uniform(0, 1)), np.array(system.p_values))
        a, b = np.array(ours(*values), dtype=float), np.array(reference(*values), dtype=float)
        assert np.allclose(a, b, rtol=1e-14, atol=1e-14 * np.abs(b).max())


def test_a_deeply_nested_expression_falls_back_to_sympys_printer() -> None:
    # sums of products, 105 deep: SymPy's printer needs a parenthesis per sum (105 levels),
    # the fast one one per sum and per product (210: more than Python's parser takes)
    expr: sp.Expr = y
    for _ in range(105):
        expr = 1 + x * (y + expr)
    function = constants.lambdify_analysis([x, y], [expr])
    expected = float(expr.subs({x: 0.5, y: 0.25}))
    assert np.isclose(function(0.5, 0.25)[0], expected, rtol=1e-13)


def test_a_symbol_named_like_a_renamed_argument_is_not_captured() -> None:
    """``_a0`` in the expressions but not among the arguments: renaming q to ``_a0`` would
    make q + _a0 evaluate to 2q; dummified instead, ``_a0`` stays a name the function lacks."""
    stray, q = sp.Symbol("_a0"), sp.Symbol("q")
    assert substitution.lambdify_folded([q], [q + 1, sp.sqrt(2) * q])(2.0) == [
        3.0, 2.0 * float(sp.sqrt(2))]
    function = substitution.lambdify_folded([q], [q + stray])
    with pytest.raises(NameError):
        function(2.0)


def test_a_piecewise_evaluates_as_numpys_select_at_scalars() -> None:
    """Each piece where its condition holds, NaN past the last condition, a constant piece a
    NumPy double (1/0 is inf, not ZeroDivisionError): bit for bit what SymPy's NumPy printer's
    ``select`` gives, with only the chosen piece evaluated."""
    pieces = sp.Piecewise((x**2 * sp.sin(y), x < y), (2, x < 2 * y), (x / y, (x < 5) & (y > 0)))
    entries = [3 * pieces + 1 / (pieces - 2), sp.Piecewise((sp.cos(x), x > 0), (0, True))]
    ours = constants.lambdify_analysis([x, y], entries)
    reference = constants.lambdify_floats([x, y], entries)
    with np.errstate(all="ignore"):
        for u in (-1.5, 0.25, 1.0, 1.5, 4.0, 7.0, float("nan")):
            values = (np.float64(u), np.float64(1.0))
            a = np.array(ours(*values), dtype=float)
            b = np.array(reference(*values), dtype=float)
            assert np.array_equal(a, b, equal_nan=True), (u, a, b)
    assert "select" not in inspect.getsource(ours)
