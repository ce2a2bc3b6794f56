"""symbolic.derivatives.diff is sympy.diff made faster: the same expression, node for node
(so generated code does not change), on the rows the pair types write and on the derivatives
a derivation takes of them (Phi_q's entries, Phi_t, Phi_tt and the second derivative along dq
of Gamma's convective part); a node it has no rule for goes to sympy.diff itself."""

from __future__ import annotations

import sympy as sp

from symkin.spec import validate
from symkin.symbolic import derivation, spatial
from symkin.symbolic.derivatives import Differentiator, Unsupported, diff
from symkin.symbolic.planar import Context
from symkin.symbolic.symbols import make_symbols

# planar pairs and drivers of every kind, input drivers, and spatial rows (Euler parameters,
# a distance driver's input); a piecewise cam profile is the last test's
FILES = ("examples/all_drivers.yaml", "examples/crank_slider_input.yaml",
         "examples/rack_linkage.yaml", "examples/stewart_fk.yaml", "examples/cardan.yaml",
         "tests/trust/spherical_four_bar.yaml")


def _rows(path: str) -> tuple[list[sp.Expr], tuple[sp.Symbol, ...], sp.Symbol]:
    mech = validate.load(path)
    symbols = make_symbols(mech)
    ctx = (spatial.SpatialContext if mech.is_spatial else Context)(mech, symbols)
    phi, rows = derivation._constraint_rows(mech, ctx)
    if mech.is_spatial:
        phi, _ = derivation._normalised(mech, ctx, phi, rows)
    return phi, symbols.q, symbols.t


def test_the_same_expression_as_sympy_diff_on_every_row() -> None:
    compared = 0
    for path in FILES:
        phi, q, t = _rows(path)
        for row in phi:
            for symbol in [s for s in q if s in row.free_symbols] + [t]:
                assert diff(row, symbol) == sp.diff(row, symbol), (path, row, symbol)
                compared += 1
            assert diff(row, t, 2) == sp.diff(row, t, 2), (path, row)
            along = sp.Dummy("along", real=True)
            moved = row.xreplace({s: s + along * sp.Symbol(f"{s}_t", real=True)
                                  for s in q if s in row.free_symbols})
            assert diff(moved, along, 2) == sp.diff(moved, along, 2), (path, row)
    assert compared > 300


def test_a_second_derivative_is_simplified_as_derivative_does() -> None:
    # Derivative applies factor_terms(signsimp(...)) to a derivative of order two or more:
    # its common factor stays outside the sum
    x, y = sp.symbols("x y", real=True)
    expr = (x * y - y**2) * sp.sin(2 * x)
    assert diff(expr, x, 2) == sp.diff(expr, x, 2)
    assert diff(expr, x) == sp.diff(expr, x)


def test_a_node_with_a_rule_of_its_own_goes_to_sympy() -> None:
    x, y = sp.symbols("x y", real=True)
    f = sp.Function("f")
    for expr in (sp.Abs(x - y) * x, sp.Piecewise((x**2, x < 1), (x, True)), f(x * y),
                 sp.Max(x, y) + x):
        assert diff(expr, x) == sp.diff(expr, x)
        assert diff(expr, x, 2) == sp.diff(expr, x, 2)
    try:
        Differentiator(x).diff(sp.Abs(x - y))
    except Unsupported:
        pass
    else:
        raise AssertionError("Abs has a derivative rule of its own")


def test_a_cam_profile_is_differentiated_by_its_piecewise_rule() -> None:
    """A cam row's Piecewise profile (its pieces, its derivative in the roller's offset and a
    square root of both, as examples/cam_cycloidal.yaml writes them): differentiated here,
    piece by piece (no fallback to sympy.diff), and still the same expression, node for node,
    to order two."""
    s, phi, x, h, a = sp.symbols("s phi x h a", real=True)
    lift = sp.Piecewise((h * (s / a - sp.sin(2 * sp.pi * s / a) / (2 * sp.pi)), s < a),
                        (h, s < 2 * a), (0, True))
    slope = sp.Piecewise((h / a * (1 - sp.cos(2 * sp.pi * s / a)), s < a), (0, True))
    radius = 3 + lift
    row = (x + sp.cos(phi) * (radius * sp.cos(s) - (radius * sp.cos(s) + slope * sp.sin(s))
                              / (2 * sp.sqrt(radius**2 + slope**2))))
    for symbol in (s, phi, x):
        ours = Differentiator(symbol).diff(row)  # raises Unsupported on a missing rule
        assert sp.srepr(ours) == sp.srepr(sp.diff(row, symbol)), symbol
        assert sp.srepr(diff(row, symbol, 2)) == sp.srepr(sp.diff(row, symbol, 2)), symbol
