"""Gamma's convective part (Phi_q dq)_q dq, derived as a row's second derivative along dq
(symbolic.differentiation.convective), equals the sum over pairs of columns of (2.74) written out
here, for the rows the chapter's and the spatial pairs write; a row that SymPy cannot
differentiate along dq in closed form, or a piecewise one, gets that sum itself."""

from __future__ import annotations

import sympy as sp

from symkin.symbolic.differentiation import convective as _convective
from symkin.symbolic.spatial import rotation
from symkin.symbolic.symbols import Symbols

Q = sp.symbols("x0 y0 e00 e01 e02 e03 x1 e10 e11 e12 e13 phi", real=True)
DQ = sp.symbols("x0_t y0_t e00_t e01_t e02_t e03_t x1_t e10_t e11_t e12_t e13_t phi_t",
                real=True)
SYMBOLS = Symbols(Q, DQ, sp.Symbol("t", real=True), (), tuple(map(str, Q)))


def _entries(row: sp.Expr) -> dict[int, sp.Expr]:
    return {k: sp.diff(row, q) for k, q in enumerate(Q) if q in row.free_symbols}


def _column_sum(row: sp.Expr) -> sp.Expr:
    """(Phi_q dq)_q dq as (2.74) writes it: the velocity row differentiated column by column."""
    velocity = sum(sp.diff(row, q) * dq for q, dq in zip(Q, DQ))
    return sum(sp.diff(velocity, q) * dq for q, dq in zip(Q, DQ))


def _rows() -> list[sp.Expr]:
    a0 = rotation(*Q[2:6])
    a1 = rotation(*Q[7:11])
    r = sp.Rational  # exact: the two forms are compared to the last digit
    s0, s1 = sp.Matrix([r(3, 10), r(-6, 5), r(1, 2)]), sp.Matrix([1, 2, r(-1, 4)])
    d = sp.Matrix([Q[6], 0, 0]) + a1 * s1 - sp.Matrix([Q[0], Q[1], 0]) - a0 * s0
    return [((a0 * s0).T * (a1 * s1))[0],  # dot-1
            ((a0 * s0).T * d)[0],  # dot-2
            (d.T * d)[0] / 2,  # distance
            Q[0] + r(1, 2) * sp.cos(Q[11]) - Q[6] * sp.sin(Q[11]),  # a planar revolute's x
            sp.Abs(Q[0] - Q[6]) * Q[11]]  # a custom equation with Abs


def test_the_derivative_along_dq_is_the_sum_over_columns() -> None:
    for row in _rows():
        difference = sp.expand(_convective(row, _entries(row), SYMBOLS) - _column_sum(row))
        assert sp.simplify(difference) == 0, row


def test_an_unevaluated_derivative_falls_back_to_the_sum_over_columns() -> None:
    row = sp.Function("f")(Q[0] * Q[1])  # SymPy keeps f' unevaluated: no closed form
    got = _convective(row, _entries(row), SYMBOLS)
    assert sp.simplify(got - _column_sum(row)) == 0
    assert not any(isinstance(s, sp.Dummy) for s in got.free_symbols)


def test_a_piecewise_row_keeps_the_sum_over_columns() -> None:
    row = sp.Piecewise((Q[0] ** 2, Q[0] < 1), (Q[0], True)) * Q[1]
    assert _convective(row, _entries(row), SYMBOLS) == sum(
        sp.diff(sum(v * DQ[k] for k, v in _entries(row).items()), Q[k]) * DQ[k]
        for k in _entries(row))
