"""The two C styles of one sparse LU plan agree: straight-line code (Phi_q's numbers folded in)
and loops over index tables (what symkin emits above ``lu_code.TABLE_FLOPS`` operations).

Both are compiled with gcc from the same plan of the lazy tongs, whose factorization has
fill-in, at a small size and at one where the straight-line code is split into parts; the
solves and the transposed solves must agree to 1e-12, each also with numpy, and where the
fixed pivot order is unsafe both must stop at the same pivot and take the dense fall-back.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from sparse_lu_harness import Library, build

from symkin.backends.c import lu_code
from symkin.codegen import lu_plan as sparse_lu
from symkin.spec import validate as model
from symkin.symbolic import derivation

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "bench"))

STYLES = ("straight", "tables")


class Tongs:
    """Lazy tongs of ``units`` scissor units, their plan and both compiled styles."""

    def __init__(self, units: int, folder: Path) -> None:
        import scaling_limit

        system = derivation.derive(model.from_dict(scaling_limit.tongs(units)))
        pattern = system.pattern()
        self.rows = np.array([r for r, _ in pattern])
        self.cols = np.array([c for _, c in pattern])
        self.n = len(system.q)
        entries = [system.phi_q[r, c] for r, c in pattern]
        self.constants = [float(e) if e.is_Number else None for e in entries]
        self._nz = sp.lambdify([system.q, system.t, system.p], entries, "math")
        self._p = system.p_values
        self.q0 = np.array(system.q0, dtype=float)
        self.plan = sparse_lu.analyse(self.n, self.rows, self.cols, self.nz(self.q0))
        self.libs: dict[str, Library] = {
            style: build(folder / style, "tongs", self.n, self.rows, self.cols, self.plan,
                         style=style, constants=self.constants) for style in STYLES}

    def nz(self, q: np.ndarray) -> np.ndarray:
        return np.array(self._nz(list(q), 0.0, self._p), dtype=float)

    def dense(self, nz: np.ndarray) -> np.ndarray:
        a = np.zeros((self.n, self.n))
        a[self.rows, self.cols] = nz
        return a


# 30 units (180 coordinates) is the smallest size at which every straight-line routine
# (factor, forward, backward and both transposed) is split into parts, as at 50.
SPLIT = 30


@pytest.fixture(scope="module", params=[5, SPLIT], ids=["tongs5", f"tongs{SPLIT}"])
def tongs(request, tmp_path_factory) -> Tongs:
    return Tongs(request.param, tmp_path_factory.mktemp(f"tongs{request.param}"))


def test_the_plan_has_fill_in_and_both_styles_are_what_they_say(tongs: Tongs) -> None:
    assert tongs.plan.n_lu > tongs.plan.nnz
    for style in STYLES:
        lu = lu_code.template_context(tongs.plan, style=style, constants=tongs.constants,
                                      prefix="tongs")
        assert lu["style"] == style
        if style == "straight":
            parts = {key: len(value) for key, value in lu.items() if key.endswith("_parts")}
            assert len(parts) == 5
            assert all(count >= 2 for count in parts.values()) == (tongs.n > 100), parts


def test_solves_agree_to_1e_12(tongs: Tongs) -> None:
    rng = np.random.default_rng(7)
    q = tongs.q0 + 0.02 * rng.normal(size=(8, tongs.n))
    nz = np.array([tongs.nz(x) for x in q])
    b = rng.normal(size=(8, tongs.n))
    x, status, dense, _, fallbacks = tongs.libs["straight"].solve(nz, b)
    y, status_t, dense_t, _, fallbacks_t = tongs.libs["tables"].solve(nz, b)
    assert not status.any() and not status_t.any() and fallbacks == fallbacks_t == 0
    assert not dense.any() and not dense_t.any()
    xt, _, _ = tongs.libs["straight"].solve_transposed(nz, b)
    yt, _, _ = tongs.libs["tables"].solve_transposed(nz, b)
    for k in range(len(b)):
        scale = max(1.0, np.abs(x[k]).max())
        np.testing.assert_allclose(y[k], x[k], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(yt[k], xt[k], rtol=0,
                                   atol=1e-12 * max(1.0, np.abs(xt[k]).max()))
        a = tongs.dense(nz[k])
        np.testing.assert_allclose(x[k], np.linalg.solve(a, b[k]), rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(xt[k], np.linalg.solve(a.T, b[k]), rtol=0,
                                   atol=1e-9 * max(1.0, np.abs(xt[k]).max()))


def test_both_styles_refuse_the_same_pivot(tongs: Tongs) -> None:
    """Unrelated values (Phi_q's numbers kept): the fixed order fails at the same pivot in
    both styles, each takes the dense fall-back, and both answers still solve the system."""
    rng = np.random.default_rng(3)
    nz = rng.normal(size=(40, len(tongs.rows)))
    known = [e for e, c in enumerate(tongs.constants) if c is not None]
    nz[:, known] = [tongs.constants[e] for e in known]
    b = rng.normal(size=(40, tongs.n))
    x, status, dense, failed, fallbacks = tongs.libs["straight"].solve(nz, b)
    y, status_t, dense_t, failed_t, fallbacks_t = tongs.libs["tables"].solve(nz, b)
    assert dense.any() and fallbacks == int(dense.sum()) == fallbacks_t
    assert failed.tolist() == failed_t.tolist() and dense.tolist() == dense_t.tolist()
    assert status.tolist() == status_t.tolist()
    for k in np.flatnonzero(status == 0):
        np.testing.assert_allclose(y[k], x[k], rtol=0, atol=1e-12 * max(1.0, np.abs(x[k]).max()))
