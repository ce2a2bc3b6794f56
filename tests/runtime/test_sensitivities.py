"""Design sensitivities q_p = dq/dp from Phi_q q_p = -Phi_p (Phi_p derived symbolically), and
the velocity sensitivities dq_p from its time derivative.

References: central finite differences of solve() over the parameters; for the textbook
crank-slider, the derivative of Example 2.7's closed form with respect to a, b, c, written out
here: with phi1 = t^2 + pi/2, s = (c - a sin phi1)/b, phi2 = asin s,
    d phi2/da = -sin phi1 / (b cos phi2),  d phi2/db = -s / (b cos phi2),  d phi2/dc = 1 / (b cos phi2)
    x3 = a cos phi1 + b cos phi2:
    d x3/da = cos phi1 + tan phi2 sin phi1,  d x3/db = 1 / cos phi2,  d x3/dc = -tan phi2
    x2 = a cos phi1, y2 = a sin phi1 (d/da only), y3 = c (d/dc = 1).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from codegen_support import compiled, derived

import symkin
from symkin.contract.options import Options

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TIGHT = Options(tol_phi=1e-14, tol_dq=1e-13)


def _closed_form_q_p(t: np.ndarray, a: float, b: float, c: float) -> np.ndarray:
    phi1 = t**2 + np.pi / 2
    s = (c - a * np.sin(phi1)) / b
    phi2 = np.arcsin(s)
    cos2 = np.cos(phi2)
    q_p = np.zeros((t.size, 9, 3))
    q_p[:, 3, 0] = np.cos(phi1)  # rod.x
    q_p[:, 4, 0] = np.sin(phi1)  # rod.y
    q_p[:, 5] = np.column_stack([-np.sin(phi1), -s, np.ones_like(t)]) / (b * cos2)[:, None]
    q_p[:, 6] = np.column_stack([np.cos(phi1) + np.tan(phi2) * np.sin(phi1), 1 / cos2,
                                 -np.tan(phi2)])  # slider.x
    q_p[:, 7, 2] = 1.0  # slider.y = c
    return q_p


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_crank_slider_q_p_matches_example_2_7(crank_slider_system, backend) -> None:
    kernel = symkin.compile(crank_slider_system, backend=backend)
    assert kernel.backend == backend
    trajectory = symkin.solve(kernel, sensitivities=True)
    assert trajectory.q_p.shape == (31, 9, 3)
    expected = _closed_form_q_p(trajectory.t, 1.0, 5.0, 4.0)
    assert np.abs(trajectory.q_p - expected).max() < 1e-9
    varied = symkin.solve(kernel, params={"a": 0.9, "b": 5.4, "c": 3.7}, sensitivities=True)
    assert np.abs(varied.q_p - _closed_form_q_p(varied.t, 0.9, 5.4, 3.7)).max() < 1e-9
    # dq_p = d/dt of q_p: the closed form differentiated in t by central differences
    h = 1e-6
    rate = (_closed_form_q_p(trajectory.t + h, 1.0, 5.0, 4.0)
            - _closed_form_q_p(trajectory.t - h, 1.0, 5.0, 4.0)) / (2 * h)
    assert np.abs(trajectory.dq_p - rate).max() < 1e-6


@pytest.mark.parametrize("example", ["four_bar", "crank_slider_general", "quick_return",
                                     "custom_driver", "andrews_squeezer"])
def test_q_p_equals_central_differences(example) -> None:
    system = derived(EXAMPLES / f"{example}.yaml")  # once per test run
    kernel = compiled(EXAMPLES / f"{example}.yaml", "c")  # from its goldens
    assert kernel.backend == "c"
    t = symkin.solve(kernel).t[:12]
    base = symkin.solve(kernel, t=t, options=TIGHT, sensitivities=True)
    for k, value in enumerate(kernel.p_values):
        h = 1e-5 * max(1e-2, abs(value))  # the squeezer's dimensions are centimetres
        shifted = []
        for sign in (1, -1):
            p = kernel.p_values.copy()
            p[k] += sign * h
            shifted.append(symkin.solve(kernel, t=t, q0=base.q[0], params=p, options=TIGHT).q)
        central = (shifted[0] - shifted[1]) / (2 * h)
        scale = max(1.0, np.abs(central).max())  # the squeezer turns at ~1400 rad/s
        assert np.abs(base.q_p[:, :, k] - central).max() < 1e-6 * scale, \
            system.parameter_names[k]
        velocities = []
        for sign in (1, -1):
            p = kernel.p_values.copy()
            p[k] += sign * h
            velocities.append(symkin.solve(kernel, t=t, q0=base.q[0], params=p,
                                           options=TIGHT).dq)
        central = (velocities[0] - velocities[1]) / (2 * h)
        scale = max(1.0, np.abs(central).max())
        assert np.abs(base.dq_p[:, :, k] - central).max() < 1e-6 * scale, \
            system.parameter_names[k]


def test_phi_p_is_the_derivative_of_phi(crank_slider_system) -> None:
    system = crank_slider_system
    for r in range(len(system.phi)):
        for k, symbol in enumerate(system.p):
            assert sp.simplify(system.phi_p[r, k] - sp.diff(system.phi[r], symbol)) == 0
    kernel = symkin.compile(system, backend="c")
    rng = np.random.default_rng(1)
    q, p = rng.normal(size=9), kernel.p_values * (1 + 0.1 * rng.normal(size=3))
    h = 1e-6
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        central = (kernel.phi(q, 0.3, p + step) - kernel.phi(q, 0.3, p - step)) / (2 * h)
        assert np.abs(kernel.phi_p(q, 0.3, p)[:, k] - central).max() < 1e-8


def test_without_sensitivities_there_is_no_q_p(crank_slider_system) -> None:
    kernel = symkin.compile(crank_slider_system, backend="c")
    plain = symkin.solve(kernel)
    assert plain.q_p is None and plain.dq_p is None
