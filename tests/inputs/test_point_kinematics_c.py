"""The generated C ``<prefix>_point_kinematics``: global position, velocity and acceleration
of every named point from q, dq, ddq, compiled and called through cffi.

Reference: the crank tip of the textbook crank-slider in closed form, with the crank angle
phi = t^2 + pi/2 of the file (so phi_t = 2t, phi_tt = 2), and the other points against
central differences of their C positions along the motion.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from codegen_support import compiled, derived

import symkin

ROOT = Path(__file__).resolve().parents[2]


def _points_c(kernel, q, dq, ddq):
    ffi, lib = kernel.ffi, kernel.lib
    n = len(kernel.points)
    r, dr, ddr = (np.zeros(2 * n) for _ in range(3))
    buf = lambda a: ffi.from_buffer("double[]", np.ascontiguousarray(a, dtype=float))  # noqa: E731
    lib.crank_slider_point_kinematics(buf(q), buf(dq), buf(ddq), buf(kernel.p_values),
                                      buf(r), buf(dr), buf(ddr))
    return r.reshape(n, 2), dr.reshape(n, 2), ddr.reshape(n, 2)


def test_point_kinematics_in_c_against_closed_form_and_differences() -> None:
    kernel = compiled(ROOT / "examples/crank_slider.yaml", "c")
    assert kernel.points == (("crank", "tip"), ("rod", "P"))
    t = np.linspace(0.2, 0.6, 4001)
    traj = symkin.solve(kernel, t=t)
    a = 1.0
    rows = [_points_c(kernel, *state) for state in zip(traj.q, traj.dq, traj.d2q)]
    r, dr, ddr = (np.array([row[k] for row in rows]) for k in range(3))
    phi, w, al = t**2 + np.pi / 2, 2 * t, 2.0
    tip = np.stack([a * np.cos(phi), a * np.sin(phi)], axis=1)
    tip_t = a * w[:, None] * np.stack([-np.sin(phi), np.cos(phi)], axis=1)
    tip_tt = a * (al * np.stack([-np.sin(phi), np.cos(phi)], axis=1)
                  - (w**2)[:, None] * np.stack([np.cos(phi), np.sin(phi)], axis=1))
    assert np.abs(r[:, 0] - tip).max() < 1e-12
    assert np.abs(dr[:, 0] - tip_t).max() < 1e-12
    assert np.abs(ddr[:, 0] - tip_tt).max() < 1e-11
    h = t[1] - t[0]
    assert np.abs((r[2:, 1] - r[:-2, 1]) / (2 * h) - dr[1:-1, 1]).max() < 1e-5
    assert np.abs((dr[2:, 1] - dr[:-2, 1]) / (2 * h) - ddr[1:-1, 1]).max() < 1e-4


def test_null_rates_are_skipped() -> None:
    kernel = compiled(ROOT / "examples/crank_slider.yaml", "c")
    ffi, lib = kernel.ffi, kernel.lib
    q = np.ascontiguousarray(symkin.solve(kernel).q[3])
    r = np.zeros(4)
    dr = np.full(4, 7.0)
    lib.crank_slider_point_kinematics(ffi.from_buffer("double[]", q), ffi.NULL, ffi.NULL,
                                      ffi.from_buffer("double[]", kernel.p_values),
                                      ffi.from_buffer("double[]", r),
                                      ffi.from_buffer("double[]", dr), ffi.NULL)
    assert np.all(dr == 7.0) and np.isfinite(r).all()


def _rotation(e: np.ndarray) -> np.ndarray:
    """The rotation matrix of unit Euler parameters (e0 the scalar part), written out."""
    e0, e1, e2, e3 = e
    return np.array([
        [e0**2 + e1**2 - e2**2 - e3**2, 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)],
        [2 * (e1 * e2 + e0 * e3), e0**2 - e1**2 + e2**2 - e3**2, 2 * (e2 * e3 - e0 * e1)],
        [2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), e0**2 - e1**2 - e2**2 + e3**2]])


def test_spatial_point_kinematics_in_c() -> None:
    """A spatial mechanism (the RSSR four-bar): (x, y, z) triples, positions against r + A(e) s
    written out here, rates against central differences of the C positions."""
    system = derived(ROOT / "examples/rssr.yaml")
    kernel = compiled(ROOT / "examples/rssr.yaml", "c")
    ffi, lib = kernel.ffi, kernel.lib
    t0, t1, _ = system.time_grid
    t = np.linspace(t0, t0 + 0.25 * (t1 - t0), 2001)
    traj = symkin.solve(kernel, t=t)
    n = len(kernel.points)
    s = np.asarray(kernel.point_vectors(), dtype=float)
    assert s.shape == (n, 3)
    buf = lambda a: ffi.from_buffer("double[]", np.ascontiguousarray(a, dtype=float))  # noqa: E731
    r, dr, ddr = (np.zeros((t.size, 3 * n)) for _ in range(3))
    for k in range(t.size):
        lib.rssr_point_kinematics(buf(traj.q[k]), buf(traj.dq[k]), buf(traj.d2q[k]),
                                  buf(kernel.p_values), buf(r[k]), buf(dr[k]), buf(ddr[k]))
    r, dr, ddr = (a.reshape(t.size, n, 3) for a in (r, dr, ddr))
    for k, (body, _) in enumerate(kernel.points):
        if body == "ground":
            expected = np.broadcast_to(s[k], (t.size, 3))
        else:
            start = kernel.coordinates.index(f"{body}.x")
            q = traj.q[:, start:start + 7]
            expected = q[:, :3] + np.array([_rotation(e) @ s[k] for e in q[:, 3:]])
        assert np.abs(r[:, k] - expected).max() < 1e-12
    h = t[1] - t[0]
    assert np.abs((r[2:] - r[:-2]) / (2 * h) - dr[1:-1]).max() < 1e-5
    assert np.abs((dr[2:] - dr[:-2]) / (2 * h) - ddr[1:-1]).max() < 1e-4
    assert np.abs(dr).max() > 0.1 and np.abs(ddr).max() > 0.1  # the points really move
