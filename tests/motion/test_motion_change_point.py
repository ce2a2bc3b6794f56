"""A forward-dynamics motion through a singular configuration: a parallelogram four-bar
(crank = rocker = 1, coupler = ground = 2) with no driver and no load, set turning at one
turn a second. Twice a turn its links line up with the ground (change points: Phi_q loses
rank there and the anti-parallelogram branch meets the parallelogram). Its exact motion is
uniform: on the parallelogram branch the coupler only translates, so T = (J1 + J3 + m a^2)
w^2 / 2 is kept with w constant, phi = phi0 + w t. The run must pass both change points on
its own branch (the rocker parallel to the crank), never a silent jump to the other."""

from __future__ import annotations

import numpy as np
import pytest
from motion_support import write

import symkin

W, PHI0 = 2 * np.pi, 0.5
PARALLELOGRAM = f"""\
name: parallelogram_free
parameters: {{a: 1.0, b: 2.0, m: 1.0}}
bodies:
  crank:   {{q0: [0, 0, {PHI0}], points: {{A: [a, 0]}}, mass: m, inertia: m*a**2/12,
            com: [a/2, 0]}}
  coupler: {{q0: [0.8776, 0.4794, 0], points: {{B: [b, 0]}}, mass: m, inertia: m*b**2/12,
            com: [b/2, 0]}}
  rocker:  {{q0: [2, 0, {PHI0}], points: {{B: [a, 0]}}, mass: m, inertia: m*a**2/12,
            com: [a/2, 0]}}
joints:
  - {{type: revolute, name: O2, i: ground,  j: crank,   sA: [0, 0], sB: [0, 0]}}
  - {{type: revolute, name: A,  i: crank,   j: coupler, sA: A,      sB: [0, 0]}}
  - {{type: revolute, name: B,  i: coupler, j: rocker,  sA: B,      sB: B}}
  - {{type: revolute, name: O4, i: rocker,  j: ground,  sA: [0, 0], sB: [b, 0]}}
forces:
  - {{type: gravity, g: [0, 0]}}
initial: {{velocities: {{crank.phi: {W!r}}}}}
time: {{t0: 0, t1: 1, dt: 0.01}}
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory):
    path = write(tmp_path_factory.mktemp("change_point"), "parallelogram.yaml", PARALLELOGRAM)
    kernel = symkin.compile(symkin.derive(path), backend="numpy")
    return symkin.solve(kernel)


def test_the_motion_passes_both_change_points_on_its_branch(run) -> None:
    names = list(run.coordinates)
    crank, rocker = (run.q[:, names.index(f"{b}.phi")] for b in ("crank", "rocker"))
    # both change points (phi = pi, 2 pi) lie inside the run
    assert crank[0] < np.pi < 2 * np.pi < crank[-1]
    # from the angle assembled at t0 (q0 is drawn to 4 digits) at the rate given
    np.testing.assert_allclose(crank, crank[0] + W * run.t, rtol=0, atol=1e-6)
    assert crank[0] == pytest.approx(PHI0, abs=1e-4)
    np.testing.assert_allclose(rocker, crank, rtol=0, atol=1e-6)  # still a parallelogram
    coupler = run.q[:, names.index("coupler.phi")]
    assert np.abs(coupler).max() < 1e-6  # the coupler translates, never turns
    kinetic = dict(run.outputs)["kinetic_energy"]
    assert np.ptp(kinetic) < 1e-6 * kinetic[0]
