"""The generated C solver's condition at solved points, against NumPy: ||Phi_q||_1 (the
straight-line column sums, Phi_q's numbers folded in) equals the largest column sum of |Phi_q|;
||Phi_q^-1||_1 is exact where the generated code computes the inverse's columns
(backends.c.inverse_code: every example here) and equals the largest column sum of
numpy.linalg.inv; where that code would be too long, the solver runs the Hager-Higham estimate
of runtime.solving.accuracy instead, a lower bound that is usually exact (carried from point to
point by the Banach lemma while Phi_q moves little)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from codegen_support import compiled, derived

import symkin
from symkin import backends
from symkin.backends.c import inverse_code
from symkin.contract import tuning
from symkin.runtime import driver
from symkin.runtime.solving import accuracy, linalg

EXAMPLES_DIR = Path(__file__).resolve().parents[3] / "examples"

EXAMPLES = ["crank_slider", "andrews_squeezer", "quick_return", "four_bar", "all_drivers"]


def _solved_points(kernel: Any) -> list[tuple[float, np.ndarray, Any]]:
    """(t, Phi_q, report) at about 25 points of the example's grid, solved by the C solver."""
    ffi, lib, name, n = kernel.ffi, kernel.lib, kernel.name, len(kernel.coordinates)
    options, state = ffi.new(f"{name}_options *"), ffi.new(f"{name}_state *")
    work = ffi.new(f"{name}_workspace *")
    getattr(lib, f"{name}_default_options")(options)
    p = ffi.new(f"{name}_real[]", list(kernel.p_values))
    state.q[0:n] = list(kernel.q0)
    times = driver.solve(kernel).t
    points = []
    for t in times[:: max(1, len(times) // 25)]:
        report = ffi.new(f"{name}_report *")
        assert getattr(lib, f"{name}_solve_step")(options, p, t, state, work, report) == 0
        points.append((float(t), kernel.phi_q(np.array(ffi.unpack(state.q, n)), t), report))
    return points


@pytest.mark.parametrize("example", EXAMPLES)
def test_exact_inverse_norm_at_solved_points(example: str) -> None:
    kernel = compiled(EXAMPLES_DIR / f"{example}.yaml", "c")  # the goldens' solver
    assert kernel.backend == "c"
    for _, a, report in _solved_points(kernel):
        norm = np.abs(a).sum(axis=0).max()
        assert report.cond / report.inv_norm == pytest.approx(norm, rel=1e-14)
        exact = np.abs(np.linalg.inv(a)).sum(axis=0).max()
        assert report.inv_norm == pytest.approx(exact, rel=1e-12)
        # the NumPy backend's factors give the same exact norm
        assert linalg.factor(a).inverse_norm1() == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("example", ["crank_slider", "andrews_squeezer"])
def test_hager_estimate_where_the_exact_code_would_be_long(
        example: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(inverse_code, "EXACT_OPS", 0)  # generated afresh, without the columns
    kernel = symkin.compile(derived(EXAMPLES_DIR / f"{example}.yaml"), backend="c")
    assert kernel.backend == "c"
    points = same = 0
    for _, a, report in _solved_points(kernel):
        expected = accuracy.inverse_norm1(lambda b: np.linalg.solve(a, b),
                                          lambda b: np.linalg.solve(a.T, b), len(a))
        exact = np.abs(np.linalg.inv(a)).sum(axis=0).max()
        # Hager's lower bound, or the Banach-lemma bound from the last fresh estimate,
        # which may exceed the exact norm by 1 / (1 - REESTIMATE_SHIFT)^2 at most
        # (tests/backends/c/test_dense_condition.py)
        carried = exact / (1 - tuning.REESTIMATE_SHIFT) ** 2
        assert exact / 3 <= report.inv_norm <= carried * (1 + 1e-9)
        points += 1
        same += report.inv_norm == pytest.approx(expected, rel=1e-9)
    # both are the same estimator on LUs that round differently: near a tie of two columns
    # they may take different ones
    assert same >= 0.8 * points


def test_exact_code_is_refused_beyond_its_budget() -> None:
    """A chain of loops has a dense inverse: its exact columns would cost far more than the
    estimate, so the generated solver keeps the estimator there."""
    from symkin.codegen import lower

    system = derived(EXAMPLES_DIR / "crank_slider.yaml")
    plan = lower.lower(system, backends.get("c")).lu_plan
    assert plan is not None
    values: list[float | None] = [None] * plan.n_lu
    assert inverse_code.exact_context(plan, values, {}, repr, "double", "fabs", limit=10) is None
    context = inverse_code.exact_context(plan, values, {}, repr, "double", "fabs")
    assert context is not None and context["ops"] <= inverse_code.EXACT_OPS
