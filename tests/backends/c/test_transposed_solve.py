"""The generated sparse LU's transposed solve (A^T x = b, needed by the condition estimate),
compiled with gcc and checked against numpy.linalg.solve with A^T at random states.

Straight-line code (one statement per operation, Phi_q's numbers folded in) on the lazy tongs,
whose factorization has fill-in, at a small size (one function per sweep) and at a size where
the sweeps are split into bounded parts and the permutations become tables; the table-driven
style; the dense fall-back at values the fixed pivot order refuses.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from sparse_lu_harness import build, render

from symkin.backends.c import lu_code
from symkin.codegen import lu_plan as sparse_lu
from symkin.spec import validate as model
from symkin.symbolic import derivation

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "bench"))


class Tongs:
    """Lazy tongs of ``units`` scissor units: Phi_q's pattern, known entries and values."""

    def __init__(self, units: int) -> None:
        import scaling_limit

        self.system = derivation.derive(model.from_dict(scaling_limit.tongs(units)))
        pattern = self.system.pattern()
        self.rows = np.array([r for r, _ in pattern])
        self.cols = np.array([c for _, c in pattern])
        self.n = len(self.system.q)
        entries = [self.system.phi_q[r, c] for r, c in pattern]
        self.constants = [float(e) if e.is_Number else None for e in entries]
        self._nz = sp.lambdify([self.system.q, self.system.t, self.system.p], entries, "math")
        self.q0 = np.array(self.system.q0, dtype=float)
        self.plan = sparse_lu.analyse(self.n, self.rows, self.cols, self.nz(self.q0))

    def nz(self, q: np.ndarray) -> np.ndarray:
        return np.array(self._nz(list(q), 0.0, self.system.p_values), dtype=float)

    def dense(self, nz: np.ndarray) -> np.ndarray:
        a = np.zeros((self.n, self.n))
        a[self.rows, self.cols] = nz
        return a


@pytest.fixture(scope="module")
def small() -> Tongs:
    return Tongs(5)


@pytest.fixture(scope="module")
def large() -> Tongs:
    return Tongs(50)  # 100 bodies, N = 300: parts and permutation tables


def _check(case: Tongs, folder: Path, style: str, states: int = 20,
           spread: float = 0.1) -> np.ndarray:
    """Random states near q0 (the fixed order holds there) and random right-hand sides: the C
    transposed solve against numpy's solve with A^T. Returns the fall-back flags."""
    lib = build(folder, "tongs", case.n, case.rows, case.cols, case.plan, style=style,
                constants=case.constants)
    rng = np.random.default_rng(11)
    q = case.q0 + spread * rng.normal(size=(states, case.n))
    nz = np.array([case.nz(x) for x in q])
    b = rng.normal(size=(states, case.n))
    x, status, dense = lib.solve_transposed(nz, b)
    for k in range(states):
        assert status[k] == 0
        expected = np.linalg.solve(case.dense(nz[k]).T, b[k])
        np.testing.assert_allclose(x[k], expected, rtol=0,
                                   atol=1e-10 * max(1.0, np.abs(expected).max()))
    return dense


def test_fill_in_straight_line(small: Tongs, tmp_path: Path) -> None:
    assert small.plan.n_lu > small.plan.nnz  # the factorization has fill-in
    lu = lu_code.template_context(small.plan, constants=small.constants, prefix="tongs")
    assert lu["style"] == "straight" and len(lu["upper_t_parts"]) == 1
    source = render("tongs", small.n, small.rows, small.cols, small.plan,
                    constants=small.constants)["tongs_sparse_lu.c"]
    transposed = source[source.index("void tongs_lu_solve_transposed"):]
    assert "for (" not in transposed  # straight-line: no loop over index tables
    assert not _check(small, tmp_path, "straight").any()


def test_split_straight_line(large: Tongs, tmp_path: Path) -> None:
    lu = lu_code.template_context(large.plan, constants=large.constants, prefix="tongs")
    assert lu["style"] == "straight" and lu["perm_tables"]
    assert len(lu["upper_t_parts"]) > 1 and len(lu["lower_t_parts"]) > 1
    assert not _check(large, tmp_path, "straight", states=8, spread=0.02).any()


def test_tables_style(small: Tongs, tmp_path: Path) -> None:
    assert not _check(small, tmp_path, "tables").any()


def test_dense_fall_back(small: Tongs, tmp_path: Path) -> None:
    """Unrelated values make the fixed order fail: the dense LU's transposed solve answers."""
    lib = build(tmp_path, "tongs", small.n, small.rows, small.cols, small.plan,
                style="straight", constants=small.constants)
    rng = np.random.default_rng(3)
    nz = rng.normal(size=(60, len(small.rows)))
    known = [e for e, c in enumerate(small.constants) if c is not None]
    nz[:, known] = [small.constants[e] for e in known]  # the numbers stay numbers
    b = rng.normal(size=(60, small.n))
    x, status, dense = lib.solve_transposed(nz, b)
    assert dense.any()
    checked = 0
    for k in range(60):
        a = small.dense(nz[k])
        if dense[k] and status[k] == 0 and np.linalg.cond(a) < 1e8:
            checked += 1
            expected = np.linalg.solve(a.T, b[k])
            np.testing.assert_allclose(x[k], expected, rtol=0,
                                       atol=1e-8 * max(1.0, np.abs(expected).max()))
    assert checked >= 5
