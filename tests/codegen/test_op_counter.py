"""codegen.cse_tidy.OpCounter gives SymPy's count_ops, number for number.

The header's operation counts (before and after CSE) are counted by OpCounter, which remembers
each subtree's count instead of walking it again; the reference here is ``sympy.count_ops``
itself, on every expression the lowering counts for a few examples (before CSE, and each
temporary and output after it) and on expressions made to reach each of count_ops's branches.
"""

from __future__ import annotations

import pytest
import sympy as sp
from codegen_support import ROOT, derived

from symkin.codegen import symbol_printing
from symkin.codegen.cse_tidy import OpCounter
from symkin.codegen.system_facts import mass_pattern, parameter_pattern, routine_expressions

x, y, z = sp.symbols("x y z", real=True)
f = sp.Function("f")

# One or more of each branch: rationals (negative, fractions, 1), a product with a negative
# coefficient and with a denominator (integer or not), sums all negative and starting with a
# negative term, 1/x, E and exp, Min/Max (LatticeOp), functions, an undefined function, a
# Derivative, Piecewise with relational conditions, Abs, a relational and a boolean on top,
# products of powers.
BRANCHES = [
    sp.Rational(-3, 4), sp.S.One, sp.Integer(-2), sp.Float(-0.5), -x, -2 * x * y,
    x / 3, -x / 3, x / y, -x / (y + 1), (x + 1) / (2 * y), 2 / (x + y), -3 / x,
    -x - y, -x + y, x - y - z, 1 / x, x ** -2, sp.E, sp.exp(x), sp.exp(-x / 2) * y,
    sp.Min(x, y, 1 - x), sp.Max(x, -y), sp.sin(x) * sp.cos(y) ** 2, f(x, y),
    sp.Derivative(f(x), x), sp.Piecewise((x ** 2, x < 1), (-x, True)), sp.Abs(x - y),
    sp.Heaviside(x - 1), sp.sqrt(x ** 2 + y ** 2), sp.atan2(y, -x), x < y,
    sp.And(x < y, y < 1), sp.Eq(x, 2 * y),
    # products whose factors are powers (numerators only, or not: the shortcut's edges)
    x ** 2 * y, sp.sqrt(x) * y, -x ** 3 * sp.sin(y), x ** sp.Float(1.5) * y, x ** y * z,
    x ** (-y) * z, x ** (2 * y) * z, 2 * x ** 2 * y / 3,
]

FILES = ["examples/all_drivers.yaml", "examples/crank_slider_load.yaml", "examples/rssr.yaml"]


def _counted_expressions(path: str) -> list[sp.Basic]:
    """What lower counts for one file: every routine's expressions as derived (before CSE),
    and the temporaries and outputs of their CSE."""
    system = derived(ROOT / path)
    pattern = system.pattern()
    expressions = routine_expressions(system, pattern, parameter_pattern(system),
                                      mass_pattern(system))
    prepare = symbol_printing.Preparer(symbol_printing.internal_symbols(system))
    found: list[sp.Basic] = []
    for exprs in expressions.values():
        prepared = [prepare(e) for e in exprs]
        found += exprs
        if prepared:
            temporaries, values = sp.cse(prepared, symbols=sp.numbered_symbols("w", real=True),
                                         order="canonical")
            found += [value for _, value in temporaries] + list(values)
    return found


@pytest.mark.parametrize("expr", BRANCHES, ids=str)
def test_each_branch_counts_as_sympy(expr: sp.Basic) -> None:
    assert OpCounter()(expr) == sp.count_ops(expr)


@pytest.mark.parametrize("path", FILES)
def test_lowered_expressions_count_as_sympy(path: str) -> None:
    expressions = _counted_expressions(path)
    count = OpCounter()  # one memory for all, as lower keeps one
    wrong = [(sp.count_ops(e), count(e), str(e)[:80]) for e in expressions
             if count(e) != sp.count_ops(e)]
    assert not wrong, f"{len(wrong)} of {len(expressions)} differ, e.g. {wrong[:3]}"
    assert count.many(expressions) == sum(sp.count_ops(e) for e in expressions)


def test_a_subtree_met_again_is_not_walked_again() -> None:
    count = OpCounter()
    shared = sp.sin(x) * sp.cos(y) - x * y / 3
    assert count(f(shared) + z) == sp.count_ops(f(shared) + z)
    before = len(count._known)
    assert count(shared) == sp.count_ops(shared)  # looked up: nothing new remembered
    assert len(count._known) == before
