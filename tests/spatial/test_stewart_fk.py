"""Forward kinematics of the Stewart-Gough platform with the leg lengths as inputs
(examples/stewart_fk.yaml, one moving body; examples/stewart_legs_fk.yaml, with its 12 leg
bodies): the generated C ``solve_inputs`` (through symkin.solve with a C kernel) and the
NumPy backend recover the prescribed poses from the leg lengths.

The reference is independent of symkin: the benchmark's poses (stewart_trajectory of
bench/stewart/stewart.c, roll, pitch, yaw as in stewart.h) and their leg lengths
|r + R P_i - B_i| by NumPy; the solved pose is compared with the prescribed one (position, and
the rotation matrix A(e) of the solved Euler parameters against R), and the solved rates and
accelerations with central differences of the solved positions.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import symkin

ROOT = Path(__file__).resolve().parents[2]
BACKENDS = ("c", "numpy")
FILES = {"stewart_fk": 0.0, "stewart_legs_fk": 1.0}  # the second subtracts the home lengths


def _geometry() -> tuple[np.ndarray, np.ndarray]:
    """stewart_default_geometry of bench/stewart/stewart.c, platform points in its own frame."""
    i = np.arange(6)
    pair, side = i // 2, np.where(i % 2, 1, -1)
    base_angle = pair * 2 * np.pi / 3 + side * np.radians(10)
    top_angle = pair * 2 * np.pi / 3 + np.pi / 3 - side * np.radians(40)
    base = np.stack([np.cos(base_angle), np.sin(base_angle), 0 * i], axis=1)
    top = np.stack([0.6 * np.cos(top_angle), 0.6 * np.sin(top_angle), 0 * i], axis=1)
    return base, top


def _rotation(a: float, b: float, c: float) -> np.ndarray:
    """R = Rz(c) Ry(b) Rx(a)."""
    ca, sa, cb, sb, cc, sc = (math.cos(a), math.sin(a), math.cos(b), math.sin(b),
                              math.cos(c), math.sin(c))
    rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    return rz @ ry @ rx


def _poses(t: np.ndarray, tilt: float) -> np.ndarray:
    """stewart_trajectory of bench/stewart/stewart.c at s = 2 pi t: a circle of radius 0.1
    about the home height 1, heave 0.05, roll/pitch/yaw of amplitude tilt."""
    s = 2 * np.pi * t
    return np.stack([0.1 * np.cos(s), 0.1 * np.sin(s), 1 + 0.05 * np.sin(2 * s),
                     tilt * np.sin(s), tilt * np.cos(s), 0.5 * tilt * np.sin(3 * s)], axis=1)


def _legs(pose: np.ndarray) -> np.ndarray:
    base, top = _geometry()
    R = _rotation(*pose[3:])
    return np.linalg.norm(pose[:3] + top @ R.T - base, axis=1)


def _euler_rotation(e: np.ndarray) -> np.ndarray:
    """A(e) of unit Euler parameters (Haug's (6.2.26)), written out here."""
    e0, e1, e2, e3 = e
    return 2 * np.array([
        [e0 * e0 + e1 * e1 - 0.5, e1 * e2 - e0 * e3, e1 * e3 + e0 * e2],
        [e1 * e2 + e0 * e3, e0 * e0 + e2 * e2 - 0.5, e2 * e3 - e0 * e1],
        [e1 * e3 - e0 * e2, e2 * e3 + e0 * e1, e0 * e0 + e3 * e3 - 0.5]])


@pytest.fixture(scope="module", params=[(f, b) for f in FILES for b in BACKENDS],
                ids=lambda p: f"{p[0]}-{p[1]}")
def kernel(request: pytest.FixtureRequest):
    name, backend = request.param
    return name, symkin.compile(symkin.derive(ROOT / "examples" / f"{name}.yaml"),
                                backend=backend)


@pytest.mark.parametrize("tilt", [0.05, 0.5])
def test_poses_are_recovered_from_leg_lengths(kernel, tilt: float) -> None:
    name, k = kernel
    assert k.input_names == tuple(f"leg{i}" for i in range(1, 7))
    t = np.linspace(0.0, 1.0, 201)
    poses = _poses(t, tilt)
    home = _legs(np.array([0, 0, 1.0, 0, 0, 0])) * FILES[name]
    lengths = np.array([_legs(p) for p in poses]) - home
    got = symkin.solve(k, t=t, inputs=lengths)
    assert not got.flagged.any()
    # the C sparse LU never leaves its plan (stewart_fk fell back 20 times at 0.5 rad before
    # its leg rows were interchanged at run time: codegen.lu_interchange.with_margin)
    assert got.lu_fallbacks == 0
    names = k.coordinates
    at = [names.index(f"platform.{c}") for c in ("x", "y", "z", "e0", "e1", "e2", "e3")]
    for q, pose in zip(got.q, poses):
        assert np.max(np.abs(q[at[:3]] - pose[:3])) < 1e-9
        assert np.max(np.abs(_euler_rotation(q[at[3:]]) - _rotation(*pose[3:]))) < 1e-9


def test_rates_and_accelerations_match_differences(kernel) -> None:
    """With the legs' rates and accelerations (central differences of the closed-form lengths
    on a fine grid), the solved dq and d2q equal differences of the solved positions."""
    name, k = kernel
    t = np.linspace(0.0, 0.2, 801)
    h = t[1] - t[0]
    fine = lambda s: np.array([_legs(p) for p in _poses(s, 0.5)])  # noqa: E731
    step = 1e-4
    lengths = fine(t) - _legs(np.array([0, 0, 1.0, 0, 0, 0])) * FILES[name]
    rates = (fine(t + step) - fine(t - step)) / (2 * step)
    accels = (fine(t + step) - 2 * fine(t) + fine(t - step)) / step**2
    got = symkin.solve(k, t=t, inputs=lengths, input_rates=rates, input_accels=accels)
    assert not got.flagged.any()
    assert np.max(np.abs((got.q[2:] - got.q[:-2]) / (2 * h) - got.dq[1:-1])) < 1e-5
    assert np.max(np.abs((got.dq[2:] - got.dq[:-2]) / (2 * h) - got.d2q[1:-1])) < 1e-3
