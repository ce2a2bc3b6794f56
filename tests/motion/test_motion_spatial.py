"""A free spatial rigid body (space: 3d, no joints) tumbling: its kinetic energy and its
angular momentum (global) stay what they were, its centre moves uniformly; the initial
angular velocity is the one the file gives (global components, the body turned at t0)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from motion_support import kernel as built
from motion_support import shared

import symkin

FREE_BODY = """\
name: tumbling
space: 3d
parameters: {m: 2.0}
bodies:
  box: {q0: [0, 0, 0, 0.921060994, 0.233651005, 0.311534674, 0], mass: m, inertia: [1.0, 2.0, 2.5],
        points: {corner: [0.3, 0.2, 0.1]}}
initial: {velocities: {box.x: 0.5, box.z: -0.25, box.omega_x: 0.1, box.omega_y: 3.0,
                       box.omega_z: 0.2}}
integrator: {rtol: 1e-11, atol: 1e-12}
time: {t0: 0, t1: 6, dt: 0.1}
"""


def _rotation(e: np.ndarray) -> np.ndarray:
    e0, v = e[0], e[1:]
    skew = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return (e0 ** 2 - v @ v) * np.eye(3) + 2 * np.outer(v, v) + 2 * e0 * skew


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_a_free_body_keeps_its_energy_and_angular_momentum(tmp_path: Path,
                                                           backend: str) -> None:
    kernel = built(shared("free.yaml", FREE_BODY), backend)
    trajectory = symkin.solve(kernel)
    omega, _ = trajectory.angular()
    omega = omega[:, 0]
    assert omega[0] == pytest.approx([0.1, 3.0, 0.2], abs=1e-12)
    inertia = np.diag([1.0, 2.0, 2.5])
    momentum = np.array([_rotation(q[3:]) @ inertia @ _rotation(q[3:]).T @ w
                         for q, w in zip(trajectory.q, omega)])
    # rotation near the middle axis: ω wanders (in the body frame the body flips, as
    # Dzhanibekov's nut does) while L and T must not
    assert np.ptp(omega, axis=0).max() > 0.1
    assert momentum == pytest.approx(np.tile(momentum[0], (momentum.shape[0], 1)), abs=1e-8)
    kinetic = dict(trajectory.outputs)["kinetic_energy"]
    turned = _rotation(trajectory.q[0, 3:])
    spin = 0.5 * omega[0] @ turned @ inertia @ turned.T @ omega[0]
    expected = 0.5 * 2.0 * (0.5 ** 2 + 0.25 ** 2) + spin
    assert kinetic == pytest.approx(np.full(kinetic.size, expected), rel=1e-9)
    assert trajectory.q[:, 0] == pytest.approx(0.5 * trajectory.t, abs=1e-9)
    assert trajectory.q[:, 2] == pytest.approx(-0.25 * trajectory.t, abs=1e-9)
    assert np.sum(trajectory.q[:, 3:] ** 2, axis=1) == pytest.approx(1.0, abs=1e-10)
