"""The example mechanisms: each is valid, has DOF == driving equations, assembles from its
q0 over its whole time grid, and moves as its geometry says it must.

The solver here is a plain Newton iteration on lambdified Phi (a few lines, independent of
symkin's generated code and driver); the checks compare with closed forms of each linkage.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from codegen_support import derived

import symkin
from symkin.spec.schema import equation_count
from symkin.spec.validate import degrees_of_freedom
from symkin.symbolic.derivation import System

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MINE = ["crank_slider.yaml", "four_bar.yaml", "quick_return.yaml", "all_drivers.yaml",
        "custom_driver.yaml"]


@dataclass
class Motion:
    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    coordinates: tuple[str, ...]
    worst_condition: float

    def __getitem__(self, name: str) -> np.ndarray:
        return self.q[:, self.coordinates.index(name)]

    def rate(self, name: str) -> np.ndarray:
        return self.dq[:, self.coordinates.index(name)]


def assemble(system: System) -> Motion:
    """Newton on Phi(q, t) = 0 at each grid time from a Taylor predictor, then dq and ddq."""
    values = dict(zip(system.p, system.p_values))
    arguments = (system.q, system.dq, system.t)
    phi, jac, phi_t, gamma = (sp.lambdify(arguments, sp.Matrix(m).subs(values), "numpy")
                              for m in (system.phi, system.phi_q, system.phi_t, system.gamma))
    t0, t1, dt = system.time_grid
    times = np.arange(t0, t1 + dt / 2, dt)
    q, dq, ddq = (np.array(system.q0, float), np.zeros(len(system.q)), np.zeros(len(system.q)))
    rows, worst = [], 0.0
    for k, t in enumerate(times):
        if k:
            q = q + dq * dt + ddq * dt**2 / 2
        for _ in range(25):
            residual = np.asarray(phi(q, dq, t), float).ravel()
            if np.linalg.norm(residual) < 1e-12:
                break
            q = q - np.linalg.solve(np.asarray(jac(q, dq, t), float), residual)
        else:
            raise AssertionError(f"{system.name}: no convergence at t = {t}")
        jacobian = np.asarray(jac(q, dq, t), float)
        worst = max(worst, np.linalg.cond(jacobian))
        dq = np.linalg.solve(jacobian, -np.asarray(phi_t(q, dq, t), float).ravel())
        ddq = np.linalg.solve(jacobian, np.asarray(gamma(q, dq, t), float).ravel())
        rows.append((q, dq, ddq))
    q_all, dq_all, ddq_all = (np.array(part) for part in zip(*rows))
    return Motion(times, q_all, dq_all, ddq_all, system.coordinates, worst)


@functools.cache
def solved(name: str) -> tuple[System, Motion]:
    system = derived(EXAMPLES / name)  # the run's shared derivation
    return system, assemble(system)


@pytest.fixture(params=MINE)
def example(request) -> tuple[System, Motion]:
    return solved(request.param)


def test_examples_have_dof_equal_to_driving_equations(example) -> None:
    system, _ = example
    mech = system.mechanism
    assert degrees_of_freedom(mech) == sum(equation_count(d) for d in mech.drivers)
    assert len(system.rows) == len(system.q)


def test_examples_assemble_without_dead_centres(example) -> None:
    system, motion = example
    assert motion.worst_condition < 1e4, system.name
    if system.name != "crank_slider":  # the textbook starts from q = 0 on purpose
        # The q0 in the file is a good guess: the assembled pose at t0 is close to it.
        assert np.max(np.abs(motion.q[0] - np.array(system.q0))) < 0.01


def _params(system: System) -> dict[str, float]:
    return dict(zip(system.parameter_names, system.p_values))


def test_four_bar_keeps_its_link_lengths_and_rocks() -> None:
    system, motion = solved("four_bar.yaml")
    p = _params(system)
    a, b, c, d = p["a"], p["b"], p["c"], p["d"]
    assert a + d < b + c and a == min(a, b, c, d)  # Grashof crank-rocker
    pin_a = np.stack([a * np.cos(motion["crank.phi"]), a * np.sin(motion["crank.phi"])], 1)
    pin_b = np.stack([d + c * np.cos(motion["rocker.phi"]), c * np.sin(motion["rocker.phi"])], 1)
    np.testing.assert_allclose(np.linalg.norm(pin_b - pin_a, axis=1), b, atol=1e-10)
    np.testing.assert_allclose(motion["crank.phi"], p["theta0"] + p["w"] * motion.t,
                               atol=1e-10)
    # The rocker swings between its two extreme positions, where the crank and coupler are
    # in line: |O4 B| = c and |O2 B| = b - a or b + a (law of cosines on the ground link).
    extreme = [math.acos((d**2 + c**2 - s**2) / (2 * d * c)) for s in (b - a, b + a)]
    swing = math.pi - np.array(extreme)  # the rocker angle measured from the x-axis
    assert motion["rocker.phi"].min() == pytest.approx(swing.min(), abs=2e-3)
    assert motion["rocker.phi"].max() == pytest.approx(swing.max(), abs=2e-3)


def test_quick_return_forward_stroke_takes_twice_the_return() -> None:
    system, motion = solved("quick_return.yaml")
    p = _params(system)
    # The lever is tangent to the crank circle at its extremes: sin(half swing) = r / h.
    half_swing = math.asin(p["r"] / p["h"])
    assert motion["lever.phi"].max() - math.pi / 2 == pytest.approx(half_swing, abs=1e-3)
    assert math.pi / 2 - motion["lever.phi"].min() == pytest.approx(half_swing, abs=1e-3)
    # The slow stroke takes pi + 2 * half_swing of the crank's turn (240 degrees), the quick
    # return the rest (120): the crank turns uniformly, so count grid points.
    moving_right = np.mean(motion.rate("ram.x") > 0)
    slow = max(moving_right, 1 - moving_right)
    assert slow == pytest.approx((math.pi + 2 * half_swing) / (2 * math.pi), abs=0.02)
    assert slow / (1 - slow) == pytest.approx(2, abs=0.1)
    # The pin stays on the lever's axis (the slot) and the ram on its guide.
    pin = np.stack([p["r"] * np.cos(motion["crank.phi"]),
                    p["h"] + p["r"] * np.sin(motion["crank.phi"])], 1)
    normal = np.stack([-np.sin(motion["lever.phi"]), np.cos(motion["lever.phi"])], 1)
    np.testing.assert_allclose(np.sum(pin * normal, axis=1), 0, atol=1e-10)
    np.testing.assert_allclose(motion["ram.y"], p["guide_y"], atol=1e-10)


def test_all_drivers_rig_follows_its_programme() -> None:
    system, motion = solved("all_drivers.yaml")
    p = _params(system)
    t, w = motion.t, p["w"]
    tip_x = motion["arm2.x"] + p["l2"] * np.cos(motion["arm2.phi"])
    tip_y = motion["arm2.y"] + p["l2"] * np.sin(motion["arm2.phi"])
    np.testing.assert_allclose(tip_x, p["cx"] + p["rc"] * np.cos(w * t), atol=1e-10)
    np.testing.assert_allclose(tip_y, p["cy"] + p["rc"] * np.sin(w * t), atol=1e-10)
    along = ((motion["carriage.x"] - motion["arm2.x"]) * np.cos(motion["arm2.phi"])
             + (motion["carriage.y"] - motion["arm2.y"]) * np.sin(motion["arm2.phi"]))
    np.testing.assert_allclose(along, p["s0"] + p["s1"] * np.sin(w * t), atol=1e-10)
    np.testing.assert_allclose(motion["gripper.phi"] - motion["carriage.phi"],
                               0.3 * np.sin(w * t), atol=1e-10)
    np.testing.assert_allclose(motion["tracer.x"] - motion["gripper.x"], 0.5 * np.cos(w * t),
                               atol=1e-10)
    np.testing.assert_allclose(motion["tracer.phi"], w * t - 0.5 * t**2, atol=1e-10)
    # Velocity of the tracer's angle: d/dt (w t - t^2/2), from Phi_t of the polynomial driver.
    np.testing.assert_allclose(motion.rate("tracer.phi"), w - t, atol=1e-10)


def test_custom_driver_matches_the_crank_slider_closed_form() -> None:
    """Crank angle psi(t) = psi0 + w t + k sin(w t); slider x = a cos psi + sqrt(b^2 - (a sin
    psi)^2) (an in-line crank-slider); velocities by differentiating the closed form."""
    system, motion = solved("custom_driver.yaml")
    p = _params(system)
    a, b, w, k, psi0 = p["a"], p["b"], p["w"], p["k"], p["psi0"]
    t = motion.t
    psi = psi0 + w * t + k * np.sin(w * t)
    dpsi = w + k * w * np.cos(w * t)
    np.testing.assert_allclose(motion["crank.phi"], psi, atol=1e-10)
    np.testing.assert_allclose(motion.rate("crank.phi"), dpsi, atol=1e-9)
    root = np.sqrt(b**2 - (a * np.sin(psi))**2)
    x = a * np.cos(psi) + root
    dx = (-a * np.sin(psi) - a**2 * np.sin(psi) * np.cos(psi) / root) * dpsi
    np.testing.assert_allclose(motion["slider.x"], x, atol=1e-10)
    np.testing.assert_allclose(motion.rate("slider.x"), dx, atol=1e-9)
    # Acceleration of the crank: d2psi/dt2, which needs the Phi_tq and Phi_tt terms of Gamma.
    crank = motion.coordinates.index("crank.phi")
    np.testing.assert_allclose(motion.ddq[:, crank], -k * w**2 * np.sin(w * t), atol=1e-8)
