"""The sparse LU with Phi_q's constant entries folded in (backends.c.lu_code).

Pivots that are numbers (the +-1 of ground joints and revolute joints) get no reciprocal and no
test at run time, multipliers that are numbers become literals. The solutions must still be
those of a dense LU (NumPy's LAPACK here, an independent code) at random states, and a
singular Jacobian must still be caught: the crank-slider's det Phi_q = b cos(rod.phi) and the
four-bar's b c sin(coupler.phi - rocker.phi) (closed forms, checked here by SymPy) vanish at
known angles.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from codegen_support import random_states, system

import symkin

MECHANISMS = ["crank_slider", "four_bar", "andrews_squeezer", "quick_return"]


def _lu_solve(kernel, nz: np.ndarray, b: np.ndarray) -> tuple[int, float, int, np.ndarray]:  # type: ignore[no-untyped-def]
    """(status, pivot ratio, dense fall-back used, x) of the generated LU on (nz, b)."""
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    lu = ffi.new(f"{name}_lu *")
    getattr(lib, f"{name}_lu_init")(lu)
    status = getattr(lib, f"{name}_lu_factor")(ffi.new("double[]", nz.tolist()), lu)
    ratio = getattr(lib, f"{name}_lu_pivot_ratio")(lu)
    x = ffi.new("double[]", b.tolist())
    if status == 0:
        getattr(lib, f"{name}_lu_solve")(lu, x)
    return status, ratio, lu.dense, np.array(ffi.unpack(x, len(b)))


@pytest.mark.parametrize("name", MECHANISMS)
def test_constant_pivots_solve_like_a_dense_lu(name: str) -> None:
    derived = system(name)
    kernel = symkin.compile(derived, backend="c", linalg="sparse")
    assert kernel.backend == "c"
    source = (kernel.folder / f"{name}_sparse_lu.c").read_text()
    assert "pivots are numbers known at generation time" in source
    rng = np.random.default_rng(3)
    sparse_path = 0
    for q, _, t, p in random_states(derived, count=60, seed=5):
        dense = kernel.phi_q(q, t, p)
        if np.linalg.cond(dense) > 1e8:
            continue
        b = rng.standard_normal(len(q))
        status, ratio, used_dense, x = _lu_solve(kernel, kernel.phi_q_nz(q, t, p), b)
        assert status == 0 and ratio > 0
        expected = np.linalg.solve(dense, b)
        assert np.abs(x - expected).max() <= 1e-9 * max(1.0, np.abs(expected).max())
        sparse_path += not used_dense
    assert sparse_path >= 20  # most states take the folded sparse path itself


@pytest.mark.parametrize("name, coordinate, angle", [
    ("crank_slider", "rod.phi", math.pi / 2), ("crank_slider", "rod.phi", -math.pi / 2)])
def test_singular_crank_slider_is_caught(name: str, coordinate: str, angle: float) -> None:
    derived = system(name)
    det = sp.factor(sp.Matrix(derived.phi_q).det())
    assert sp.simplify(det - derived.p[1] * sp.cos(derived.q[5])) == 0  # b cos(rod.phi)
    kernel = symkin.compile(derived, backend="c", linalg="sparse")
    assert kernel.backend == "c"
    for q, _, t, p in random_states(derived, count=10, seed=9):
        q[derived.coordinates.index(coordinate)] = angle
        status, ratio, _, _ = _lu_solve(kernel, kernel.phi_q_nz(q, t, p), np.ones(len(q)))
        assert status != 0 or ratio < 1e-10


def test_singular_four_bar_is_caught() -> None:
    derived = system("four_bar")
    kernel = symkin.compile(derived, backend="c", linalg="sparse")
    assert kernel.backend == "c"
    coupler, rocker = (derived.coordinates.index(c) for c in ("coupler.phi", "rocker.phi"))
    for q, _, t, p in random_states(derived, count=10, seed=10):
        q[coupler] = q[rocker]  # sin(coupler.phi - rocker.phi) = 0
        status, ratio, _, _ = _lu_solve(kernel, kernel.phi_q_nz(q, t, p), np.ones(len(q)))
        assert status != 0 or ratio < 1e-10


def test_a_non_finite_entry_is_caught() -> None:
    """Only the smallest constant pivot keeps a test; it still fails on inf and NaN."""
    derived = system("crank_slider")
    kernel = symkin.compile(derived, backend="c", linalg="sparse")
    q = np.zeros(len(derived.q))
    for bad in (math.inf, math.nan):
        nz = kernel.phi_q_nz(q, 0.0)
        nz[3] = bad
        status, ratio, _, _ = _lu_solve(kernel, nz, np.ones(len(q)))
        assert status != 0 or not ratio > 0
