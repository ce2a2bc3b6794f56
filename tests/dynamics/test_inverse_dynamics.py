"""Inverse dynamics against references derived here, independently of symkin's derivation:
the crank torque of a massless slider-crank by virtual work (closed form), Newton-Euler
free-body equations of every body of a four-bar with gravity, a spring-damper, a brake and
a force, and the power balance (effort power + applied power = dT/dt) on every example with
forces. Both backends; the C runs compiled code.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from codegen_support import compiled
from motion_support import kernel_from

import symkin

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
BACKENDS = ("c", "numpy")
OMEGA = np.array([[0.0, -1.0], [1.0, 0.0]])


def _solve(source, backend: str):
    """The run of a mechanism (a dictionary, or a file), its derivation and kernels shared by
    the tests here."""
    if isinstance(source, dict):
        return symkin.solve(kernel_from(source, backend))
    return symkin.solve(compiled(source, backend))


def _rot(phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s], [s, c]]).transpose(2, 0, 1)  # (T, 2, 2)


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


class Body:
    """Position, velocity, acceleration of a body-fixed point, written out (2.14-2.16)."""

    def __init__(self, traj, name: str) -> None:
        q, dq, ddq = traj.body(name)
        self.r, self.v, self.a = q[:, :2], dq[:, :2], ddq[:, :2]
        self.phi, self.w, self.alpha = q[:, 2], dq[:, 2], ddq[:, 2]
        self.R = _rot(self.phi)

    def point(self, s):
        Rs = self.R @ np.asarray(s, float)
        ORs = Rs @ OMEGA.T
        return (self.r + Rs, self.v + ORs * self.w[:, None],
                self.a + ORs * self.alpha[:, None] - Rs * (self.w ** 2)[:, None])


def _largest(traj) -> float:
    return max(np.abs(traj.reaction[..., :2]).max(), np.abs(traj.effort).max())


# ----- slider-crank: virtual work, closed form -------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
def test_slider_crank_torque_is_virtual_work(backend: str) -> None:
    """Massless links: T dθ + F·dx = 0, so the motor torque is T = F0 dx/dθ with
    x(θ) = a cos θ + sqrt(b² - (c - a sin θ)²) (Example 2.7) and the load -F0 along x."""
    data = yaml.safe_load((EXAMPLES / "crank_slider_load.yaml").read_text())
    for body in data["bodies"].values():
        for key in ("mass", "inertia", "com"):
            body.pop(key, None)
    data["forces"] = [f for f in data["forces"] if f["type"] != "gravity"]
    traj = _solve(data, backend)
    a, b, c, f0 = 1.0, 5.0, 4.0, 100.0
    theta = traj.t ** 2 + np.pi / 2
    h = c - a * np.sin(theta)
    dx = -a * np.sin(theta) + h * a * np.cos(theta) / np.sqrt(b ** 2 - h ** 2)
    torque = f0 * dx
    assert traj.forces.driver_names == ("motor",)
    np.testing.assert_allclose(traj.effort[:, 0], torque, rtol=0, atol=1e-10 * f0)
    # the slide carries the load's reaction: the force slider -> ground is the normal force
    # only (v = [0, 1]); with massless links the pins see the same force along the rod
    names = traj.forces.joint_names
    slide = traj.reaction[:, names.index("slide")]
    assert np.allclose(slide[:, 0], 0, atol=1e-12)
    rod_b = traj.reaction[:, names.index("B")]
    phi2 = np.arcsin(h / b)
    # the rod is a two-force member: the pin force is along the rod, its x part is F0
    np.testing.assert_allclose(rod_b[:, 0], f0, rtol=1e-10)
    np.testing.assert_allclose(rod_b[:, 1], f0 * np.tan(phi2), rtol=1e-10, atol=1e-9)


# ----- four-bar: Newton-Euler per body ---------------------------------------------------------

FB = dict(a=1.0, b=4.0, c=3.0, d=4.5, w=2 * np.pi, m1=1.0, m2=4.0, m3=3.0, k0=200.0,
          l0=2.0, d0=5.0, cr=2.0, g=-9.81)


def _four_bar_loads(traj):
    """Every external load of the four-bar, as (body, force (T,2), point (T,2), couple (T,))."""
    p = FB
    crank, coupler, rocker = (Body(traj, n) for n in ("crank", "coupler", "rocker"))
    bodies = {"crank": crank, "coupler": coupler, "rocker": rocker}
    masses = {"crank": (p["m1"], p["m1"] * p["a"] ** 2 / 12, [p["a"] / 2, 0]),
              "coupler": (p["m2"], 0.8, [p["b"] / 2, 0.4]),
              "rocker": (p["m3"], p["m3"] * p["c"] ** 2 / 12, [p["c"] / 2, 0])}
    T = traj.t.size
    loads = []
    for name, (m, _, com) in masses.items():
        rc, _, _ = bodies[name].point(com)
        loads.append((name, np.tile([0.0, m * p["g"]], (T, 1)), rc, np.zeros(T)))
    rp, vp, _ = coupler.point([p["b"] / 2, 1.2])
    anchor = np.array([2.0, 4.0])
    d = anchor - rp
    length = np.linalg.norm(d, axis=1)
    rate = -np.einsum("ij,ij->i", d, vp) / length  # dL/dt, the anchor fixed
    tension = p["k0"] * (length - p["l0"]) + p["d0"] * rate
    loads.append(("coupler", tension[:, None] * d / length[:, None], rp, np.zeros(T)))
    loads.append(("rocker", np.zeros((T, 2)), rocker.r, -p["cr"] * rocker.w))
    push = np.column_stack([10 * np.sin(2 * np.pi * traj.t), np.zeros(T)])
    loads.append(("coupler", push, rp, np.zeros(T)))
    return bodies, masses, loads, (vp, tension, rate, push)


@pytest.mark.parametrize("backend", BACKENDS)
def test_four_bar_newton_euler_per_body(backend: str) -> None:
    traj = _solve(EXAMPLES / "four_bar_dynamics.yaml", backend)
    bodies, masses, loads, _ = _four_bar_loads(traj)
    p = FB
    T = traj.t.size
    force = {n: np.zeros((T, 2)) for n in bodies}
    moment = {n: np.zeros(T) for n in bodies}  # about each centre of mass
    com = {n: bodies[n].point(masses[n][2]) for n in bodies}

    def apply(body, f, at, couple):
        if body in bodies:
            force[body] += f
            moment[body] += couple + _cross(at - com[body][0], f)

    for body, f, at, couple in loads:
        apply(body, f, at, couple)
    # joints: (name, i, j, the joint's point on i, global)
    points_on_i = {"O2": np.zeros((T, 2)), "A": bodies["crank"].point([p["a"], 0])[0],
                   "B": bodies["coupler"].point([p["b"], 0])[0], "O4": bodies["rocker"].r}
    joined = {"O2": ("ground", "crank"), "A": ("crank", "coupler"), "B": ("coupler", "rocker"),
              "O4": ("rocker", "ground")}
    for k, name in enumerate(traj.forces.joint_names):
        i, j = joined[name]
        f, m = traj.reaction[:, k, :2], traj.reaction[:, k, 2]
        apply(j, f, points_on_i[name], m)
        apply(i, -f, points_on_i[name], -m)
    apply("crank", np.zeros((T, 2)), bodies["crank"].r, traj.effort[:, 0])  # motor on body i
    scale = _largest(traj)
    for name, (m, inertia, _c) in masses.items():
        _, _, acc = com[name]
        np.testing.assert_allclose(force[name], m * acc, rtol=0, atol=1e-9 * scale,
                                   err_msg=f"sum of forces on {name}")
        np.testing.assert_allclose(moment[name], inertia * bodies[name].alpha, rtol=0,
                                   atol=1e-9 * scale, err_msg=f"sum of moments on {name}")
    # revolute joints carry no moment
    assert np.abs(traj.reaction[..., 2]).max() < 1e-9 * scale


# ----- power balance on every example with forces ----------------------------------------------

def _kinetic_rate(bodies, masses):
    total = 0.0
    for name, (m, inertia, c) in masses.items():
        _, v, a = bodies[name].point(c)
        total = total + m * np.einsum("ij,ij->i", v, a) + inertia * bodies[name].w * \
            bodies[name].alpha
    return total


def _power_four_bar(traj):
    bodies, masses, loads, (vp, tension, rate, push) = _four_bar_loads(traj)
    applied = sum(np.einsum("ij,ij->i", f, bodies[b].point(
        masses[b][2])[1]) for b, f, _, _ in loads[:3])  # gravity at each com
    applied += -tension * rate                            # spring-damper
    applied += -FB["cr"] * bodies["rocker"].w ** 2         # brake
    applied += np.einsum("ij,ij->i", push, vp)             # push at P
    drive = traj.effort[:, 0] * FB["w"]
    return drive + applied, _kinetic_rate(bodies, masses)


def _power_crank_slider(traj):
    a, b, m1, m2, m3, f0, g = 1.0, 5.0, 2.0, 5.0, 3.0, 100.0, -9.81
    bodies = {n: Body(traj, n) for n in ("crank", "rod", "slider")}
    masses = {"crank": (m1, m1 * a * a / 12, [a / 2, 0]), "rod": (m2, m2 * b * b / 12, [b / 2, 0]),
              "slider": (m3, 0.1, [0, 0])}
    applied = sum(masses[n][0] * g * bodies[n].point(masses[n][2])[1][:, 1] for n in bodies)
    applied = applied - f0 * bodies["slider"].v[:, 0]
    drive = traj.effort[:, 0] * 2 * traj.t  # theta = t^2 + pi/2
    return drive + applied, _kinetic_rate(bodies, masses)


def _power_parallelogram(traj):
    """The parallelogram with an extra bar and a swung lamp (drawn layout: each frame at the
    body's first point, global axes as drawn); its reactions are partly indeterminate, its
    efforts are not (tests/dynamics/test_redundant_reactions.py)."""
    a, th0, w, arm, mb, mc, ml, g = 1.0, np.pi / 3, np.pi / 2, 0.4, 1.0, 3.0, 2.0, -9.81
    half = [a * np.cos(th0) / 2, a * np.sin(th0) / 2]
    bodies = {n: Body(traj, n) for n in ("crank", "rocker", "extra", "coupler", "lamp")}
    masses = {"crank": (mb, mb * a * a / 12, half), "rocker": (mb, mb * a * a / 12, half),
              "extra": (mb, mb * a * a / 12, half), "coupler": (mc, 0.25, [0.5, 0]),
              "lamp": (ml, 0.02, [0, -arm])}
    applied = sum(masses[n][0] * g * bodies[n].point(masses[n][2])[1][:, 1] for n in bodies)
    swing = traj.effort[:, 1] * (bodies["lamp"].w - bodies["coupler"].w)
    return traj.effort[:, 0] * w + swing + applied, _kinetic_rate(bodies, masses)


POWER = {"four_bar_dynamics": _power_four_bar, "crank_slider_load": _power_crank_slider,
         "parallelogram_extra_bar_loads": _power_parallelogram}


def test_every_example_with_forces_has_a_power_balance() -> None:
    with_forces = sorted(p.stem for p in EXAMPLES.glob("*.yaml")
                         if "forces:" in p.read_text())
    assert with_forces == sorted(POWER)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", sorted(POWER))
def test_power_balance(name: str, backend: str) -> None:
    traj = _solve(EXAMPLES / f"{name}.yaml", backend)
    power, kinetic_rate = POWER[name](traj)
    scale = np.abs(power).max() + np.abs(kinetic_rate).max()
    np.testing.assert_allclose(power, kinetic_rate, rtol=0, atol=1e-9 * scale)


@pytest.mark.parametrize("backend", BACKENDS)
def test_prismatic_reaction_moment_is_about_A_on_i(backend: str) -> None:
    """The slider of the loaded crank-slider with the slide's point A off its frame origin:
    Newton-Euler for the slider (it does not turn) checks that the prismatic pair's M is the
    moment about A, carried by the slider (body i), of what the slider exerts on the ground."""
    data = yaml.safe_load((EXAMPLES / "crank_slider_load.yaml").read_text())
    slide = next(j for j in data["joints"] if j["type"] == "prismatic")
    slide["sA"] = [0.3, 0.2]
    traj = _solve(data, backend)
    b, m3, f0, g = 5.0, 3.0, 100.0, -9.81
    rod, slider = Body(traj, "rod"), Body(traj, "slider")
    names = traj.forces.joint_names
    f_b, m_b = traj.reaction[:, names.index("B"), :2], traj.reaction[:, names.index("B"), 2]
    f_s, m_s = (traj.reaction[:, names.index("slide"), :2],
                traj.reaction[:, names.index("slide"), 2])
    p_b = rod.point([b, 0])[0]
    a_point = slider.point([0.3, 0.2])[0]
    load = np.tile([-f0, 0.0], (traj.t.size, 1))
    total = f_b - f_s + load + np.array([0.0, m3 * g])
    scale = _largest(traj)
    np.testing.assert_allclose(total, m3 * slider.a, rtol=0, atol=1e-9 * scale)
    moment = _cross(p_b - slider.r, f_b) + m_b - _cross(a_point - slider.r, f_s) - m_s
    np.testing.assert_allclose(moment, 0.1 * slider.alpha, rtol=0, atol=1e-9 * scale)
    assert np.abs(m_s).max() > 1e-3 * scale  # the offset A makes the slide carry a moment
