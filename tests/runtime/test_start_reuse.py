"""The start check spends nothing a call need not: it judges a start from the condition
estimate the solver made of Phi_q at the first row (from the factors it had anyway) where
that suffices, and the lever arms of a configuration are worked out once.

References: the crank-slider's closed form (textbook Example 2.5, offset c: the slider's
x = a cos phi + sqrt(b^2 - (c - a sin phi)^2)), and NumPy's exact 1-norm condition numbers
for the bound clearly_regular relies on."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.contract.options import Options
from symkin.runtime.solving import start

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def crank_slider():
    mechanism = symkin.load(ROOT / "examples" / "crank_slider.yaml")
    return symkin.compile(symkin.derive(mechanism), backend="c")


def test_a_regular_start_is_judged_without_a_factorisation_of_its_own(crank_slider,
                                                                       monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the start check factored Phi_q itself")

    monkeypatch.setattr(start, "scaled_cond", refuse)
    monkeypatch.setattr(np.linalg, "inv", refuse)
    t = np.linspace(0.0, 1.5, 31)
    trajectory = symkin.solve(crank_slider, t=t)
    phi = t**2 + math.pi / 2  # the driver
    a, b, c = 1.0, 5.0, 4.0
    x = a * np.cos(phi) + np.sqrt(b**2 - (c - a * np.sin(phi)) ** 2)
    np.testing.assert_allclose(trajectory.q[:, crank_slider.coordinates.index("slider.x")], x,
                               atol=1e-9)


def test_without_an_estimate_the_check_factors(crank_slider, monkeypatch):
    calls = []
    real = start.scaled_cond
    monkeypatch.setattr(start, "scaled_cond", lambda *a: calls.append(1) or real(*a))
    q = symkin.solve(crank_slider, t=[0.0]).q[0]
    p = np.array(crank_slider.p_values, dtype=float)
    assert start.singular_start(crank_slider, q, 0.0, p, Options()) is None
    assert calls == [1]


@pytest.mark.parametrize("seed", range(20))
def test_the_bound_on_the_scaled_condition_holds(seed):
    """cond_1(R^-1 A C) <= cond_1(A) max(L, 1/L)^2 for C, R diagonal with entries 1 or L:
    what clearly_regular relies on, checked with exact condition numbers."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 12))
    a = rng.normal(size=(n, n))
    scale = float(10.0 ** rng.uniform(-3, 3))
    column = np.where(rng.random(n) < 0.5, scale, 1.0)
    row = np.where(rng.random(n) < 0.5, scale, 1.0)
    scaled = a * column[None, :] / row[:, None]
    exact = np.linalg.cond(scaled, 1)
    assert exact <= np.linalg.cond(a, 1) * max(scale, 1 / scale) ** 2 * (1 + 1e-9)


def test_lever_arms_are_kept_per_configuration(crank_slider):
    q = np.array(crank_slider.q0, dtype=float) + 0.1
    p = np.array(crank_slider.p_values, dtype=float)
    nz, scale = start.lever_arms(crank_slider, q, 0.0, p)
    assert start.lever_arms(crank_slider, q, 0.0, p)[0] is nz  # kept
    assert scale == start.length_scale(crank_slider, crank_slider.phi_q_nz(q, 0.0, p))
    angle = np.array([name.endswith(".phi") for name in crank_slider.coordinates])
    doubled = np.where(angle, q, 2 * q)  # every length doubled: so is the largest lever arm
    assert start.lever_arms(crank_slider, doubled, 0.0, 2 * p)[1] == \
        pytest.approx(2 * scale, rel=1e-12)


def test_the_generated_lever_arm_is_the_pythons(crank_slider):
    """lever_arm asks the generated <prefix>_length_scales; it must be the L that
    length_scale reads off Phi_q (the unit and the start are decided by it)."""
    p = np.array(crank_slider.p_values, dtype=float)
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = np.array(crank_slider.q0, dtype=float) + rng.normal(size=len(crank_slider.q0))
        python = start.length_scale(crank_slider, crank_slider.phi_q_nz(q, 0.3, p))
        assert start.lever_arm(crank_slider, q, 0.3, p) == pytest.approx(python, rel=1e-12)
