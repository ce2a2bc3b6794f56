"""A driver that stays (a rheonomic constraint): a pendulum hung from a cart that the drivers
shake along x. The pendulum starts with the rate of least kinetic energy, the drivers' work
closes the energy balance, and the drivers report their efforts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from motion_support import write

import symkin

SHAKEN = """\
name: shaken
parameters: {L: 0.8, m: 1.5, g: 9.81}
bodies:
  cart: {q0: [0, 0, 0], mass: 4.0, inertia: 0.3}
  bob:  {q0: [0, 0, PHI0], mass: m, inertia: 0, com: [L, 0]}
joints:
  - {type: revolute, i: cart, j: bob, sA: [0, 0], sB: [0, 0]}
drivers:
  - {type: trajectory, name: shaker, j: cart, sB: [0, 0], f: ["0.3*sin(4*t)", 0]}
  - {type: angle, name: level, i: cart, j: ground, theta: 0}
forces:
  - {type: gravity, g: [0, -g]}
integrator: {rtol: 1e-11, atol: 1e-12}
time: {t0: 0, t1: 3, dt: 0.05}
"""


@pytest.fixture(scope="module")
def trajectory(
        tmp_path_factory: pytest.TempPathFactory) -> symkin.runtime.outputs.results.Trajectory:
    path = write(tmp_path_factory.mktemp("shaken"), "shaken.yaml",
                 SHAKEN.replace("PHI0", repr(-math.pi / 2 + 0.5)))
    return symkin.solve(symkin.compile(symkin.derive(path), backend="numpy"))


def test_the_free_rate_at_t0_has_the_least_kinetic_energy(trajectory) -> None:
    # the cart moves at 1.2 along x; the bob's centre at v + L φ' (-sin φ, cos φ) is slowest
    # for L φ' = 1.2 sin φ (by hand)
    phi = -math.pi / 2 + 0.5
    assert trajectory.dq[0, 0] == pytest.approx(1.2, abs=1e-12)
    assert trajectory.dq[0, 5] == pytest.approx(1.2 * math.sin(phi) / 0.8, abs=1e-10)


def test_the_drivers_work_closes_the_energy_balance(trajectory) -> None:
    out = dict(trajectory.outputs)
    total = out["kinetic_energy"] + out["potential_energy"] - out["work_nonconservative"]
    scale = np.max(np.abs(out["kinetic_energy"]) + np.abs(out["potential_energy"]))
    assert np.ptp(out["work_nonconservative"]) > 0.1 * scale  # the shaker works ...
    assert np.ptp(total) <= 1e-8 * scale  # ... and that is where the energy came from
    # the shaker's x effort is the force on the cart: m_cart a_cart + what the bob pulls
    effort = trajectory.effort[:, 0]
    cart_accel = -0.3 * 16 * np.sin(4 * trajectory.t)
    pull = trajectory.reaction[:, 0, 0]  # cart on bob, x: the bob pulls the cart back
    assert effort == pytest.approx(4.0 * cart_accel + pull, abs=1e-8)
