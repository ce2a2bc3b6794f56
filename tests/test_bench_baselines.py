"""The benchmark's baselines and scaling family are right before they are timed.

References: Example 2.7's closed form (itself checked by central differences) and loop
closure of the four-bar chain at its geometric closed form.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from symkin.spec import validate as model
from symkin.symbolic import derivation

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

import scaling_family
from baselines import handwritten_c, lambdify_driver, reference, textbook_numpy

STEPS = 30  # the chapter's own grid, dt = 0.05


def test_closed_form_derivatives_match_central_differences() -> None:
    t = np.linspace(0.1, 1.4, 7)
    h = 1e-5
    q_plus, dq_plus, _ = reference.closed_form(t + h)
    q_minus, dq_minus, _ = reference.closed_form(t - h)
    _, dq, d2q = reference.closed_form(t)
    np.testing.assert_allclose((q_plus - q_minus) / (2 * h), dq, atol=1e-7)
    np.testing.assert_allclose((dq_plus - dq_minus) / (2 * h), d2q, atol=1e-6)


def test_literal_textbook_port_on_the_chapters_grid() -> None:
    t, q, dq, d2q = textbook_numpy.KorbWodz(dt=0.05, steps=STEPS)
    assert max(reference.errors(t, q.T, dq.T, d2q.T)) < 1e-9


def test_lambdify_driver(crank_slider_path: Path) -> None:
    t = reference.grid(STEPS)
    q, dq, d2q = lambdify_driver.solve_grid(lambdify_driver.derive(crank_slider_path), t,
                                            np.zeros(9))
    assert max(reference.errors(t, q, dq, d2q)) < 1e-9


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
@pytest.mark.parametrize("build", [handwritten_c.build_dense, handwritten_c.build_sparse])
def test_hand_written_c(build, tmp_path: Path) -> None:
    result = build(tmp_path).solve_grid(STEPS, 0.05)
    assert max(reference.errors(reference.grid(STEPS), result.q, result.dq, result.d2q)) < 1e-9
    assert result.fallbacks == 0


def test_four_bar_chain_assembles_at_its_closed_form() -> None:
    loops = 4
    mech = model.from_dict(scaling_family.chain(loops))
    system = derivation.derive(mech)
    assert len(system.q) == 3 * scaling_family.bodies_of(loops)
    assert system.dof == len(mech.drivers) == 1
    import sympy as sp

    phi = sp.lambdify([system.q, system.t, system.p], list(system.phi), "math")
    assert np.allclose(system.q0, scaling_family.closed_form(loops, 0.0)[0])
    for t in (0.0, 0.8, 2.5):
        q = scaling_family.closed_form(loops, t)[0]
        assert np.abs(phi(list(q), t, system.p_values)).max() < 1e-12
