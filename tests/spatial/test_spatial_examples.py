"""The spatial examples against references derived here, independently of symkin:

- the spatial slider-crank: the slider's x from the rod's length, and its rates;
- the Stewart-Gough platform, one body driven by six leg lengths, and the same platform with
  its 12 leg bodies (6-UPS): the leg lengths are the inverse kinematics of a pose path, so
  the solved pose must be that path (forward kinematics recovered);
- the delta robot: each forearm's rods keep their length and the platform its orientation;
- the Cardan shaft: tan(theta2) = tan(theta1) / cos(beta) with its exact derivatives (its
  redundant equation removed by the derivation).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.runtime.outputs.spatial import rotation

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
BACKENDS = ["c", "numpy"]


def _solve(name: str, backend: str) -> symkin.Trajectory:
    # one derivation and generation per run for both backends (stewart's, delta's take many
    # seconds)
    return symkin.solve(compiled(EXAMPLES / name, backend))


@pytest.mark.parametrize("backend", BACKENDS)
def test_spatial_slider_crank_against_the_rod_length(backend: str) -> None:
    r, L, h, k = 0.08, 0.4, 0.1, 0.12
    result = _solve("spatial_slider_crank.yaml", backend)
    th, w = 2 * np.pi * result.t, 2 * np.pi
    ay, az = h + r * np.cos(th), k + r * np.sin(th)  # the crank pin; the slider at (x, 0, 0)
    x = np.sqrt(L**2 - ay**2 - az**2)
    # x^2 = L^2 - g with g = ay^2 + az^2; dg/dth = -2 r (h sin th - k cos th)
    dg = -2 * r * (h * np.sin(th) - k * np.cos(th)) * w
    ddg = -2 * r * (h * np.cos(th) + k * np.sin(th)) * w**2
    dx = -dg / (2 * x)
    ddx = -(ddg + 2 * dx**2) / (2 * x)
    pos, vel, acc = result.point("slider", "B")
    assert np.abs(pos[:, 0] - x).max() < 1e-12
    assert np.abs(pos[:, 1:]).max() < 1e-12
    assert np.abs(vel[:, 0] - dx).max() < 1e-10
    assert np.abs(acc[:, 0] - ddx).max() < 1e-8
    pin, _, _ = result.point("rod", "A")
    assert np.abs(pin[:, 1] - ay).max() < 1e-12 and np.abs(pin[:, 2] - az).max() < 1e-12


def _pose_path(t):
    """The Stewart examples' pose path (their file comment): r(t) and A(t) = Rz(g) Rx(b)."""
    s = np.sin(2 * np.pi * t)
    r = np.stack([0.05 * s, 0.03 * np.cos(2 * np.pi * t) - 0.03, 1.0 + 0.1 * s], 1)
    g, b = 0.2 * s, 0.1 * np.sin(4 * np.pi * t)
    cg, sg, cb, sb = np.cos(g), np.sin(g), np.cos(b), np.sin(b)
    z, o = np.zeros_like(t), np.ones_like(t)
    rz = np.stack([np.stack([cg, -sg, z], -1), np.stack([sg, cg, z], -1),
                   np.stack([z, z, o], -1)], -2)
    rx = np.stack([np.stack([o, z, z], -1), np.stack([z, cb, -sb], -1),
                   np.stack([z, sb, cb], -1)], -2)
    return r, rz @ rx


def _check_pose(result) -> None:
    r, A = _pose_path(result.t)
    q, dq, _ = result.body("platform")
    assert np.abs(q[:, :3] - r).max() < 1e-10
    assert np.abs(rotation(q[:, 3:]) - A).max() < 1e-10
    # the velocity of the platform's origin: the derivative of r(t), by central differences
    # of the closed form (h = 1e-6: truncation ~1e-12)
    h = 1e-6
    dr = (_pose_path(result.t + h)[0] - _pose_path(result.t - h)[0]) / (2 * h)
    assert np.abs(dq[:, :3] - dr).max() < 1e-8


@pytest.mark.parametrize("backend", BACKENDS)
def test_stewart_platform_recovers_the_pose_from_its_leg_lengths(backend: str) -> None:
    _check_pose(_solve("stewart.yaml", backend))


def test_stewart_platform_with_its_leg_bodies_recovers_the_pose() -> None:
    result = _solve("stewart_legs.yaml", "c")
    _check_pose(result)
    # each leg's piston moves along its cylinder's axis and ends at the platform point
    pos, _, _ = result.point("piston1", "P1")
    top, _, _ = result.point("platform", "P1")
    assert np.abs(pos - top).max() < 1e-10


@pytest.mark.parametrize("backend", BACKENDS)
def test_delta_robot_rods_keep_their_length_and_the_platform_its_orientation(
        backend: str) -> None:
    R, la, lb, r = 0.2, 0.25, 0.5, 0.05
    result = _solve("delta.yaml", backend)
    q, _, _ = result.body("platform")
    assert np.abs(q[:, 3:] - [1, 0, 0, 0]).max() < 1e-10
    c, dc, ddc = result.point("platform", "C")
    for k in range(3):
        phi = 2 * np.pi * k / 3
        u, z = np.array([np.cos(phi), np.sin(phi), 0.0]), np.array([0, 0, 1.0])
        arg = 2 * np.pi * result.t + 2 * k * np.pi / 3
        th, dth, ddth = 0.3 * np.sin(arg), 0.6 * np.pi * np.cos(arg), \
            -1.2 * np.pi**2 * np.sin(arg)
        # the elbow turns down about the tangent: E = R u + la (cos th u - sin th z)
        e = R * u + la * (np.cos(th)[:, None] * u - np.sin(th)[:, None] * z)
        de = la * dth[:, None] * (-np.sin(th)[:, None] * u - np.cos(th)[:, None] * z)
        dde = la * (ddth[:, None] * (-np.sin(th)[:, None] * u - np.cos(th)[:, None] * z)
                    - dth[:, None] ** 2 * (np.cos(th)[:, None] * u - np.sin(th)[:, None] * z))
        d, dd, ddd = c + r * u - e, dc - de, ddc - dde
        assert np.abs(np.linalg.norm(d, axis=1) - lb).max() < 1e-12
        assert np.abs(np.sum(d * dd, 1)).max() < 1e-10
        assert np.abs(np.sum(d * ddd, 1) + np.sum(dd * dd, 1)).max() < 1e-8


@pytest.mark.parametrize("backend", BACKENDS)
def test_cardan_shaft_speed_ratio_against_the_closed_form(backend: str) -> None:
    beta = np.pi / 6
    result = _solve("cardan.yaml", backend)
    th1, w1 = 2 * np.pi * result.t, 2 * np.pi
    # tan th2 = tan th1 / cos beta, on the branch continuous with th1
    th2 = np.arctan2(np.sin(th1), np.cos(th1) * np.cos(beta))
    k = 1 - np.sin(beta) ** 2 * np.cos(th1) ** 2
    w2 = w1 * np.cos(beta) / k
    a2 = -w1**2 * np.cos(beta) * np.sin(beta) ** 2 * np.sin(2 * th1) / k**2
    omega, alpha = result.angular()
    out = result.bodies.index("shaft2")
    axis = np.array([np.cos(beta), np.sin(beta), 0.0])
    assert np.abs(omega[:, out] @ axis - w2).max() < 1e-9
    assert np.abs(alpha[:, out] @ axis - a2).max() < 1e-7
    q, _, _ = result.body("shaft2")
    # shaft2 turned by th2 about its axis: the drawn cross arm [0, 0, 1] goes to
    # cos th2 [0, 0, 1] + sin th2 (axis x [0, 0, 1])
    arm = rotation(q[:, 3:]) @ np.array([0, 0, 1.0])
    expected = (np.cos(th2)[:, None] * np.array([0, 0, 1.0])
                + np.sin(th2)[:, None] * np.cross(axis, [0, 0, 1.0]))
    assert np.abs(arm - expected).max() < 1e-10
