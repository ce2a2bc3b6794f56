"""The generated C solver's condition estimate at solved points, against NumPy: ||Phi_q||_1
(the straight-line column sums, Phi_q's numbers folded in) equals the largest column sum of
|Phi_q| from numpy, and ||Phi_q^-1||_1 is the Hager-Higham estimate of runtime.accuracy run on
numpy's solves with Phi_q and Phi_q^T (at most points: both are lower bounds of the exact
norm, and where two candidate columns tie to rounding the two LUs may pick different ones)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.runtime import accuracy, driver

EXAMPLES_DIR = Path(__file__).resolve().parent.parent / "examples"

EXAMPLES = ["crank_slider", "andrews_squeezer", "quick_return", "four_bar", "all_drivers"]


@pytest.mark.parametrize("example", EXAMPLES)
def test_norm_and_estimate_at_solved_points(example: str) -> None:
    kernel = symkin.compile(symkin.derive(EXAMPLES_DIR / f"{example}.yaml"), backend="c")
    assert kernel.backend == "c"
    ffi, lib, name, n = kernel.ffi, kernel.lib, kernel.name, len(kernel.coordinates)
    options, state = ffi.new(f"{name}_options *"), ffi.new(f"{name}_state *")
    work, report = ffi.new(f"{name}_workspace *"), ffi.new(f"{name}_report *")
    getattr(lib, f"{name}_default_options")(options)
    p = ffi.new(f"{name}_real[]", list(kernel.p_values))
    state.q[0:n] = list(kernel.q0)
    times = driver.solve(kernel).t
    points = same = 0
    for t in times[:: max(1, len(times) // 25)]:
        assert getattr(lib, f"{name}_solve_step")(options, p, t, state, work, report) == 0
        a = kernel.phi_q(np.array(ffi.unpack(state.q, n)), t)
        norm = np.abs(a).sum(axis=0).max()
        assert report.cond / report.inv_norm == pytest.approx(norm, rel=1e-14)
        expected = accuracy.inverse_norm1(lambda b: np.linalg.solve(a, b),
                                          lambda b: np.linalg.solve(a.T, b), n)
        exact = np.abs(np.linalg.inv(a)).sum(axis=0).max()
        assert exact / 3 <= report.inv_norm <= exact * (1 + 1e-9)
        points += 1
        same += report.inv_norm == pytest.approx(expected, rel=1e-9)
    assert same >= 0.8 * points
