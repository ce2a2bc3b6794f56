"""The redundancy analysis evaluates Phi_q from each row's structural non-zeros (the
derivatives the derivation keeps), not from a dense symbolic Jacobian: on every file with
redundant or dependent rows it removes the same rows, with the same rank and mobility, as
the analysis run on SymPy's own dense Jacobian, and its Phi_q is Phi's central finite
difference at the assembled configuration."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import sympy as sp

import symkin
from symkin.symbolic import redundancy

ROOT = Path(__file__).resolve().parents[2]
FILES = [
    "examples/parallelogram_extra_bar.yaml",
    "examples/parallelogram_extra_bar_loads.yaml",
    "examples/cardan.yaml",
    "tests/mechanisms/pendulum_two_drivers.yaml",
    "tests/trust/spherical_four_bar.yaml",
    "bench/iftomm/a04_bricard.yaml",
]


_DERIVED: dict[str, tuple[Any, dict[str, Any]]] = {}


def _analysed(name: str) -> tuple[Any, dict[str, Any]]:
    """The derived system and the arguments its derivation gave the analysis (each file
    derived once for the module's tests)."""
    if name not in _DERIVED:
        seen: dict[str, Any] = {}
        original = redundancy.analyse

        def spy(*args: Any, **kwargs: Any) -> redundancy.Finding:
            seen["args"], seen["kwargs"] = args, kwargs
            seen["finding"] = original(*args, **kwargs)
            return seen["finding"]

        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(redundancy, "analyse", spy)
            _DERIVED[name] = symkin.derive(ROOT / name), seen
    return _DERIVED[name]


@pytest.mark.parametrize("name", FILES)
def test_the_sparse_jacobian_removes_what_the_dense_one_removes(name: str) -> None:
    system, seen = _analysed(name)
    assert "finding" in seen, f"{name} has no redundancy analysis"
    phi, q = seen["args"][0], seen["args"][1]
    dense = sp.Matrix(phi).jacobian(list(q))  # SymPy's own derivatives, zeros and all
    entries = [{k: dense[r, k] for k in range(len(q)) if dense[r, k] != 0}
               for r in range(len(phi))]
    reference = redundancy.analyse(*seen["args"], **{**seen["kwargs"], "entries": entries})
    found = seen["finding"]
    assert (found.kept, found.removed, found.rank, found.mobility) == (
        reference.kept, reference.removed, reference.rank, reference.mobility)
    assert [item.index for item in system.removed] == list(found.removed)
    assert len(system.rows) == len(found.kept)


@pytest.mark.parametrize("name", FILES[:3] + FILES[-1:])
def test_phi_q_is_the_finite_difference_of_phi(name: str) -> None:
    """At the assembled configuration (and one moved off it), Phi_q's every entry, zeros
    included, against Phi's central difference (error ~ h^2 |Phi'''|, h = 1e-6)."""
    system, _ = _analysed(name)
    rows = list(system.phi) + [item.phi for item in system.removed]
    equations = redundancy._Equations(rows, system.q, system.t, system.p, system.p_values)
    t0 = float(system.time_grid[0])
    start = np.array(system.q0, dtype=float)
    for q in (start, start + 0.01 * np.sin(np.arange(len(start)) + 1.0)):
        jacobian = equations.phi_q(q, t0)
        h = 1e-6
        columns = [(equations.phi(q + h * e, t0) - equations.phi(q - h * e, t0)) / (2 * h)
                   for e in np.eye(len(q))]
        np.testing.assert_allclose(jacobian, np.array(columns).T, rtol=0, atol=1e-7)
