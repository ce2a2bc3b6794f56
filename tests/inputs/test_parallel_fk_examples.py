"""Forward kinematics of the delta robot (examples/delta_fk.yaml) and the planar 3-RRR
(examples/three_rrr_fk.yaml) from their actuated angles, on both backends (the C kernel
really compiled and run through its generated ``solve_inputs``).

The reference is independent of symkin: prescribed platform poses, their actuated angles by
the closed-form inverse kinematics written here (circle intersections for the 3-RRR, the
equation A cos(theta) + B sin(theta) = C of each delta arm), and the solved pose compared with
the prescribed one to 1e-12. The geometry is read from the drawings (the files' points).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from codegen_support import compiled

import symkin

ROOT = Path(__file__).resolve().parents[2]
BACKENDS = ("c", "numpy")
T = np.linspace(0.0, 1.0, 101)


def _drawing(name: str) -> dict:
    return yaml.safe_load((ROOT / "examples" / f"{name}.yaml").read_text())["bodies"]


def _kernel(name: str, backend: str):
    kernel = compiled(ROOT / "examples" / f"{name}.yaml", backend)  # from its goldens
    assert kernel.backend == backend
    return kernel


def _rrr_angles(poses: np.ndarray) -> np.ndarray:
    """Inverse kinematics of the 3-RRR: each elbow E_k is where the circles about A_k (the
    proximal length) and C_k (the distal length) meet, on the right of A_k -> C_k as drawn;
    theta_k is the turn of A_k -> E_k from the drawing."""
    bodies = _drawing("three_rrr_fk")
    angles = np.zeros((len(poses), 3))
    for k in range(3):
        a, e0 = (np.array(bodies[f"prox{k + 1}"]["points"][n]) for n in (f"A{k + 1}",
                                                                           f"E{k + 1}"))
        c0 = np.array(bodies["platform"]["points"][f"C{k + 1}"])
        l1 = np.linalg.norm(e0 - a)
        l2 = np.linalg.norm(c0 - e0)
        drawn = math.atan2(*(e0 - a)[::-1])
        for row, (x, y, phi) in enumerate(poses):
            rotation = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
            c = np.array([x, y]) + rotation @ c0
            d = c - a
            length = float(np.linalg.norm(d))
            u = d / length
            along = (l1**2 - l2**2 + length**2) / (2 * length)
            elbow = a + along * u + math.sqrt(l1**2 - along**2) * np.array([u[1], -u[0]])
            angles[row, k] = math.remainder(math.atan2(*(elbow - a)[::-1]) - drawn, 2 * math.pi)
    return angles


def _rrr_poses(t: np.ndarray) -> np.ndarray:
    s = 2 * np.pi * t
    return np.stack([0.08 * np.cos(s) - 0.08, 0.06 * np.sin(s), 0.15 * np.sin(s)], axis=1)


@pytest.mark.parametrize("backend", BACKENDS)
def test_three_rrr_poses_are_recovered_from_actuated_angles(backend: str) -> None:
    kernel = _kernel("three_rrr_fk", backend)
    assert kernel.input_names == ("theta1", "theta2", "theta3")
    poses = _rrr_poses(T)
    got = symkin.solve(kernel, t=T, inputs=_rrr_angles(poses))
    assert not got.flagged.any()
    at = [kernel.coordinates.index(f"platform.{c}") for c in ("x", "y", "phi")]
    assert np.max(np.abs(got.q[:, at] - poses)) < 1e-12


def _rotate(axis: np.ndarray, theta: float, w: np.ndarray) -> np.ndarray:
    """Rodrigues' rotation of w by theta about the unit axis."""
    return (w * math.cos(theta) + np.cross(axis, w) * math.sin(theta)
            + axis * (axis @ w) * (1 - math.cos(theta)))


def _delta_arms() -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]]:
    """Per arm: shoulder S, unit axis, elbow E (drawn), platform point P (drawn, relative to
    the platform's centre C) and the rod length |E - P|, for rod a of each parallelogram."""
    bodies = _drawing("delta_fk")
    joints = {j["name"]: j for j in yaml.safe_load(
        (ROOT / "examples" / "delta_fk.yaml").read_text())["joints"]}
    centre = np.array(bodies["platform"]["points"]["C"])
    arms = []
    for k in (1, 2, 3):
        arm = bodies[f"arm{k}"]["points"]
        s, e = np.array(arm[f"S{k}"]), np.array(arm[f"E{k}a"])
        p = np.array(bodies["platform"]["points"][f"P{k}a"])
        axis = np.array(joints[f"shoulder{k}"]["axis"], dtype=float)
        arms.append((s, axis / np.linalg.norm(axis), e, p - centre, float(np.linalg.norm(e - p))))
    return arms


def _delta_angles(centres: np.ndarray) -> np.ndarray:
    """Inverse kinematics of the delta: the platform translates, so P = c + (P0 - C0); the
    elbow E(theta) = S + rot(axis, theta)(E0 - S) keeps |E - P| = L. With w = E0 - S split
    into its part along the axis, a (a.w), and across it, w', E - P = d' + w' cos(theta) +
    (a x w) sin(theta), d' = S - P + a (a.w); so A cos(theta) + B sin(theta) = K with
    A = 2 d'.w', B = 2 d'.(a x w), K = L^2 - |d'|^2 - |w'|^2: the root nearer the drawing
    (theta = 0)."""
    angles = np.zeros((len(centres), 3))
    for k, (s, axis, e0, offset, rod) in enumerate(_delta_arms()):
        w = e0 - s
        across = w - axis * (axis @ w)
        for row, c in enumerate(centres):
            d = s - (c + offset) + axis * (axis @ w)
            a, b = 2 * (d @ across), 2 * (d @ np.cross(axis, w))
            k_ = rod**2 - d @ d - across @ across
            base, spread = math.atan2(b, a), math.acos(k_ / math.hypot(a, b))
            angles[row, k] = min((math.remainder(base + spread, 2 * math.pi),
                                  math.remainder(base - spread, 2 * math.pi)), key=abs)
            elbow = s + _rotate(axis, angles[row, k], w)
            assert abs(np.linalg.norm(elbow - c - offset) - rod) < 1e-12
    return angles


def _delta_centres(t: np.ndarray) -> np.ndarray:
    s = 2 * np.pi * t
    return np.stack([0.06 * np.cos(s), 0.05 * np.sin(s), -0.3 - 0.04 * np.sin(2 * s)],
                    axis=1)


@pytest.mark.parametrize("backend", BACKENDS)
def test_delta_positions_are_recovered_from_arm_angles(backend: str) -> None:
    kernel = _kernel("delta_fk", backend)
    assert kernel.input_names == ("theta1", "theta2", "theta3")
    centres = _delta_centres(T)
    got = symkin.solve(kernel, t=T, inputs=_delta_angles(centres))
    assert not got.flagged.any()
    names = kernel.coordinates
    at = [names.index(f"platform.{c}") for c in ("x", "y", "z")]
    assert np.max(np.abs(got.q[:, at] - centres)) < 1e-12
    euler = got.q[:, [names.index(f"platform.e{k}") for k in range(4)]]
    assert np.max(np.abs(np.abs(euler[:, 0]) - 1)) < 1e-12  # it only translates


@pytest.mark.parametrize("name", ["delta_fk", "three_rrr_fk"])
def test_no_dense_fallback_along_the_path(name: str) -> None:
    """The generated C's sparse LU keeps its pivot order along the prescribed path (its order
    is checked along walks of the inputs, codegen.sample.input_walks; three_rrr_fk fell back
    40 times on this path when it was chosen at the drawn configuration alone)."""
    kernel = _kernel(name, "c")
    paths = {"delta_fk": lambda: _delta_angles(_delta_centres(T)),
             "three_rrr_fk": lambda: _rrr_angles(_rrr_poses(T))}
    inputs = paths[name]()
    assert symkin.solve(kernel, t=T, inputs=inputs).lu_fallbacks == 0
