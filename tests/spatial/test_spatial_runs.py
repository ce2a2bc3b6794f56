"""Spatial mechanisms solved by the compiled kernels of both backends (C compiled and run,
and NumPy), against references derived by hand here:

- the RSSR four-bar's input-output equation (the coupler's length written out), its rocker
  angle from the closed-form solution and the rocker's rates by implicit differentiation;
- a gimbal whose inner body pitches through +-90 degrees (where Euler angles lock) and on
  over a full tumble: its orientation Rz(psi) Ry(theta), angular velocity and acceleration
  and a point's motion in closed form.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin import cli
from symkin.spec.validate import from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
BACKENDS = ["c", "numpy"]


# ----- RSSR ------------------------------------------------------------------------------

A, D, H, C = 0.1, 0.5, 0.4, 0.4  # examples/rssr.yaml
B2 = (D - A) ** 2 + C**2 + H**2  # the coupler's length squared, as drawn


def _rssr_residual(theta, psi):
    """|B - A|^2 - b^2 with A = (a cos th, a sin th, 0), B = (d, c cos psi, h + c sin psi)."""
    return ((D - A * np.cos(theta)) ** 2 + (C * np.cos(psi) - A * np.sin(theta)) ** 2
            + (H + C * np.sin(psi)) ** 2 - B2)


def _rssr_psi(theta):
    """The rocker angle from k1 cos psi + k2 sin psi = k3, on the branch through psi = 0."""
    k1, k2 = -2 * A * C * np.sin(theta), 2 * H * C
    k3 = B2 - A * A - C * C - D * D - H * H + 2 * A * D * np.cos(theta)
    base, spread = np.arctan2(k2, k1), np.arccos(k3 / np.hypot(k1, k2))
    return base - spread  # psi = 0 at theta = 0: base = pi/2, spread = pi/2


@pytest.mark.parametrize("backend", BACKENDS)
def test_rssr_follows_its_input_output_equation(backend: str) -> None:
    result = symkin.solve(compiled(EXAMPLES / "rssr.yaml", backend))
    theta = 2 * np.pi * result.t
    r, dr, ddr = result.point("rocker", "B")
    psi = np.arctan2(r[:, 2] - H, r[:, 1])
    assert np.abs(_rssr_residual(theta, psi)).max() < 1e-12
    assert np.abs(psi - _rssr_psi(theta)).max() < 1e-10
    assert np.abs(r[:, 0] - D).max() < 1e-12
    # rates: F_th dth + F_psi dpsi = 0 (dth = 2 pi), and the second derivative of it
    dth = 2 * np.pi
    f_th = 2 * A * D * np.sin(theta) - 2 * A * C * np.cos(theta) * np.cos(psi)
    f_ps = 2 * A * C * np.sin(theta) * np.sin(psi) + 2 * H * C * np.cos(psi)
    dpsi = -f_th * dth / f_ps
    f_thth = 2 * A * D * np.cos(theta) + 2 * A * C * np.sin(theta) * np.cos(psi)
    f_thps = 2 * A * C * np.cos(theta) * np.sin(psi)
    f_psps = 2 * A * C * np.sin(theta) * np.cos(psi) - 2 * H * C * np.sin(psi)
    ddpsi = -(f_thth * dth**2 + 2 * f_thps * dth * dpsi + f_psps * dpsi**2) / f_ps
    omega, alpha = result.angular()
    rocker = result.bodies.index("rocker")
    assert np.abs(omega[:, rocker, 0] - dpsi).max() < 1e-9
    assert np.abs(omega[:, rocker, 1:]).max() < 1e-9
    assert np.abs(alpha[:, rocker, 0] - ddpsi).max() < 1e-7
    tangent = np.stack([np.zeros_like(psi), -np.sin(psi), np.cos(psi)], 1)
    assert np.abs(dr - C * dpsi[:, None] * tangent).max() < 1e-9
    normal = np.stack([np.zeros_like(psi), np.cos(psi), np.sin(psi)], 1)
    expected = C * ddpsi[:, None] * tangent - C * dpsi[:, None] ** 2 * normal
    assert np.abs(ddr - expected).max() < 1e-7


# ----- a gimbal through +-90 degrees of pitch -----------------------------------------------

GIMBAL = {
    "name": "gimbal", "space": "3d", "layout": "drawn",
    "parameters": {"L": 0.8},
    "bodies": {
        "yoke": {"points": {"O": [0, 0, 0]}},
        "rotor": {"points": {"O": [0, 0, 0], "P": ["L", 0, 0]}},
    },
    "joints": [
        {"type": "revolute", "name": "yaw", "i": "ground", "j": "yoke", "at": "O",
         "axis": [0, 0, 1]},
        {"type": "revolute", "name": "pitch", "i": "yoke", "j": "rotor", "at": "O",
         "axis": [0, 1, 0]},
    ],
    "drivers": [
        {"type": "angle", "joint": "yaw", "theta": "sin(t)"},
        {"type": "angle", "joint": "pitch", "theta": "2*pi*t"},
    ],
    "time": {"t0": 0, "t1": 1.5, "dt": 0.01},
}


@functools.cache
def _gimbal() -> symkin.System:
    """The gimbal, derived once for both backends."""
    return symkin.derive(from_dict(GIMBAL))


def _rz(a):
    c, s, z, o = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1),
                     np.stack([z, z, o], -1)], -2)


def _ry(a):
    c, s, z, o = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1),
                     np.stack([-s, z, c], -1)], -2)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_tumble_through_plus_minus_90_degrees_of_pitch(backend: str) -> None:
    result = symkin.solve(symkin.compile(_gimbal(), backend=backend))
    t = result.t
    psi, dpsi, ddpsi = np.sin(t), np.cos(t), -np.sin(t)
    theta, dtheta = 2 * np.pi * t, 2 * np.pi
    assert theta[-1] > 2 * np.pi + np.pi / 2  # through +90, -90 (as 270) and a full turn
    q, _, _ = result.body("rotor")
    from symkin.runtime.outputs.spatial import rotation

    expected = _rz(psi) @ _ry(theta)
    assert np.abs(rotation(q[:, 3:]) - expected).max() < 1e-10
    assert np.abs(np.sum(q[:, 3:] ** 2, 1) - 1).max() < 1e-12
    # omega = dpsi z + dtheta Rz(psi) y; alpha its derivative
    y_turned = np.stack([-np.sin(psi), np.cos(psi), np.zeros_like(t)], 1)
    omega = dtheta * y_turned
    omega[:, 2] += dpsi
    dy_turned = dpsi[:, None] * np.stack([-np.cos(psi), -np.sin(psi), np.zeros_like(t)], 1)
    alpha = dtheta * dy_turned
    alpha[:, 2] += ddpsi
    w, a = result.angular()
    rotor = result.bodies.index("rotor")
    assert np.abs(w[:, rotor] - omega).max() < 1e-9
    assert np.abs(a[:, rotor] - alpha).max() < 1e-7
    # the point P = R [L, 0, 0]: dr = omega x r, ddr = alpha x r + omega x (omega x r)
    r, dr, ddr = result.point("rotor", "P")
    assert np.abs(r - 0.8 * expected[:, :, 0]).max() < 1e-10
    assert np.abs(dr - np.cross(omega, r)).max() < 1e-9
    assert np.abs(ddr - np.cross(alpha, r) - np.cross(omega, np.cross(omega, r))).max() < 1e-7


def test_float_and_dense_builds_of_a_spatial_kernel() -> None:
    """--real float (C) agrees with double to float precision; the dense LU to rounding."""
    path = EXAMPLES / "rssr.yaml"
    double = symkin.solve(compiled(path, "c"))
    single = symkin.solve(compiled(path, "c", real="float"))
    dense = symkin.solve(compiled(path, "c", linalg="dense"))
    assert np.abs(single.q - double.q).max() < 1e-5
    assert np.abs(dense.q - double.q).max() < 1e-12


def test_spatial_outputs_csv_and_npz(tmp_path: Path,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    """The file contracts: r, dr, ddr (n_t, n_points, 3), omega and alpha (n_t, n_bodies, 3)
    with bodies in the NPZ; the CSV's point and angular columns; each CSV value equal to the
    NPZ's. Written by ``symkin run`` (in this process: the CLI's own exit code is
    tests/cli's)."""
    for name in ("run.csv", "run.npz"):
        code = cli.main(["run", str(EXAMPLES / "rssr.yaml"), "--backend", "numpy", "-o",
                         str(tmp_path / name)])
        assert code == 0, capsys.readouterr().err
    data = np.load(tmp_path / "run.npz")
    n_t = data["t"].size
    assert list(data["points"]) == ["crank.A0", "crank.A", "rocker.B0", "rocker.B"]
    assert data["r"].shape == data["dr"].shape == data["ddr"].shape == (n_t, 4, 3)
    assert list(data["bodies"]) == ["crank", "rocker"]
    assert data["omega"].shape == data["alpha"].shape == (n_t, 2, 3)
    header = (tmp_path / "run.csv").read_text().splitlines()[0].split(",")
    table = np.loadtxt(tmp_path / "run.csv", delimiter=",", skiprows=1)
    column = {name: table[:, k] for k, name in enumerate(header)}
    start = header.index("rocker.B_x")
    assert header[start:start + 9] == [f"rocker.B_{s}" for s in
                                       ("x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az")]
    assert header[-13:-1] == [f"{b}.{k}_{a}" for b in ("crank", "rocker")
                              for k in ("omega", "alpha") for a in "xyz"]
    assert header[-1] == "flagged"
    assert np.array_equal(column["rocker.B_vz"], data["dr"][:, 3, 2])
    assert np.array_equal(column["rocker.alpha_x"], data["alpha"][:, 1, 0])
    assert np.array_equal(column["crank.e3_tt"], data["d2q"][:, header.index("crank.e3") - 1])
