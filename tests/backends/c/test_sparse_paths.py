"""The sparse paths around the generated sparse LU.

- generation: the sparse LU's pivot order is chosen at the assembled configuration at t0
  (checked against Example 2.7's closed form), and at q0 when the mechanism cannot assemble;
- the Python driver: SuperLU (scipy.sparse.linalg.splu) from SPARSE_FROM coordinates on, checked
  against the dense LAPACK path and against numpy.linalg.solve;
- ``symkin run``'s note on fall-backs.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml
from driver_support import kernel_for

import symkin
from symkin import backends
from symkin.cli import run_outputs
from symkin.codegen import lower as codegen
from symkin.codegen import sample as codegen_sample
from symkin.runtime import driver
from symkin.runtime.solving import linalg
from symkin.spec import validate as model

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


def crank_slider_q(t: float, a: float = 1.0, b: float = 5.0, c: float = 4.0) -> np.ndarray:
    """Example 2.7's closed form of the textbook crank-slider."""
    phi1 = t**2 + math.pi / 2
    x2, y2 = a * math.cos(phi1), a * math.sin(phi1)
    phi2 = math.asin((c - y2) / b)
    return np.array([0, 0, phi1, x2, y2, phi2, x2 + b * math.cos(phi2), c, 0])


def test_sample_configuration_is_the_assembled_position(crank_slider_system) -> None:
    # the file's q0 is the chapter's q = 0, far from the assembled position
    assert not np.allclose(crank_slider_system.q0, crank_slider_q(0.0), atol=0.1)
    sample = np.array(codegen_sample.sample_configuration(crank_slider_system))
    np.testing.assert_allclose(sample, crank_slider_q(0.0), atol=1e-9)


def test_sample_configuration_falls_back_to_q0_when_assembly_fails() -> None:
    data = yaml.safe_load((EXAMPLES / "crank_slider.yaml").read_text())
    data["parameters"]["c"] = 10.0  # the slider's guide beyond the reach of crank + rod (6)
    system = symkin.derive(model.from_dict(data))
    assert codegen_sample.sample_configuration(system) == tuple(system.q0)
    code = codegen.lower(system, backends.get("c"))  # the plan is still made (at q0), generation goes on
    assert code.options["linalg"] == "sparse" and code.lu_plan is not None and code.lu_plan.n_lu >= code.nnz


def test_sparse_lu_is_the_default(crank_slider_system, tmp_path) -> None:
    written = {p.name for p in symkin.generate(crank_slider_system, backend="c",
                                               out_dir=tmp_path)}
    assert "crank_slider_sparse_lu.c" in written and "crank_slider_linalg.c" not in written


def test_python_driver_sparse_path_matches_dense(crank_slider_system, monkeypatch) -> None:
    kernel = kernel_for(crank_slider_system, "numpy")
    times = driver.grid(0.0, 1.5, 0.01)
    dense = driver.solve(kernel, t=times)
    monkeypatch.setattr(linalg, "SPARSE_FROM", 1)
    assert isinstance(linalg.factor_at(kernel, dense.q[5], times[5], kernel.p_values),
                      linalg.SparseFactors)
    sparse = driver.solve(kernel, t=times)
    for name in ("q", "dq", "d2q"):
        assert np.abs(getattr(sparse, name) - getattr(dense, name)).max() <= 1e-12, name
    reference = np.array([crank_slider_q(t) for t in times])
    assert np.abs(sparse.q - reference).max() <= 1e-9


def test_factor_sparse_solves_and_judges_singularity() -> None:
    rng = np.random.default_rng(7)
    n = 120
    rows = np.r_[np.arange(n), np.arange(1, n), rng.integers(0, n, 40)]
    cols = np.r_[np.arange(n), np.arange(n - 1), rng.integers(0, n, 40)]
    pattern = sorted(set(zip(rows.tolist(), cols.tolist())))
    rows, cols = (np.array(v) for v in zip(*pattern))
    values = rng.uniform(0.5, 2.0, rows.size) * np.where(rows == cols, 10.0, 1.0)
    a = np.zeros((n, n))
    a[rows, cols] = values
    b = rng.normal(size=n)
    factors = linalg.factor_sparse(n, rows, cols, values)
    np.testing.assert_allclose(factors.solve(b), np.linalg.solve(a, b), rtol=1e-10, atol=1e-12)
    # SuperLU orders rows and columns its own way, so its pivots differ from LAPACK's
    assert 0.0 < factors.pivot_ratio <= 1.0
    singular = values.copy()
    singular[(rows == 3)] = 0.0  # an empty row
    assert linalg.factor_sparse(n, rows, cols, singular).pivot_ratio == 0.0
    assert linalg.factor_sparse(n, rows, cols, np.full(values.size, np.nan)).pivot_ratio == 0.0


def test_run_mentions_fallbacks_and_that_they_cost_no_accuracy() -> None:
    assert run_outputs.fallback_note(1, 31).startswith("1 pivot fall-back to dense LU over 31")
    note = run_outputs.fallback_note(3, 31)
    assert note.startswith("3 pivot fall-backs to dense LU") and "not accuracy" in note
    # one short line by default (every run of such a mechanism prints it); the why with -v
    assert len(note) < 100 and note.endswith("-v says why)")
    verbose = run_outputs.fallback_note(3, 31, verbose=True)
    assert "redone with dense LU and partial pivoting" in verbose and "-v" not in verbose
