"""Inverse dynamics of spatial mechanisms against references derived here, independently of
symkin's derivation (Euler parameters, the kinetic energy and Lagrange's equations):

- a body turning about a vertical axis at constant speed: the bearing's force and moment in
  closed form (centripetal force, weight, the products of inertia's gyroscopic moment);
- Newton-Euler per body (sum of forces = m a_c, sum of moments about the centre of mass =
  J alpha + ω x J ω, global) on the spatial slider-crank with gravity, a torque, a damper force
  and a spring-damper;
- the Stewart platform at rest under its weight: leg forces f = J^-T w, J from the legs'
  directions;
- the power balance (effort power + applied power = dT/dt).
Both backends; the C runs compiled code. The slider-crank is the file
bench/spatial_slider_crank_forces.yaml (checked here to be the example with this module's
masses and loads), so that this module, the 3D report's tests and the forces' instruction
budget derive and generate it once per run.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from motion_support import kernel as shared_kernel
from motion_support import kernel_from

import symkin

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
FORCES = ROOT / "bench" / "spatial_slider_crank_forces.yaml"
BACKENDS = ("c", "numpy")
G = np.array([0.0, 0.0, -9.81])


def _solve(data: dict, backend: str):
    return symkin.solve(kernel_from(data, backend))  # derived once for both backends


def _rotation(e):
    """A(e) of Euler parameters e (T, 4), written out: (T, 3, 3)."""
    e0, e1, e2, e3 = e.T
    return np.stack([
        np.stack([e0**2 + e1**2 - e2**2 - e3**2, 2 * (e1*e2 - e0*e3), 2 * (e1*e3 + e0*e2)], -1),
        np.stack([2 * (e1*e2 + e0*e3), e0**2 - e1**2 + e2**2 - e3**2, 2 * (e2*e3 - e0*e1)], -1),
        np.stack([2 * (e1*e3 - e0*e2), 2 * (e2*e3 + e0*e1), e0**2 - e1**2 - e2**2 + e3**2], -1),
    ], 1)


def _e_matrix(e):
    """E(e) = [-e, ẽ + e0 I], (T, 3, 4): ω = 2 E ė (global)."""
    e0, e1, e2, e3 = e.T
    return np.stack([np.stack([-e1, e0, -e3, e2], -1), np.stack([-e2, e3, e0, -e1], -1),
                     np.stack([-e3, -e2, e1, e0], -1)], 1)


class Body:
    """A spatial body's pose and motion from its seven coordinates."""

    def __init__(self, traj, name: str) -> None:
        q, dq, ddq = traj.body(name)
        self.r, self.v, self.a = q[:, :3], dq[:, :3], ddq[:, :3]
        self.A = _rotation(q[:, 3:])
        E = _e_matrix(q[:, 3:])
        self.w = 2 * np.einsum("tij,tj->ti", E, dq[:, 3:])
        self.alpha = 2 * np.einsum("tij,tj->ti", E, ddq[:, 3:])

    def point(self, s):
        """Position, velocity and acceleration of the point with local vector s."""
        As = np.einsum("tij,j->ti", self.A, np.asarray(s, float))
        wAs = np.cross(self.w, As)
        return (self.r + As, self.v + wAs,
                self.a + np.cross(self.alpha, As) + np.cross(self.w, wAs))

    def inertia(self, J):
        """The tensor in global components, A J Aᵀ: (T, 3, 3)."""
        return np.einsum("tij,jk,tlk->til", self.A, np.asarray(J, float), self.A)


# ----- a body turning about a vertical axis: closed form ---------------------------------------

ROTOR = {
    "name": "rotor", "space": "3d", "layout": "drawn",
    "parameters": {"a": 0.3, "h": 0.2, "m": 2.0, "w": 3.0, "P": 0.02, "beta": 0.0},
    "bodies": {"arm": {"points": {"O": [0, 0, 0], "C": ["a", 0, "h"]}, "mass": "m",
                       "inertia": [[0.1, 0, "P"], [0, 0.2, 0], ["P", 0, 0.15]], "com": "C"}},
    "joints": [{"type": "revolute", "name": "shaft", "i": "ground", "j": "arm", "at": "O",
                "axis": [0, 0, 1]}],
    # θ = ωt + ½βt²: turning at a constant ω (β = 0, the file's), or speeding up (ω = 0); one
    # kernel for both, the parameters given at run time
    "drivers": [{"type": "angle", "name": "motor", "joint": "shaft",
                 "theta": "w*t + beta*t**2/2"}],
    "forces": [{"type": "gravity", "g": [0, 0, -9.81]}],
    "time": {"t0": 0, "t1": 2, "dt": 0.05},
}


@pytest.mark.parametrize("backend", BACKENDS)
def test_rotor_bearing_loads_in_closed_form(backend: str) -> None:
    """Turning at constant ω about z, the centre c = [a cos ωt, a sin ωt, h] needs the force
    F = m a_c - m g = [-m ω² a cos, -m ω² a sin, m g] from the bearing; about c the moments
    balance ω x J ω = ω² [-J_yz, J_xz, 0] with J_xz = P cos ωt, J_yz = P sin ωt (J = Rz J' Rzᵀ),
    so the bearing's moment about O is M_O = ω² [-P sin ωt, P cos ωt, 0] + c x F, and the
    motor delivers no torque."""
    traj = _solve(ROTOR, backend)
    a, h, m, w, p = 0.3, 0.2, 2.0, 3.0, 0.02
    wt = w * traj.t
    c = np.stack([a * np.cos(wt), a * np.sin(wt), np.full_like(wt, h)], -1)
    force = np.stack([-m * w**2 * a * np.cos(wt), -m * w**2 * a * np.sin(wt),
                      np.full_like(wt, m * 9.81)], -1)
    moment = w**2 * np.stack([-p * np.sin(wt), p * np.cos(wt), 0 * wt], -1) + np.cross(c, force)
    assert traj.reaction.shape == (traj.t.size, 1, 6)
    np.testing.assert_allclose(traj.reaction[:, 0, :3], force, rtol=0, atol=1e-9)
    np.testing.assert_allclose(traj.reaction[:, 0, 3:], moment, rtol=0, atol=1e-9)
    np.testing.assert_allclose(traj.effort[:, 0], 0, atol=1e-9)


@pytest.mark.parametrize("backend", BACKENDS)
def test_rotor_speeding_up_needs_the_torque_about_the_axis(backend: str) -> None:
    """θ = ½ β t² (ω = 0, β = 2: θ = t²): the motor's torque about z on the arm is
    (J_zz + m a²) β."""
    traj = symkin.solve(kernel_from(ROTOR, backend), params={"w": 0.0, "beta": 2.0})
    e3 = traj.q[:, traj.coordinates.index("arm.e3")]
    np.testing.assert_allclose(e3, np.sin(traj.t**2 / 2), atol=1e-12)  # it turned by t²
    np.testing.assert_allclose(traj.effort[:, 0], (0.15 + 2.0 * 0.3**2) * 2.0, atol=1e-9)


# ----- the spatial slider-crank: Newton-Euler per body -------------------------------------------

R_, L_, H_, K_ = 0.08, 0.4, 0.1, 0.12
XB = np.sqrt(L_**2 - (H_ + R_) ** 2 - K_**2)
SPRING_END = np.array([0.2, 0.3, 0.3])
MASS = {"crank": 1.5, "rod": 2.0, "slider": 3.0}
INERTIA = {"crank": [[0.004, 0, 0], [0, 0.003, 0.0005], [0, 0.0005, 0.002]],
           "rod": np.diag([0.02, 0.01, 0.025]), "slider": np.eye(3) * 0.01}
ORIGIN = {"ground": np.zeros(3), "crank": np.array([0, H_, K_]),
          "rod": np.array([0, H_ + R_, K_]), "slider": np.array([XB, 0, 0])}
COM = {"crank": np.array([0, H_ + R_ / 2, K_]), "rod": np.array([XB, H_ + R_, K_]) / 2,
       "slider": np.array([XB, 0, 0])}
# joint: (i, j, its point as drawn)
JOINTS = {"crank_bearing": ("ground", "crank", ORIGIN["crank"]),
          "pin": ("crank", "rod", ORIGIN["rod"]),
          "cross": ("slider", "rod", ORIGIN["slider"]),
          "guide": ("ground", "slider", ORIGIN["slider"])}


def _slider_crank() -> dict:
    data = yaml.safe_load((EXAMPLES / "spatial_slider_crank.yaml").read_text())
    for body in MASS:
        inertia = np.asarray(INERTIA[body])
        data["bodies"][body].update(mass=MASS[body], inertia=inertia.tolist(),
                                    com=COM[body].tolist())
    data["forces"] = [
        {"type": "gravity", "g": G.tolist()},
        {"type": "torque", "name": "twist", "body": "rod", "m": ["0.3*sin(2*pi*t)", 0, 0.1]},
        {"type": "force", "name": "damper", "body": "slider", "at": [float(XB), 0, 0],
         "f": ["-40*slider.x_t", 0, 5]},
        {"type": "spring", "name": "s1", "i": "rod", "A": ORIGIN["rod"].tolist(),
         "j": "ground", "B": SPRING_END.tolist(), "k": 300, "length0": 0.1, "damping": 4},
    ]
    return data


def test_the_bench_file_is_this_slider_crank() -> None:
    """bench/spatial_slider_crank_forces.yaml is the example with the masses, tensors,
    centres and loads written above, but for its name and time step."""
    bench = yaml.safe_load(FORCES.read_text(encoding="utf-8"))
    assert {**_slider_crank(), "name": bench["name"], "time": bench["time"]} == bench


def _solved_slider_crank(backend: str):
    """The bench file (above) on 51 points of its second (its own file's grid has 101)."""
    return symkin.solve(shared_kernel(FORCES, backend), t=np.linspace(0.0, 1.0, 51))


def _external(traj, bodies):
    """Per body, the applied loads other than joints and drivers: (force, moment about c),
    and their power."""
    t = traj.t
    loads = {}
    power = np.zeros(t.size)
    for name, body in bodies.items():
        c, vc, _ = body.point(COM[name] - ORIGIN[name])
        loads[name] = [MASS[name] * G + 0 * c, np.zeros_like(c)]
        power += vc @ (MASS[name] * G)
    n = np.stack([0.3 * np.sin(2 * np.pi * t), 0 * t, 0.1 + 0 * t], -1)
    loads["rod"][1] = loads["rod"][1] + n
    power += np.einsum("ti,ti->t", n, bodies["rod"].w)
    slider = bodies["slider"]
    f = np.stack([-40 * slider.v[:, 0], 0 * t, 5 + 0 * t], -1)
    loads["slider"][0] = loads["slider"][0] + f  # at B, the slider's centre
    power += np.einsum("ti,ti->t", f, slider.v)
    x, vx, _ = bodies["rod"].point(np.zeros(3))
    d = SPRING_END - x
    length = np.linalg.norm(d, axis=1)
    rate = -np.einsum("ti,ti->t", d, vx) / length
    tension = 300 * (length - 0.1) + 4 * rate
    spring = tension[:, None] * d / length[:, None]
    c_rod = bodies["rod"].point(COM["rod"] - ORIGIN["rod"])[0]
    loads["rod"][0] = loads["rod"][0] + spring
    loads["rod"][1] = loads["rod"][1] + np.cross(x - c_rod, spring)
    power += -tension * rate
    return loads, power


@pytest.mark.parametrize("backend", BACKENDS)
def test_slider_crank_newton_euler_per_body(backend: str) -> None:
    traj = _solved_slider_crank(backend)
    assert traj.forces.joint_names == tuple(JOINTS)
    assert traj.forces.driver_names == ("driver0",)
    bodies = {name: Body(traj, name) for name in MASS}
    loads, _ = _external(traj, bodies)
    total = {name: [f.copy(), m.copy()] for name, (f, m) in loads.items()}
    com = {name: bodies[name].point(COM[name] - ORIGIN[name])[0] for name in MASS}
    for k, (i, j, drawn) in enumerate(JOINTS.values()):
        point = (bodies[i].point(drawn - ORIGIN[i])[0] if i in bodies
                 else np.tile(drawn, (traj.t.size, 1)))
        force, moment = traj.reaction[:, k, :3], traj.reaction[:, k, 3:]
        for body, sign in ((j, 1.0), (i, -1.0)):
            if body in total:
                total[body][0] += sign * force
                total[body][1] += sign * (moment + np.cross(point - com[body], force))
    torque = traj.effort[:, 0][:, None] * np.array([1.0, 0, 0])  # on j = crank about x
    total["crank"][1] += torque
    scale = max(np.abs(traj.reaction).max(), np.abs(traj.effort).max())
    for name, body in bodies.items():
        _, _, ac = body.point(COM[name] - ORIGIN[name])
        J = body.inertia(INERTIA[name])
        Jw = np.einsum("tij,tj->ti", J, body.w)
        np.testing.assert_allclose(total[name][0], MASS[name] * ac, rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(total[name][1],
                                   np.einsum("tij,tj->ti", J, body.alpha) + np.cross(body.w, Jw),
                                   rtol=0, atol=1e-8 * scale)


@pytest.mark.parametrize("backend", BACKENDS)
def test_slider_crank_power_balance(backend: str) -> None:
    """Effort power (torque x 2π rad/s) + applied power = dT/dt, with
    dT/dt = Σ m v_c·a_c + ω·(J alpha) (the J-rate term vanishes: ωᵀ J̇ ω = 0)."""
    traj = _solved_slider_crank(backend)
    bodies = {name: Body(traj, name) for name in MASS}
    _, applied = _external(traj, bodies)
    rate = np.zeros(traj.t.size)
    for name, body in bodies.items():
        _, vc, ac = body.point(COM[name] - ORIGIN[name])
        J = body.inertia(INERTIA[name])
        rate += MASS[name] * np.einsum("ti,ti->t", vc, ac)
        rate += np.einsum("ti,tij,tj->t", body.w, J, body.alpha)
    effort_power = traj.effort[:, 0] * 2 * np.pi
    scale = np.abs(effort_power).max()
    np.testing.assert_allclose(effort_power + applied, rate, rtol=0, atol=1e-8 * scale)


# ----- the Stewart platform at rest: leg forces f = J^-T w --------------------------------------

def _stewart_at_rest() -> tuple[dict, np.ndarray, np.ndarray]:
    data = yaml.safe_load((EXAMPLES / "stewart.yaml").read_text())
    zp = 1.0
    base = np.array([data["bodies"]["ground"]["points"][f"B{k}"] for k in range(1, 7)], float)
    top = np.array([[float(v) if not isinstance(v, str) else zp for v in
                     data["bodies"]["platform"]["points"][f"P{k}"]] for k in range(1, 7)])
    lengths = np.linalg.norm(top - base, axis=1)
    for driver, length in zip(data["drivers"], lengths):
        driver["f"] = repr(float(length))
    data["bodies"]["platform"].update(mass=50, inertia=[2, 2, 3.5], com=[0.05, -0.02, "zp + 0.1"])
    data["forces"] = [{"type": "gravity", "g": G.tolist()}]
    data["time"] = {"t0": 0, "t1": 0.5, "dt": 0.25}
    return data, base, top


@pytest.mark.parametrize("backend", BACKENDS)
def test_stewart_platform_leg_forces_hold_its_weight(backend: str) -> None:
    """At rest: Σ f_k u_k = -m g and Σ (P_k - c) x f_k u_k = 0 with u_k the unit leg from
    B_k to P_k, i.e. Jᵀ f = w with J's rows [u_kᵀ, ((P_k - c) x u_k)ᵀ]."""
    data, base, top = _stewart_at_rest()
    traj = _solve(data, backend)
    u = (top - base) / np.linalg.norm(top - base, axis=1)[:, None]
    c = np.array([0.05, -0.02, 1.1])
    jacobian = np.hstack([u, np.cross(top - c, u)])
    weight = np.concatenate([-50 * G, np.zeros(3)])
    legs = np.linalg.solve(jacobian.T, weight)
    assert traj.effort.shape == (traj.t.size, 6)
    np.testing.assert_allclose(traj.q[:, 2], 1.0, atol=1e-12)  # it does not move
    for row in traj.effort:
        np.testing.assert_allclose(row, legs, rtol=0, atol=1e-9 * np.abs(legs).max())


# ----- outputs -----------------------------------------------------------------------------------

def test_backends_agree_and_the_csv_has_six_components(tmp_path: Path) -> None:
    runs = {backend: _solve(ROTOR, backend) for backend in BACKENDS}
    np.testing.assert_allclose(runs["c"].reaction, runs["numpy"].reaction, atol=1e-10)
    path = runs["c"].save(tmp_path / "rotor.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert header[-7:] == ["motor.effort", "shaft.Fx", "shaft.Fy", "shaft.Fz", "shaft.Mx",
                           "shaft.My", "shaft.Mz"]
    npz = np.load(runs["numpy"].save(tmp_path / "rotor.npz"))
    assert npz["reaction"].shape == (runs["numpy"].t.size, 1, 6)


@pytest.mark.parametrize("backend", BACKENDS)
def test_local_layout_inertia_and_com_are_in_the_body_frame(backend: str) -> None:
    """The rotor in the local layout, its frame turned by θ = ωt + π/2 about z: the centre
    and the tensor written in that frame (c' = Rᵀ c, J' = Rᵀ J R with R = Rz(π/2)) give the
    loads of the drawn rotor, whose frame is turned by ωt alone."""
    turn = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    drawn_inertia = np.array([[0.1, 0, 0.02], [0, 0.2, 0], [0.02, 0, 0.15]])
    data = {
        "name": "rotor_local", "space": "3d", "parameters": ROTOR["parameters"],
        "bodies": {"arm": {"q0": [0, 0, 0, float(np.cos(np.pi / 4)), 0, 0,
                                  float(np.sin(np.pi / 4))],
                           "mass": "m", "com": (turn.T @ [0.3, 0, 0.2]).tolist(),
                           "inertia": (turn.T @ drawn_inertia @ turn).tolist()}},
        "joints": [{"type": "revolute", "name": "shaft", "i": "ground", "j": "arm",
                    "sA": [0, 0, 0], "sB": [0, 0, 0], "axis": [0, 0, 1]}],
        "drivers": [{"type": "angle", "name": "motor", "i": "ground", "j": "arm",
                     "axis": [0, 0, 1], "theta": "w*t + pi/2"}],
        "forces": ROTOR["forces"], "time": ROTOR["time"],
    }
    local, drawn = _solve(data, backend), _solve(ROTOR, backend)
    np.testing.assert_allclose(local.reaction, drawn.reaction, rtol=0, atol=1e-9)
    np.testing.assert_allclose(local.effort, drawn.effort, rtol=0, atol=1e-9)


@pytest.mark.parametrize("backend", BACKENDS)
def test_input_legs_hold_the_platform(backend: str) -> None:
    """The forward-kinematics Stewart file (leg lengths are inputs) with a platform mass, the
    inputs held at the drawn lengths: the efforts are J^-T w again (an input's effort is
    conjugate to the input, as a formula's is)."""
    data = yaml.safe_load((EXAMPLES / "stewart_fk.yaml").read_text())
    base = np.array([data["bodies"]["ground"]["points"][f"B{k}"] for k in range(1, 7)], float)
    top = np.array([data["bodies"]["platform"]["points"][f"P{k}"] for k in range(1, 7)], float)
    data["bodies"]["platform"].update(mass=30, inertia=[1, 1, 1.5], com=[0.02, 0.03, 1.05])
    data["forces"] = [{"type": "gravity", "g": G.tolist()}]
    kernel = kernel_from(data, backend)
    t = np.linspace(0.0, 0.2, 3)
    lengths = np.tile(np.linalg.norm(top - base, axis=1), (t.size, 1))
    still = np.zeros_like(lengths)  # at rest: without rates dq and d2q are NaN
    traj = symkin.solve(kernel, t=t, inputs=lengths, input_rates=still, input_accels=still)
    u = (top - base) / lengths[0][:, None]
    jacobian = np.hstack([u, np.cross(top - np.array([0.02, 0.03, 1.05]), u)])
    legs = np.linalg.solve(jacobian.T, np.concatenate([-30 * G, np.zeros(3)]))
    for row in traj.effort:
        np.testing.assert_allclose(row, legs, rtol=0, atol=1e-9 * np.abs(legs).max())


def test_sweep_envelope_has_the_six_components() -> None:
    """A sweep over the rotor's speed: the bearing's radial force peaks at the largest ω,
    m ω² a (closed form), and the envelope names JOINT.Fx ... JOINT.Mz."""
    kernel = kernel_from(ROTOR, "c")
    speeds = np.array([1.0, 2.0, 4.0])
    result = symkin.sweep(kernel, {"w": speeds}, workers=1)
    _, reaction = result.forces
    assert reaction.shape == (3, result.t.size, 1, 6)
    radial = np.hypot(reaction[..., 0, 0], reaction[..., 0, 1])
    np.testing.assert_allclose(radial.max(axis=1), 2.0 * speeds**2 * 0.3, rtol=1e-9)
    names = [row[0] for row in result.force_envelope()]
    assert names == ["motor.effort"] + [f"shaft.{part}" for part in
                                        ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]


@pytest.mark.parametrize("backend", BACKENDS)
def test_cardan_torque_through_its_removed_rows(backend: str) -> None:
    """The Cardan shaft has three rows removed as redundant, so its bearing forces are not
    unique; the drive torque is. Massless shafts and a brake torque B on the output: by power,
    T1 = B ω2/ω1 = B cos β / (1 - sin²β cos²θ1) (tan θ2 = tan θ1 / cos β, differentiated)."""
    data = yaml.safe_load((EXAMPLES / "cardan.yaml").read_text(encoding="utf-8"))
    data["forces"] = [{"type": "torque", "name": "brake", "body": "shaft2",
                       "m": ["-3*cos(beta)", "-3*sin(beta)", 0]}]
    traj = _solve(data, backend)
    beta, theta = np.pi / 6, 2 * np.pi * traj.t
    torque = 3 * np.cos(beta) / (1 - np.sin(beta) ** 2 * np.cos(theta) ** 2)
    forces = traj.forces
    assert np.max(np.abs(forces.effort[:, 0] - torque)) < 1e-9
    assert forces.effort_determinate.all()
    assert forces.reaction.shape == (traj.t.size, 3, 6)
    # the cross's forces along the shafts are shared among the removed rows: min-norm, marked
    assert "cross.Fx" in forces.indeterminate()
