"""Every assembly at given inputs (symkin.scan(kernel, inputs=...)): the number found equals
the number counted here, independently of symkin, and each assembly closes the loops.

The counts: a planar 3-RRR at fixed actuated angles is a 3-RPR (elbows fixed, distal links of
fixed length). Sweeping the platform angle phi, legs 1 and 2 place the platform in closed form
(two circles meet, two branches); the sign changes of leg 3's residual along both branches
count the assemblies (the branches join where the circles touch, with equal residuals, so no
root is lost there), and bisection gives each pose. A 3-3 (octahedral) Stewart platform: each
platform vertex lies on a circle about a base edge; sweeping vertex 1's angle, vertices 2 and 3
follow in closed form (two roots each), and the sign changes of the third side's residual over
the four branch pairs count the assemblies. The four-bar: two (circle intersections).
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from motion_support import kernel as built
from motion_support import shared

from symkin import cli
from symkin.errors import SolveError
from symkin.runtime.scanning.scan import scan

SWEEP = 200_000
ROOT = Path(__file__).resolve().parents[2]


def _sign_changes(f: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Indices k where f changes sign from sample k to k + 1 (periodic), both valid."""
    both = valid & np.roll(valid, -1)
    return np.flatnonzero(both & (np.sign(f) != np.sign(np.roll(f, -1))))


def _bisect(f: Callable[[float], float], a: float, b: float) -> float:
    fa = f(a)
    for _ in range(80):
        m = 0.5 * (a + b)
        fm = f(m)
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


def _rotation2(phi: float) -> np.ndarray:
    return np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])


# --- the planar 3-RRR, counted as a 3-RPR -------------------------------------------------

ELBOWS = np.array([[-0.02, 0.11], [-0.79, 0.73], [-0.44, -0.11]])
PLATFORM = np.array([[-0.53, -0.6], [-0.37, -0.19], [0.51, 0.47]])  # in its own frame
DISTAL = np.array([0.88, 0.85, 1.1])
PROXIMAL = 0.4  # the actuated link: its angle fixes the elbow


def _rpr_place(phi: np.ndarray, sign: int) -> tuple[np.ndarray, np.ndarray]:
    """The platform origin where legs 1 and 2 close at platform angles phi (branch sign), and
    where they can (the two circles meet)."""
    c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
    k1, k2 = (ELBOWS[k] - np.hstack([c * PLATFORM[k][0] - s * PLATFORM[k][1],
                                     s * PLATFORM[k][0] + c * PLATFORM[k][1]]) for k in (0, 1))
    d = k2 - k1
    length = np.linalg.norm(d, axis=1)
    along = (DISTAL[0]**2 - DISTAL[1]**2 + length**2) / (2 * length)
    h2 = DISTAL[0]**2 - along**2
    u = d / length[:, None]
    normal = np.stack([-u[:, 1], u[:, 0]], axis=1)
    return (k1 + along[:, None] * u + sign * np.sqrt(np.maximum(h2, 0.0))[:, None] * normal,
            h2 > 0)


def _rpr_residual(phi: np.ndarray, sign: int) -> np.ndarray:
    origin, _ = _rpr_place(phi, sign)
    c, s = np.cos(phi), np.sin(phi)
    joint = origin + np.stack([c * PLATFORM[2][0] - s * PLATFORM[2][1],
                               s * PLATFORM[2][0] + c * PLATFORM[2][1]], axis=1)
    return np.sum((joint - ELBOWS[2])**2, axis=1) - DISTAL[2]**2


@functools.cache  # the same sweep for every test of the module (read, never changed)
def rpr_poses() -> list[np.ndarray]:
    """Every (x, y, phi) of the platform, by the sweep of the module docstring."""
    phis = np.linspace(-math.pi, math.pi, SWEEP, endpoint=False)
    step = 2 * math.pi / SWEEP
    poses = []
    for sign in (1, -1):
        _, valid = _rpr_place(phis, sign)
        for k in _sign_changes(_rpr_residual(phis, sign), valid):
            phi = _bisect(lambda v, sign=sign: float(_rpr_residual(np.array([v]), sign)[0]),
                          phis[k], phis[k] + step)
            origin = _rpr_place(np.array([phi]), sign)[0][0]
            poses.append(np.array([*origin, math.remainder(phi, 2 * math.pi)]))
    return poses


def _point(values: np.ndarray) -> str:
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"


def _rrr_file(tmp_path: Path, pose: np.ndarray) -> Path:
    """A 3-RRR drawn in the assembly ``pose``: ground pivot A_k at PROXIMAL from the elbow."""
    lines = ["name: rrr_six", "layout: drawn", "bodies:"]
    pivots = ELBOWS + PROXIMAL * np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    joints = [_rotation2(pose[2]) @ PLATFORM[k] + pose[:2] for k in range(3)]
    ground = ", ".join(f"A{k + 1}: {_point(pivots[k])}" for k in range(3))
    lines.append(f"  ground: {{points: {{{ground}}}}}")
    for k in range(3):
        n = k + 1
        lines.append(f"  prox{n}: {{points: {{A{n}: {_point(pivots[k])}, "
                     f"E{n}: {_point(ELBOWS[k])}}}}}")
        lines.append(f"  dist{n}: {{points: {{E{n}: {_point(ELBOWS[k])}, "
                     f"C{n}: {_point(joints[k])}}}}}")
    lines.append(f"  platform: {{frame: {{origin: {_point(pose[:2])}, angle: {float(pose[2])!r}}}, "
                 "points: {%s}}" % ", ".join(f"C{k + 1}: {_point(joints[k])}" for k in range(3)))
    lines.append("joints:")
    for n in (1, 2, 3):
        lines += [f"  - {{type: revolute, i: ground, j: prox{n}, at: A{n}}}",
                  f"  - {{type: revolute, i: prox{n}, j: dist{n}, at: E{n}}}",
                  f"  - {{type: revolute, i: dist{n}, j: platform, at: C{n}}}"]
    lines.append("drivers:")
    lines += [f"  - {{type: angle, name: theta{n}, i: prox{n}, j: ground, theta: input}}"
              for n in (1, 2, 3)]
    lines.append("time: {t0: 0, t1: 1, dt: 0.1}")
    return shared("rrr_six.yaml", "\n".join(lines) + "\n")  # one derivation per run


def test_the_3rpr_sweep_counts_six() -> None:
    """The independent count itself: six poses, each closing all three legs."""
    poses = rpr_poses()
    assert len(poses) == 6
    for x, y, phi in poses:
        for k in range(3):
            gap = np.array([x, y]) + _rotation2(phi) @ PLATFORM[k] - ELBOWS[k]
            assert abs(np.linalg.norm(gap) - DISTAL[k]) < 1e-10


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_3rrr_has_the_six_assemblies_counted_by_the_sweep(tmp_path: Path, backend: str) -> None:
    expected = rpr_poses()
    kernel = built(_rrr_file(tmp_path, expected[0]), backend)
    report = scan(kernel, inputs={"theta1": 0.0, "theta2": 0.0, "theta3": 0.0})
    assert report.motions == () and dict(report.inputs) == {f"theta{n}": 0.0 for n in (1, 2, 3)}
    names = kernel.coordinates
    at = [names.index(f"platform.{c}") for c in ("x", "y", "phi")]
    found = [b.q[at] for b in report.branches]
    assert len(found) == len(expected) == 6
    for pose in expected:
        matches = [f for f in found if max(abs(f[0] - pose[0]), abs(f[1] - pose[1]),
                                           abs(math.remainder(f[2] - pose[2], 2 * math.pi)))
                   < 1e-8]
        assert len(matches) == 1, (pose, found)
    for branch in report.branches:  # the loops close: each distal link spans elbow to joint
        x, y, phi = branch.q[at]
        for k in range(3):
            joint = np.array([x, y]) + _rotation2(phi) @ PLATFORM[k]
            assert abs(np.linalg.norm(joint - ELBOWS[k]) - DISTAL[k]) < 1e-10


# --- the 3-3 (octahedral) Stewart platform -------------------------------------------------

BASE = np.array([[1.0, 0.0, 0.0], [-0.5, math.sqrt(3) / 2, 0.0], [-0.5, -math.sqrt(3) / 2, 0.0]])
LEGS = np.array([1.363, 0.996, 1.373, 1.018, 0.802, 1.306])  # B1P1 B2P1 B2P2 B3P2 B3P3 B1P3
SIDES = np.array([1.057, 1.203, 0.662])  # |P1P2|, |P1P3|, |P2P3|
ENDS = ((0, 1), (1, 2), (2, 0))  # the base vertices of platform vertex k's two legs


def _circle(k: int) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """Centre, radius and in-plane axes of the circle platform vertex k moves on: about the
    base edge of its two legs, at their lengths."""
    b1, b2 = BASE[ENDS[k][0]], BASE[ENDS[k][1]]
    r1, r2 = LEGS[2 * k], LEGS[2 * k + 1]
    edge = b2 - b1
    span = float(np.linalg.norm(edge))
    w = edge / span
    along = (r1**2 - r2**2 + span**2) / (2 * span)
    u = np.cross(w, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    return b1 + along * w, math.sqrt(r1**2 - along**2), u, np.cross(w, u)


def _on(k: int, angle: np.ndarray) -> np.ndarray:
    centre, radius, u, v = _circle(k)
    return centre + radius * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)


def _follow(k: int, vertex: np.ndarray, side: float, sign: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertex k's angles at distance ``side`` from vertex 1 (branch sign): a cos + b sin = c."""
    centre, radius, u, v = _circle(k)
    m = centre - vertex
    a, b = 2 * radius * (m @ u), 2 * radius * (m @ v)
    c = side**2 - np.sum(m * m, axis=1) - radius**2
    reach = np.hypot(a, b)
    return (np.arctan2(b, a) + sign * np.arccos(np.clip(c / reach, -1, 1)),
            np.abs(c) < reach)


def _third_side(theta: np.ndarray, s2: int, s3: int) -> tuple[np.ndarray, np.ndarray]:
    vertex = _on(0, theta)
    a2, ok2 = _follow(1, vertex, SIDES[0], s2)
    a3, ok3 = _follow(2, vertex, SIDES[1], s3)
    return np.sum((_on(1, a2) - _on(2, a3))**2, axis=1) - SIDES[2]**2, ok2 & ok3


@functools.cache  # the same sweep for every test of the module (read, never changed)
def stewart_vertices() -> list[np.ndarray]:
    """The platform's vertices (3, 3) in every assembly, by the sweep of the docstring."""
    thetas = np.linspace(-math.pi, math.pi, SWEEP, endpoint=False)
    step = 2 * math.pi / SWEEP
    found = []
    for s2 in (1, -1):
        for s3 in (1, -1):
            f, valid = _third_side(thetas, s2, s3)
            for k in _sign_changes(f, valid):
                def third(v: float, s2: int = s2, s3: int = s3) -> float:
                    return float(_third_side(np.array([v]), s2, s3)[0][0])

                theta = np.array([_bisect(third, thetas[k], thetas[k] + step)])
                vertex = _on(0, theta)
                found.append(np.vstack([vertex, _on(1, _follow(1, vertex, SIDES[0], s2)[0]),
                                        _on(2, _follow(2, vertex, SIDES[1], s3)[0])]))
    return found


def _stewart_file(tmp_path: Path, vertices: np.ndarray) -> Path:
    """The 3-3 platform drawn at ``vertices``, its six legs distance drivers with input f."""
    ground = ", ".join(f"B{k + 1}: {_point(BASE[k])}" for k in range(3))
    top = ", ".join(f"P{k + 1}: {_point(vertices[k])}" for k in range(3))
    legs = [f"  - {{type: distance, name: leg{2 * k + n + 1}, i: ground, j: platform, "
            f"A: B{ENDS[k][n] + 1}, B: P{k + 1}, f: input}}" for k in range(3) for n in (0, 1)]
    text = "\n".join(["name: octahedral", "space: 3d", "layout: drawn", "bodies:",
                      f"  ground: {{points: {{{ground}}}}}",
                      f"  platform: {{points: {{{top}}}}}", "joints: []", "drivers:",
                               *legs, "time: {t0: 0, t1: 1, dt: 0.1}"]) + "\n"
    return shared("octahedral.yaml", text)  # one derivation per run


def _rotation(e: np.ndarray) -> np.ndarray:
    """A(e) of unit Euler parameters, written out here."""
    e0, e1, e2, e3 = e
    return 2 * np.array([
        [e0 * e0 + e1 * e1 - 0.5, e1 * e2 - e0 * e3, e1 * e3 + e0 * e2],
        [e1 * e2 + e0 * e3, e0 * e0 + e2 * e2 - 0.5, e2 * e3 - e0 * e1],
        [e1 * e3 - e0 * e2, e2 * e3 + e0 * e1, e0 * e0 + e3 * e3 - 0.5]])


def test_the_octahedral_sweep_counts_twelve() -> None:
    found = stewart_vertices()
    assert len(found) == 12
    for vertices in found:
        for k, (i, j) in enumerate(ENDS):
            assert abs(np.linalg.norm(vertices[k] - BASE[i]) - LEGS[2 * k]) < 1e-10
            assert abs(np.linalg.norm(vertices[k] - BASE[j]) - LEGS[2 * k + 1]) < 1e-10
        sides = [np.linalg.norm(vertices[a] - vertices[b]) for a, b in ((0, 1), (0, 2), (1, 2))]
        assert np.max(np.abs(np.array(sides) - SIDES)) < 1e-10


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_stewart_3_3_has_the_twelve_assemblies_counted_by_the_sweep(tmp_path: Path,
                                                                     backend: str) -> None:
    expected = stewart_vertices()
    kernel = built(_stewart_file(tmp_path, expected[0]), backend)
    report = scan(kernel, inputs=LEGS)
    names = kernel.coordinates
    r = [names.index(f"platform.{c}") for c in ("x", "y", "z")]
    e = [names.index(f"platform.e{k}") for k in range(4)]
    local = expected[0] - expected[0][0]  # the frame: at P1, axes as drawn
    found = [branch.q[r] + local @ _rotation(branch.q[e]).T for branch in report.branches]
    assert len(found) == len(expected) == 12
    for vertices in expected:
        assert sum(np.max(np.abs(f - vertices)) < 1e-8 for f in found) == 1
    for vertices in found:  # every leg closes
        for k, (i, j) in enumerate(ENDS):
            assert abs(np.linalg.norm(vertices[k] - BASE[i]) - LEGS[2 * k]) < 1e-10
            assert abs(np.linalg.norm(vertices[k] - BASE[j]) - LEGS[2 * k + 1]) < 1e-10


def test_cli_scan_at_inputs_lists_the_six_and_locates_bad_inputs(
        tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    """``symkin scan`` in this process (cli.main, what the console script runs; an exception
    it let out would fail the test as a traceback would)."""
    path = str(_rrr_file(tmp_path, rpr_poses()[0]))
    status = cli.main(["scan", path, "--backend", "numpy", "--all-branches", "--input",
                       "theta1=0", "--input", "theta2=0", "--input", "theta3=0"])
    out, err = capfd.readouterr()
    assert status == 0, err
    assert "theta3 = 0: 6\n" in out
    for bad, said in ((["--input", "theta1=x"], "--input theta1=x: write NAME=VALUE"),
                      (["--input", "theta1=0"], "missing 'theta2', 'theta3'"),
                      ([], "a scan needs their values")):
        status = cli.main(["scan", path, "--backend", "numpy", *bad])
        err = capfd.readouterr().err
        assert status == 2 and said in err and path in err, err


def test_scan_refuses_bad_inputs_with_what_is_wrong() -> None:
    with_inputs = built(ROOT / "examples" / "crank_slider_input.yaml", "numpy")
    without = built(ROOT / "tests" / "mechanisms" / "non_grashof.yaml", "numpy")
    for kernel, inputs, said in (
            (with_inputs, [1.0, 2.0], "give 1 values (crank_angle), got 2"),
            (with_inputs, {"crank_angle": math.inf}, "crank_angle is inf"),
            (with_inputs, {"crank": 1.0}, "no input driver named 'crank'; missing 'crank_angle'"),
            (without, [1.0], "has no input drivers")):
        with pytest.raises(SolveError, match=re.escape(said)):
            scan(kernel, inputs=inputs)


def test_crank_slider_at_an_input_angle_has_its_two_assemblies() -> None:
    """The textbook crank-slider with the crank angle an input: the slider slides on y = c = 4,
    the rod (b = 5) joins the crank tip A = (cos theta, sin theta) (a = 1) to it, so its x is
    cos(theta) +- sqrt(b^2 - (c - sin(theta))^2): two assemblies."""
    kernel = built(ROOT / "examples" / "crank_slider_input.yaml", "c")
    theta = 1.2
    report = scan(kernel, inputs={"crank_angle": theta})
    reach = math.sqrt(25.0 - (4.0 - math.sin(theta))**2)
    expected = [math.cos(theta) - reach, math.cos(theta) + reach]
    names = kernel.coordinates
    found = sorted(float(b.q[names.index("slider.x")]) for b in report.branches)
    assert len(found) == 2 and np.allclose(found, expected, atol=1e-9, rtol=0)
    for branch in report.branches:
        assert branch.q[names.index("slider.y")] == pytest.approx(4.0, abs=1e-9)
