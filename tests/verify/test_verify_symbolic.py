"""symkin.verify.symbolic.compare (symbolic route) and symkin.testing.assert_kinematics_match."""

from __future__ import annotations

import types
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import symkin
from symkin.errors import SymkinError
from symkin.testing import assert_kinematics_match
from symkin.verify import hand as verify_hand
from symkin.verify import numeric, symbolic

ROOT = Path(__file__).resolve().parents[2]
CASES = Path(__file__).resolve().parents[1] / "verify_cases"

# The user's own symbols: same names as symkin's coordinates, but no assumptions.
x1, y1, f1, x2, y2, f2, x3, y3, f3 = sp.symbols(
    "crank.x crank.y crank.phi rod.x rod.y rod.phi slider.x slider.y slider.phi")
a, b, c, t = sp.symbols("a b c t")


def _book_jacobian() -> sp.Matrix:
    """Example 2.5 (b) for a = 1, b = 5, c = 4 as symbols, written out by hand."""
    J = sp.zeros(9, 9)
    J[0, 0] = J[1, 1] = -1
    J[2, 0], J[2, 2], J[2, 3] = 1, -a * sp.sin(f1), -1
    J[3, 1], J[3, 2], J[3, 4] = 1, a * sp.cos(f1), -1
    J[4, 3], J[4, 5], J[4, 6] = 1, -b * sp.sin(f2), -1
    J[5, 4], J[5, 5], J[5, 7] = 1, b * sp.cos(f2), -1
    J[6, 8], J[7, 7], J[8, 2] = 1, -1, 1
    return J


def test_a_correct_hand_jacobian_is_equal(crank_slider_system) -> None:
    result = symbolic.compare(crank_slider_system.phi_q, _book_jacobian())
    assert result.equal and bool(result) and len(result.entries) == 81
    assert result.text() == "all 81 entries are equal\n"


def test_a_wrong_entry_is_located_with_a_counterexample(crank_slider_system) -> None:
    hand = _book_jacobian()
    hand[5, 5] = b * sp.sin(f2)  # a slip: sin for cos
    result = symbolic.compare(crank_slider_system.phi_q, hand, system=crank_slider_system)
    [entry] = result.differences
    assert (entry.row, entry.column, entry.method) == (5, 5, "counterexample")
    values = {sp.Symbol(str(s)): v for s, v in entry.point.items()}
    assert entry.hand_value.real == pytest.approx(float((b * sp.sin(f2)).subs(values)))
    assert entry.derived_value.real == pytest.approx(float((b * sp.cos(f2)).subs(values)))
    assert "[5, 5] joints[2] revolute rod-slider (y), d/d rod.phi: derived" in result.text()


def test_equal_after_simplification(crank_slider_system) -> None:
    hand = _book_jacobian()
    hand[5, 5] = b * (sp.cos(f2 / 2) ** 2 - sp.sin(f2 / 2) ** 2)
    result = symbolic.compare(crank_slider_system.phi_q, hand)
    entry = next(e for e in result.entries if (e.row, e.column) == (5, 5))
    assert result.equal and entry.method in ("simplification", "numeric")


def test_gamma_and_single_entries(crank_slider_system) -> None:
    dphi1, dphi2 = sp.symbols("crank.phi_t rod.phi_t")
    hand = sp.Matrix([0, 0, a * sp.cos(f1) * dphi1**2, a * sp.sin(f1) * dphi1**2,
                      b * sp.cos(f2) * dphi2**2, b * sp.sin(f2) * dphi2**2, 0, 0, 2])
    assert symbolic.compare(crank_slider_system.gamma, hand).equal
    # a missing term, one entry alone: the chapter's gam(3:4) without Rot1*sA1*dfi1^2
    lone = symbolic.compare(crank_slider_system.gamma[2], sp.Integer(0))
    assert not lone.equal and lone.differences[0].method == "counterexample"
    assert symbolic.compare(sp.sin(a) ** 2 + sp.cos(a) ** 2, 1).equal


def test_numeric_fallback_when_simplification_gives_up(monkeypatch) -> None:
    monkeypatch.setattr(sp, "simplify", lambda expr: expr)  # a simplifier that proves nothing
    result = symbolic.compare(sp.Matrix([sp.sin(2 * a)]), sp.Matrix([2 * sp.sin(a) * sp.cos(a)]))
    assert result.equal and result.entries[0].method == "numeric"


def test_shape_mismatch_and_bad_arguments(crank_slider_system) -> None:
    with pytest.raises(SymkinError, match="9 x 9 but the hand one is 9 x 8"):
        symbolic.compare(crank_slider_system.phi_q, sp.zeros(9, 8))
    with pytest.raises(SymkinError, match="give a SymPy expression or matrix"):
        symbolic.compare(crank_slider_system.phi_q, "J")


# ----- the pytest helper ---------------------------------------------------------------------

def test_helper_passes_for_a_correct_derivation() -> None:
    report = assert_kinematics_match(CASES / "four_bar.yaml", CASES / "four_bar_hand.py")
    assert report.ok and report.samples == numeric.DEFAULT_SAMPLES


def test_helper_accepts_a_module_or_an_object() -> None:
    system = symkin.derive(CASES / "luffing.yaml")
    module = verify_hand.load_hand_module(CASES / "luffing_hand.py")
    assert_kinematics_match(system, module, samples=10)
    assert_kinematics_match(system, types.SimpleNamespace(phi_t=module.phi_t), samples=10)


def test_helper_fails_with_the_report() -> None:
    with pytest.raises(AssertionError) as failure:
        assert_kinematics_match(ROOT / "examples" / "crank_slider_general.yaml",
                                ROOT / "examples" / "textbook_hand.py")
    message = str(failure.value)
    assert "gamma[4]: row 4 joints[2] revolute rod-slider (x)" in message
    assert "MISMATCH: 2 entries differ" in message


def test_helper_keeps_the_users_exception_as_the_cause() -> None:
    def phi(q, t, p):
        return np.zeros(9)[q.size + 1]  # IndexError inside the user's code

    with pytest.raises(verify_hand.HandModuleError, match=r"phi\(q, t, p\) raised IndexError") as err:
        assert_kinematics_match(ROOT / "examples" / "crank_slider.yaml",
                                types.SimpleNamespace(phi=phi))
    assert isinstance(err.value.__cause__, IndexError)
