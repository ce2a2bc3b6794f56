"""The condition estimate behind the flags: Hager-Higham against the exact ||A^-1||_1, the
generated C's transposed LU solves against NumPy, and the C estimate against the Python one."""

from __future__ import annotations

import numpy as np
import pytest
from driver_support import derive, kernel_for

import symkin
from symkin.runtime import driver
from symkin.runtime.solving import accuracy


def test_estimate_is_a_lower_bound_and_usually_exact() -> None:
    rng = np.random.default_rng(7)
    exact_hits = 0
    for trial in range(200):
        n = int(rng.integers(2, 30))
        a = rng.normal(size=(n, n)) @ np.diag(10.0 ** rng.uniform(-6, 0, n))
        exact = np.abs(np.linalg.inv(a)).sum(axis=0).max()
        estimate = accuracy.inverse_norm1(lambda b: np.linalg.solve(a, b),
                                          lambda b: np.linalg.solve(a.T, b), n)
        assert estimate <= exact * (1 + 1e-8)
        assert estimate >= exact / 10  # within a small factor always
        exact_hits += estimate >= exact * (1 - 1e-8)
    assert exact_hits >= 150  # and exact in most cases, as Higham reports


@pytest.mark.parametrize("linalg", ["dense", "sparse"])
def test_c_transposed_solve(linalg: str) -> None:
    system = derive("parallelogram_chain") if linalg == "sparse" else derive("four_bar_test")
    kernel = symkin.compile(system, backend="c", linalg=linalg)
    assert kernel.backend == "c"
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    lu = ffi.new(f"{name}_lu *")
    getattr(lib, f"{name}_lu_init")(lu)
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = kernel.q0 + rng.normal(0, 0.2, kernel.nq)
        b = rng.normal(size=kernel.nq)
        nz = ffi.new("double[]", kernel.phi_q_nz(q, 0.1).tolist())
        x = ffi.new("double[]", b.tolist())
        assert getattr(lib, f"{name}_lu_factor")(nz, lu) == 0
        getattr(lib, f"{name}_lu_solve_transposed")(lu, x)
        expected = np.linalg.solve(kernel.phi_q(q, 0.1).T, b)
        got = np.frombuffer(ffi.buffer(x), dtype=float)
        assert np.allclose(got, expected, rtol=1e-9, atol=1e-9)


def test_c_and_python_estimates_agree_on_an_ordinary_run(crank_slider_system) -> None:
    """The textbook crank-slider: far from any singularity, nothing flagged on either backend,
    the same condition estimates, and the estimate equals the exact 1-norm condition."""
    runs = [driver.solve(kernel_for(crank_slider_system, b)) for b in ("numpy", "c")]
    kernel = kernel_for(crank_slider_system, "numpy")
    exact = [np.linalg.cond(kernel.phi_q(q, t), 1) for q, t in zip(runs[0].q, runs[0].t)]
    for run in runs:
        assert not run.flagged.any()
        assert np.allclose(run.cond, exact, rtol=1e-9)
