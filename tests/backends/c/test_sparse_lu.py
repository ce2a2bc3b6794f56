"""The generated straight-line sparse LU, compiled with gcc and checked against numpy.

References: numpy.linalg.solve for the solutions, and a dense elimination written here (no
pivoting, on the permuted matrix) for which pivot must fail the run-time ratio test.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from sparse_lu_harness import build, render

from symkin.codegen import lu_interchange
from symkin.codegen import lu_plan as sparse_lu
from symkin.errors import SolveError
from symkin.spec import validate as model
from symkin.symbolic import derivation

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
ROOT = Path(__file__).resolve().parents[3]


def _family():
    spec = importlib.util.spec_from_file_location("scaling_family",
                                                  ROOT / "bench" / "scaling_family.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class Case:
    """A system, its pattern and a compiled sparse LU for it."""

    def __init__(self, system: derivation.System, sample_q: np.ndarray, folder: Path,
                 style: str) -> None:
        self.system = system
        pattern = system.pattern()
        self.rows = np.array([r for r, _ in pattern])
        self.cols = np.array([c for _, c in pattern])
        self.n = len(system.q)
        self._nz = sp.lambdify([system.q, system.t, system.p],
                               [system.phi_q[r, c] for r, c in pattern], "math")
        self.plan = sparse_lu.analyse(self.n, self.rows, self.cols, self.nz(sample_q, 0.0))
        self.style = style
        self.lib = build(folder, system.name, self.n, self.rows, self.cols, self.plan,
                         style=style)

    def nz(self, q: np.ndarray, t: float) -> np.ndarray:
        return np.array(self._nz(list(q), t, self.system.p_values), dtype=float)

    def dense(self, nz: np.ndarray) -> np.ndarray:
        a = np.zeros((self.n, self.n))
        a[self.rows, self.cols] = nz
        return a


def crank_slider_q(t: float, a: float = 1.0, b: float = 5.0, c: float = 4.0) -> np.ndarray:
    """Example 2.7's closed form."""
    phi1 = t**2 + math.pi / 2
    x2, y2 = a * math.cos(phi1), a * math.sin(phi1)
    phi2 = math.asin((c - y2) / b)
    return np.array([0, 0, phi1, x2, y2, phi2, x2 + b * math.cos(phi2), c, 0])


STYLES = ["straight", "tables"]  # one C statement per operation, or loops over index tables


@pytest.fixture(scope="module", params=STYLES)
def crank(crank_slider_system, tmp_path_factory, request) -> Case:
    return Case(crank_slider_system, np.array(crank_slider_system.q0),
                tmp_path_factory.mktemp("crank"), request.param)


@pytest.fixture(scope="module")
def chain_system() -> derivation.System:
    return derivation.derive(model.from_dict(_family().chain(10)))


@pytest.fixture(scope="module", params=STYLES)
def chain(chain_system, tmp_path_factory, request) -> Case:
    family = _family()
    system = chain_system
    case = Case(system, np.array(system.q0), tmp_path_factory.mktemp("chain"), request.param)
    case.closed_form = lambda t: family.closed_form(10, t)[0]
    return case


def expected_failure(case: Case, nz: np.ndarray) -> int:
    """First pivot k (1-based) that is tiny or fails the ratio test in plain elimination of A[P][:, Q]."""
    a = case.dense(nz)[np.ix_(case.plan.row_perm, case.plan.col_perm)]
    tiny = case.n * np.finfo(float).eps * np.abs(nz).max()
    for k in range(case.n):
        column = np.abs(a[k:, k])
        if not (abs(a[k, k]) > tiny and abs(a[k, k]) >= case.plan.tau * column.max()):
            return k + 1
        a[k + 1:, k] /= a[k, k]
        a[k + 1:, k + 1:] -= np.outer(a[k + 1:, k], a[k, k + 1:])
    return 0


def test_crank_slider_along_the_motion_uses_the_sparse_path(crank: Case) -> None:
    times = np.linspace(0.0, 1.5, 31)
    nz = np.array([crank.nz(crank_slider_q(t), t) for t in times])
    b = np.random.default_rng(1).normal(size=(len(times), crank.n))
    x, status, dense, _, fallbacks = crank.lib.solve(nz, b)
    assert status.tolist() == [0] * len(times) and fallbacks == 0 and not dense.any()
    for k in range(len(times)):
        np.testing.assert_allclose(x[k], np.linalg.solve(crank.dense(nz[k]), b[k]),
                                   rtol=1e-12, atol=1e-12)


def static_pivots(case: Case, nz: np.ndarray) -> np.ndarray:
    """|u_kk| of plain elimination (no pivoting) of A[P][:, Q]."""
    a = case.dense(nz)[np.ix_(case.plan.row_perm, case.plan.col_perm)]
    for k in range(case.n - 1):
        a[k + 1:, k] /= a[k, k]
        a[k + 1:, k + 1:] -= np.outer(a[k + 1:, k], a[k, k + 1:])
    return np.abs(np.diag(a))


def test_pivot_ratio_on_both_paths(chain: Case) -> None:
    rng = np.random.default_rng(6)
    base = chain.nz(chain.closed_form(1.1), 1.1)
    step = next(s for s in chain.plan.steps if s.lower)
    shrunk = base.copy()
    shrunk[step.pivot] *= 1e-9  # forces the dense fall-back
    _, status, dense, _, _ = chain.lib.solve(np.vstack([base, shrunk]),
                                             rng.normal(size=(2, chain.n)))
    assert status.tolist() == [0, 0] and dense.tolist() == [0, 1]
    pivots = static_pivots(chain, base)
    assert chain.lib.ratios[0] == pytest.approx(pivots.min() / pivots.max(), rel=1e-12)
    # dense path: partial pivoting's |u_kk|, from scipy's LU of the same matrix
    import scipy.linalg

    u = np.abs(np.diag(scipy.linalg.lu(chain.dense(shrunk))[2]))
    assert chain.lib.ratios[1] == pytest.approx(u.min() / u.max(), rel=1e-9)


def test_crank_slider_pattern_needs_no_fill(crank: Case) -> None:
    # The textbook Jacobian (Example 2.5 j) is a permuted triangular matrix.
    assert crank.plan.n_lu == crank.plan.nnz == 17
    assert sorted(crank.plan.row_perm) == sorted(crank.plan.col_perm) == list(range(9))


def test_random_values_on_the_crank_slider_pattern(crank: Case) -> None:
    rng = np.random.default_rng(2)
    nz = rng.normal(size=(200, crank.plan.nnz))
    b = rng.normal(size=(200, crank.n))
    x, status, _, failed, _ = crank.lib.solve(nz, b)
    assert status.tolist() == [0] * 200
    for k in range(200):
        assert failed[k] == expected_failure(crank, nz[k])
        np.testing.assert_allclose(crank.dense(nz[k]) @ x[k], b[k], rtol=0, atol=1e-9)


def test_singular_crank_slider_is_reported(crank: Case) -> None:
    # Rod vertical (phi2 = pi/2): the slider cannot be driven, Phi_q is singular.
    q = np.array([0, 0, math.pi / 2, 0, 1, math.pi / 2, 0, 6, 0], dtype=float)
    nz = crank.nz(q, 0.0)
    assert np.linalg.matrix_rank(crank.dense(nz)) < crank.n
    _, status, dense, failed, fallbacks = crank.lib.solve(nz, np.ones(crank.n))
    assert status[0] > 0 and failed[0] > 0 and dense[0] == 1 and fallbacks == 1


def test_chain_of_four_bars_along_the_motion(chain: Case) -> None:
    rng = np.random.default_rng(3)
    times = np.linspace(0.0, 6.0, 25)
    nz = np.array([chain.nz(chain.closed_form(t), t) for t in times])
    b = rng.normal(size=(len(times), chain.n))
    x, status, dense, _, fallbacks = chain.lib.solve(nz, b)
    assert status.tolist() == [0] * len(times) and fallbacks == 0 and not dense.any()
    for k in range(len(times)):
        expected = np.linalg.solve(chain.dense(nz[k]), b[k])
        np.testing.assert_allclose(x[k], expected, rtol=1e-10, atol=1e-10 * abs(expected).max())


def test_chain_plan_is_sparse(chain: Case) -> None:
    assert chain.n == 63
    assert chain.plan.n_lu <= 2 * chain.plan.nnz  # fill stays O(n) on a chain
    assert chain.plan.unchecked == ()


def test_near_singular_pivot_falls_back_to_a_correct_answer(chain: Case) -> None:
    """Shrink each checked pivot in turn: the ratio test must fail there, the answer stay right."""
    rng = np.random.default_rng(4)
    base = chain.nz(chain.closed_form(0.3), 0.3)
    checked = [s for s in chain.plan.steps if s.lower][:8]
    assert checked, "the chain's plan should have pivots with sub-diagonal entries"
    for step in checked:
        nz = base.copy()
        nz[step.pivot] *= 1e-9  # the entry's value is untouched by earlier steps only at k = 0
        expected_k = expected_failure(chain, nz)
        b = rng.normal(size=chain.n)
        x, status, dense, failed, fallbacks = chain.lib.solve(nz, b)
        a = chain.dense(nz)
        if expected_k == 0:
            assert failed[0] == 0 and not dense[0]
        else:
            assert failed[0] == expected_k and dense[0] == 1 and fallbacks == 1
        assert status[0] == 0
        np.testing.assert_allclose(x[0], np.linalg.solve(a, b), rtol=1e-6,
                                   atol=1e-6 * abs(np.linalg.solve(a, b)).max())
    # the first pivot's value is the raw entry: shrinking it must trigger the fall-back
    first = chain.plan.steps[0]
    if first.lower:
        nz = base.copy()
        nz[first.pivot] *= 1e-9
        assert chain.lib.solve(nz, np.ones(chain.n))[3][0] == 1


def _random_pattern(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random pattern with at most 6 entries a row, made structurally non-singular."""
    cells = {(i, j) for i, j in enumerate(rng.permutation(n))}
    for i in range(n):
        cells |= {(i, int(j)) for j in rng.choice(n, size=rng.integers(1, 6), replace=False)}
    cells = sorted(cells)
    return np.array([c[0] for c in cells]), np.array([c[1] for c in cells])


@pytest.mark.parametrize("style", STYLES)
def test_random_sparse_patterns(style: str, tmp_path: Path) -> None:
    """Values near the sample keep the fixed order; unrelated values mostly fall back."""
    rng = np.random.default_rng(5)
    n = 60
    rows, cols = _random_pattern(n, rng)
    sample = rng.normal(size=len(rows))
    plan = sparse_lu.analyse(n, rows, cols, sample)
    assert plan.n_lu > plan.nnz and any(s.updates for s in plan.steps)  # fill is exercised
    lib = build(tmp_path, "rnd", n, rows, cols, plan, style=style)
    near = sample * (1 + 0.05 * rng.normal(size=(30, len(rows))))
    nz = np.vstack([near, rng.normal(size=(30, len(rows)))])
    b = rng.normal(size=(60, n))
    x, status, dense, failed, fallbacks = lib.solve(nz, b)
    assert fallbacks == int(dense.sum()) == int((failed > 0).sum())
    assert dense[:30].sum() < 5 and dense[30:].sum() > 0
    for k in range(60):
        a = np.zeros((n, n))
        a[rows, cols] = nz[k]
        assert status[k] == 0
        np.testing.assert_allclose(a @ x[k], b[k], rtol=0, atol=1e-8 * np.abs(x[k]).max())
        if not dense[k]:  # the Python executor of the plan takes the same sparse path
            np.testing.assert_allclose(lu_interchange.solve_with_plan(plan, nz[k], b[k]), x[k],
                                       rtol=1e-9, atol=1e-9 * np.abs(x[k]).max())


def test_rendering_is_deterministic(crank: Case) -> None:
    once = render("crank_slider", crank.n, crank.rows, crank.cols, crank.plan)
    again = render("crank_slider", crank.n, crank.rows, crank.cols,
                   sparse_lu.analyse(crank.n, crank.rows, crank.cols,
                                     crank.nz(np.zeros(crank.n), 0.0)))
    assert once == again


def test_structurally_singular_pattern_is_refused() -> None:
    # column 2 is empty: coordinate 2 is not constrained by any equation
    with pytest.raises(SolveError, match="structurally singular"):
        sparse_lu.analyse(3, [0, 1, 2], [0, 1, 1], [1.0, 1.0, 1.0])


def test_bad_pattern_input() -> None:
    with pytest.raises(ValueError, match="twice"):
        sparse_lu.analyse(2, [0, 0, 1], [0, 0, 1], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="outside"):
        sparse_lu.analyse(2, [0, 2], [0, 1], [1.0, 1.0])


@pytest.mark.parametrize("compiler", ["gcc", "clang", "arm-none-eabi-gcc"])
def test_float_build_compiles_cleanly(compiler: str, chain: Case, tmp_path: Path) -> None:
    """real = float (fabsf, FLT_EPSILON) under the contract's flags, also for a Cortex-M4."""
    if shutil.which(compiler) is None:
        pytest.skip(f"{compiler} is not installed")
    import subprocess

    from sparse_lu_harness import write_sources

    sources = write_sources(tmp_path, "chain10", chain.n, chain.rows, chain.cols, chain.plan,
                            real="float", style=chain.style)
    target = ["-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv4-sp-d16"] \
        if compiler.startswith("arm") else []
    for source in sources:
        done = subprocess.run([compiler, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror",
                               "-O2", *target, "-c", str(source), "-o",
                               str(tmp_path / (source.stem + ".o"))],
                              capture_output=True, text=True, check=False)
        assert done.returncode == 0, done.stderr


def test_singular_sample_still_gives_a_guarded_order(crank: Case) -> None:
    """An all-zero sample checks nothing at generation; the run-time test still decides."""
    plan = sparse_lu.analyse(crank.n, crank.rows, crank.cols, np.zeros(crank.plan.nnz))
    assert plan.unchecked == tuple(range(crank.n))
    t = 0.7
    nz = crank.nz(crank_slider_q(t), t)
    b = np.arange(1.0, crank.n + 1)
    np.testing.assert_allclose(lu_interchange.solve_with_plan(plan, nz, b),
                               np.linalg.solve(crank.dense(nz), b), rtol=1e-12)


def test_pivot_order_does_not_follow_the_last_bits_of_the_sample() -> None:
    """Two entries of one column that both pass the threshold test: which is larger by one
    rounding error must not decide the order (it did when magnitudes broke ties)."""
    rows, cols = [0, 0, 1, 1], [0, 1, 0, 1]
    tie = 1.0 + 2.0**-52
    first = sparse_lu.analyse(2, rows, cols, [1.0, 2.0, tie, 3.0])
    second = sparse_lu.analyse(2, rows, cols, [tie, 2.0, 1.0, 3.0])
    assert first.row_perm == second.row_perm and first.col_perm == second.col_perm
    assert first.steps == tuple(dataclasses.replace(s, sample_ratio=f.sample_ratio)
                                for s, f in zip(second.steps, first.steps))


def test_numeric_check_only_rejects_the_structural_order() -> None:
    """The structural order pivots on (0, 0) first; a zero there in the sample rejects it and
    the threshold-restricted alternative pivots on (0, 1), the first entry by position that
    passes (|1| >= 0.1 * 3), with every pivot checked."""
    rows, cols = [0, 0, 1, 1], [0, 1, 0, 1]
    accepted = sparse_lu.analyse(2, rows, cols, [1.0, 1.0, 1.0, 3.0])
    rejected = sparse_lu.analyse(2, rows, cols, [0.0, 1.0, 1.0, 3.0])
    assert (accepted.row_perm, accepted.col_perm, accepted.unchecked) == ((0, 1), (0, 1), ())
    assert (rejected.row_perm, rejected.col_perm, rejected.unchecked) == ((0, 1), (1, 0), ())
    assert rejected.steps[0].sample_ratio == pytest.approx(1 / 3)
