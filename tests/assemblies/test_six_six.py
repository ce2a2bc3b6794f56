"""Every assembly of 6-6 Stewart platforms (planar base, planar platform): symkin.scan finds
exactly the assemblies counted independently in planar_six (linear elimination to three
unknowns, then a total-degree homotopy written with NumPy), each pose to 1e-8.

The cases: examples/stewart_fk.yaml at all legs 1.0 (8 real assemblies, four mirror pairs
about the base plane; its three-fold symmetric design is not a general one, and the homotopy
finds 14 roots with s != 0 there, not 20; the earlier starts of the scan found 7), and a
general platform chosen for its many real assemblies (12; its 20 roots are the 40 complex
assemblies of a general 6-6 platform, which checks that the homotopy lost no path).
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest
import yaml
from codegen_support import compiled
from motion_support import kernel as built
from motion_support import shared

from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.scanning.scan import scan
from tests.assemblies.planar_six import Count, Platform, assemblies
from tests.assemblies.test_every_assembly import _rotation

ROOT = Path(__file__).resolve().parents[2]

MANY_BASE = np.array([[0.2502, 0.7944], [0.5514, -0.5496], [-0.3997, 0.7471],
                      [-0.9895, 0.6425], [0.5941, -0.0641], [-0.3939, -0.4431]])
MANY_PLATFORM = np.array([[-0.1628, -0.0365], [0.003, 0.0355], [0.3291, 0.1944],
                          [0.0812, 0.3248], [-0.1891, -0.2257], [0.0748, -0.3029]])
MANY_LEGS = np.array([0.907, 0.9098, 1.1286, 1.2788, 0.7487, 0.6193])


def _example_platform() -> Platform:
    """stewart_fk's joints in their planes: the ground's, and the platform frame's (its
    origin drawn in the joints' plane, global axes)."""
    spec = yaml.safe_load((ROOT / "examples" / "stewart_fk.yaml").read_text())
    ground = spec["bodies"]["ground"]["points"]
    body = spec["bodies"]["platform"]
    height = float(body["frame"]["origin"][2])
    base = np.array([ground[f"B{k}"][:2] for k in range(1, 7)], dtype=float)
    top = np.array([body["points"][f"P{k}"] for k in range(1, 7)], dtype=float)
    assert np.all(top[:, 2] == height)
    return Platform(base, top[:, :2])


@functools.cache
def _general_count() -> Count:
    """The independent count of the general platform at MANY_LEGS, once for the module's
    tests (a total-degree homotopy: seconds)."""
    return assemblies(Platform(MANY_BASE, MANY_PLATFORM), MANY_LEGS)


@functools.cache
def _example_count() -> Count:
    """The independent count of stewart_fk's platform at all legs 1.0, once for the module."""
    return assemblies(_example_platform(), np.ones(6))


def _point(values: np.ndarray) -> str:
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"


def _six_six_file(tmp_path: Path, platform: Platform) -> Path:
    """The platform drawn level at height 1, its six legs distance drivers with input f."""
    ground = ", ".join(f"B{k + 1}: {_point([*platform.b[k], 0.0])}" for k in range(6))
    top = ", ".join(f"P{k + 1}: {_point([*platform.p[k], 1.0])}" for k in range(6))
    legs = [f"  - {{type: distance, name: leg{k + 1}, i: ground, j: platform, A: B{k + 1}, "
            f"B: P{k + 1}, f: input}}" for k in range(6)]
    text = "\n".join(["name: six_six", "space: 3d", "layout: drawn", "bodies:",
                      f"  ground: {{points: {{{ground}}}}}",
                      f"  platform: {{frame: {{origin: [0, 0, 1.0]}}, "
                      f"points: {{{top}}}}}", "joints: []", "drivers:", *legs,
                      "time: {t0: 0, t1: 1, dt: 0.1}"]) + "\n"
    return shared("six_six.yaml", text)  # one derivation per run


def _leg_gaps(platform: Platform, rotation: np.ndarray, origin: np.ndarray,
              legs: np.ndarray) -> np.ndarray:
    joints = np.column_stack([platform.p, np.zeros(6)]) @ rotation.T + origin
    base = np.column_stack([platform.b, np.zeros(6)])
    return np.linalg.norm(joints - base, axis=1) - legs


def _scanned_poses(kernel: KinematicsKernel, legs: np.ndarray
                   ) -> list[tuple[np.ndarray, np.ndarray]]:
    names = kernel.coordinates
    r = [names.index(f"platform.{c}") for c in "xyz"]
    e = [names.index(f"platform.e{k}") for k in range(4)]
    report = scan(kernel, inputs=legs)
    return [(_rotation(branch.q[e]), branch.q[r]) for branch in report.branches]


def _assert_the_same_poses(found: list[tuple[np.ndarray, np.ndarray]],
                           expected: list[tuple[np.ndarray, np.ndarray]]) -> None:
    assert len(found) == len(expected)
    for rotation, origin in expected:
        matches = [1 for r, t in found
                   if max(np.abs(r - rotation).max(), np.abs(t - origin).max()) < 1e-8]
        assert len(matches) == 1, (rotation, origin)


def test_the_independent_count_of_a_general_platform_is_complete() -> None:
    """20 complex solutions (the 40 complex assemblies in mirror pairs): no path was lost; two
    homotopy constants give the same real assemblies, each closing every leg."""
    platform = Platform(MANY_BASE, MANY_PLATFORM)
    count = _general_count()
    other = assemblies(platform, MANY_LEGS, gamma=complex(-0.3127, 0.9498))
    assert count.complex == other.complex == 20
    assert len(count.poses) == 12
    _assert_the_same_poses(other.poses, count.poses)
    for rotation, origin in count.poses:
        assert np.abs(rotation.T @ rotation - np.eye(3)).max() < 1e-10
        assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-10)
        assert np.abs(_leg_gaps(platform, rotation, origin, MANY_LEGS)).max() < 1e-10


def test_the_example_platform_counts_eight_at_legs_one() -> None:
    count = _example_count()
    assert len(count.poses) == 8
    heights = sorted(origin[2] for _, origin in count.poses)
    assert heights == pytest.approx([-h for h in reversed(heights)], abs=1e-12)  # mirrors


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_scan_of_stewart_fk_at_legs_one_finds_the_eight(backend: str) -> None:
    platform = _example_platform()
    kernel = compiled(ROOT / "examples" / "stewart_fk.yaml", backend)  # from its goldens
    expected = _example_count().poses
    found = _scanned_poses(kernel, np.ones(6))
    _assert_the_same_poses(found, expected)
    for rotation, origin in found:
        assert np.abs(_leg_gaps(platform, rotation, origin, np.ones(6))).max() < 1e-10


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_scan_of_a_general_six_six_finds_the_twelve(tmp_path: Path, backend: str) -> None:
    platform = Platform(MANY_BASE, MANY_PLATFORM)
    kernel = built(_six_six_file(tmp_path, platform), backend)
    expected = _general_count().poses
    found = _scanned_poses(kernel, MANY_LEGS)
    _assert_the_same_poses(found, expected)
    assert len(found) == 12
    for rotation, origin in found:
        assert np.abs(_leg_gaps(platform, rotation, origin, MANY_LEGS)).max() < 1e-10
