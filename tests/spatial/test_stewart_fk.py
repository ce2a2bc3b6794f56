"""Forward kinematics of the Stewart-Gough platform with the leg lengths as inputs
(examples/stewart_fk.yaml, one moving body; examples/stewart_legs_fk.yaml, with its 12 leg
bodies): the generated C ``solve_inputs`` (through symkin.solve with a C kernel) and the
NumPy backend recover the prescribed poses from the leg lengths.

The reference is independent of symkin: the benchmark's poses (stewart_trajectory of
bench/stewart/stewart.c, roll, pitch, yaw as in stewart.h) and their leg lengths
|r + R P_i - B_i| by NumPy; the solved pose is compared with the prescribed one (position, and
the rotation matrix A(e) of the solved Euler parameters against R), and the solved rates and
accelerations with central differences of the solved positions and, exactly, with the
prescribed motion's own derivatives (mpmath's differentiation of the closed form at 40 digits,
legs and pose alike).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import mpmath
import numpy as np
import pytest
from codegen_support import compiled, derived
from octave_support import assert_octave_equals_numpy, needs_octave

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


@functools.cache
def _compiled(name: str, backend: str):
    # one derivation and generation per run for both backends and the Octave check
    # (stewart_legs_fk's take a minute each), one kernel per backend for every test here
    return compiled(ROOT / "examples" / f"{name}.yaml", backend)


@pytest.fixture(scope="module", params=[(f, b) for f in FILES for b in BACKENDS],
                ids=lambda p: f"{p[0]}-{p[1]}")
def kernel(request: pytest.FixtureRequest):
    name, backend = request.param
    return name, _compiled(name, backend)


@needs_octave
@pytest.mark.slow
def test_octave_runs_equal_numpy() -> None:
    """stewart_legs_fk's part of tests/backends/octave's check on every example, here where
    its derivation and NumPy kernel are built anyway; its .m files are the goldens."""
    assert_octave_equals_numpy(derived(ROOT / "examples" / "stewart_legs_fk.yaml"),
                               _compiled("stewart_legs_fk", "numpy"), "stewart_legs_fk",
                               _compiled("stewart_legs_fk", "octave"))


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
        assert np.max(np.abs(q[at[:3]] - pose[:3])) < 1e-12  # seen: 1.6e-15
        assert np.max(np.abs(_euler_rotation(q[at[3:]]) - _rotation(*pose[3:]))) < 1e-12


def test_rates_and_accelerations_match_differences(kernel) -> None:
    """With the legs' rates and accelerations (central differences of the closed-form lengths
    on a fine grid), the solved dq and d2q equal differences of the solved positions."""
    name, k = kernel
    # a quarter of the first 0.2 s at the same spacing h (the differences' error is set by h;
    # every pose component moves here): NumPy's loop over 801 points took half a minute
    t = np.linspace(0.0, 0.05, 201)
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


def _exact_run(tilt: float, name: str) -> tuple[dict[str, np.ndarray], ...]:
    """_exact on the grid of test_rates_and_accelerations_equal_the_motions_own, the legs
    less the file's home lengths."""
    home = _legs(np.array([0, 0, 1.0, 0, 0, 0])) * FILES[name]
    return tuple({**x, "legs": x["legs"] - home} for x in _exact_motion(tilt))


@functools.cache
def _exact_motion(tilt: float) -> tuple[dict[str, np.ndarray], ...]:
    """The mpmath differentiation, once per tilt for both files and backends."""
    return tuple(_exact(tilt, float(s)) for s in np.linspace(0.0, 1.0, 33))


def _exact(tilt: float, t: float) -> dict[str, np.ndarray]:
    """The prescribed motion and its first two time derivatives at t, by mpmath (40 digits):
    the legs and the platform's origin r and rotation R."""
    base, top = _geometry()

    def pose(s: mpmath.mpf) -> tuple[mpmath.matrix, mpmath.matrix]:
        # every leg and entry is differentiated at the same points s, at the same working
        # precision (mpmath.diff raises it): each pose computed once
        return _pose(s, mpmath.mp.prec)

    @functools.cache
    def _pose(s: mpmath.mpf, prec: int) -> tuple[mpmath.matrix, mpmath.matrix]:
        w = 2 * mpmath.pi * s
        a, b, c = tilt * mpmath.sin(w), tilt * mpmath.cos(w), tilt / 2 * mpmath.sin(3 * w)
        rz = mpmath.matrix([[mpmath.cos(c), -mpmath.sin(c), 0], [mpmath.sin(c), mpmath.cos(c), 0],
                            [0, 0, 1]])
        ry = mpmath.matrix([[mpmath.cos(b), 0, mpmath.sin(b)], [0, 1, 0],
                            [-mpmath.sin(b), 0, mpmath.cos(b)]])
        rx = mpmath.matrix([[1, 0, 0], [0, mpmath.cos(a), -mpmath.sin(a)],
                            [0, mpmath.sin(a), mpmath.cos(a)]])
        r = mpmath.matrix([mpmath.mpf("0.1") * mpmath.cos(w), mpmath.mpf("0.1") * mpmath.sin(w),
                           1 + mpmath.mpf("0.05") * mpmath.sin(2 * w)])
        return r, rz * ry * rx

    def leg(k: int, s: mpmath.mpf) -> mpmath.mpf:
        r, rotation = pose(s)
        arm = r + rotation * mpmath.matrix(top[k].tolist()) - mpmath.matrix(base[k].tolist())
        return mpmath.norm(arm)

    def entry(kind: str, index: int, s: mpmath.mpf) -> mpmath.mpf:
        r, rotation = pose(s)
        return r[index] if kind == "r" else rotation[index // 3, index % 3]

    with mpmath.workdps(40):
        at = mpmath.mpf(t)
        out = {}
        for n, suffix in enumerate(("", "_t", "_tt")):
            out["legs" + suffix] = np.array(
                [float(mpmath.diff(lambda s, k=k: leg(k, s), at, n)) for k in range(6)])
            out["r" + suffix] = np.array(
                [float(mpmath.diff(lambda s, i=i: entry("r", i, s), at, n)) for i in range(3)])
            out["R" + suffix] = np.array(
                [float(mpmath.diff(lambda s, i=i: entry("R", i, s), at, n))
                 for i in range(9)]).reshape(3, 3)
    return out


@pytest.mark.parametrize("tilt", [0.05, 0.5])
def test_rates_and_accelerations_equal_the_motions_own(kernel, tilt: float) -> None:
    """With the legs' exact rates and accelerations, the platform's solved velocity and
    acceleration equal the prescribed motion's (r and the rotation matrix's derivatives, from
    the solved Euler parameters: A is quadratic in e, so A' = (A(e + e') - A(e - e')) / 2 and
    A'' = 2 (A(e') - A(0)) + (A(e + e'') - A(e - e'')) / 2, exactly)."""
    name, k = kernel
    t = np.linspace(0.0, 1.0, 33)  # close enough that Newton tracks one assembly
    exact = _exact_run(tilt, name)
    got = symkin.solve(k, t=t, inputs=np.array([x["legs"] for x in exact]),
                       input_rates=np.array([x["legs_t"] for x in exact]),
                       input_accels=np.array([x["legs_tt"] for x in exact]))
    assert not got.flagged.any() and not got.branch_jumps.any()
    names = k.coordinates
    r = [names.index(f"platform.{c}") for c in ("x", "y", "z")]
    e = [names.index(f"platform.e{j}") for j in range(4)]
    zero = _euler_rotation(np.zeros(4))
    for q, dq, ddq, x in zip(got.q, got.dq, got.d2q, exact):
        assert np.max(np.abs(q[r] - x["r"])) < 1e-12
        assert np.max(np.abs(dq[r] - x["r_t"])) < 1e-11
        assert np.max(np.abs(ddq[r] - x["r_tt"])) < 1e-10
        rate = (_euler_rotation(q[e] + dq[e]) - _euler_rotation(q[e] - dq[e])) / 2
        accel = (2 * (_euler_rotation(dq[e]) - zero)
                 + (_euler_rotation(q[e] + ddq[e]) - _euler_rotation(q[e] - ddq[e])) / 2)
        assert np.max(np.abs(rate - x["R_t"])) < 1e-11
        assert np.max(np.abs(accel - x["R_tt"])) < 1e-10
