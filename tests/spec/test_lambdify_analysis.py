"""constants.lambdify_analysis: the fast-printed NumPy callables of generation-time analyses
evaluate what SymPy's own lambdify evaluates (to rounding), and an expression nested deeper
than Python's parser takes in their parenthesised form is printed by SymPy's printer instead."""

from __future__ import annotations

import numpy as np
import sympy as sp
from codegen_support import ROOT, derived

from symkin.spec import constants

x, y = sp.symbols("x y", real=True)


def test_an_examples_phi_q_evaluates_as_sympys_lambdify() -> None:
    system = derived(ROOT / "examples" / "rssr.yaml")
    entries = [system.phi_q[r, c] for r, c in system.pattern()] + list(system.phi)
    arguments = (list(system.q), system.t, list(system.p))
    ours = constants.lambdify_floats(arguments, entries, dummify=True, analysis=True)
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
