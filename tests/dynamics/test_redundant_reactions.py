"""Reactions where an equation was removed as redundant, against a reference written here.

The mechanism: examples/parallelogram_extra_bar_loads.yaml, a parallelogram four-bar with an
extra parallel bar (one equation removed as redundant), masses, gravity, and a lamp hung from
the coupler at P and swung by a second motor. Its motion is known in closed form: the three
bars turn together, theta = th0 + w t, the coupler translates (every point moves by
a u(theta)), the lamp turns by psi(t) = psi0 sin(pi t) relative to it.

By hand: the unknowns are the 7 pin forces (what body i exerts on body j) and the 2 motor
torques, 16 of them, for 5 bodies x 3 Newton-Euler equations: one more than the equations.
The null space is a self-stress of the three parallel bars: axial forces f_A, f_B, f_C along
u with f_A + f_B + f_C = 0 and d f_B + e f_C = 0 (moments on the coupler), none through the
lamp's hinge and no motor torque (an axial bar force has no moment about the bar's ground
pivot). So: both efforts, the lamp hinge's force and every revolute's M (zero) are
determinate; Fx and Fy of the six loop joints are not (u has both components). The minimum-
norm solution is numpy.linalg.lstsq of the hand-written 15 x 16 system (for revolutes the
multipliers are the pin forces, for the angle drivers minus the torques: the same norm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from codegen_support import compiled
from motion_support import kernel_from

import symkin
from symkin import cli

ROOT = Path(__file__).resolve().parents[2]
MECHANISM = ROOT / "examples" / "parallelogram_extra_bar_loads.yaml"
BACKENDS = ("c", "numpy")
P = dict(a=1.0, d=1.0, e=0.5, th0=np.pi / 3, w=np.pi / 2, l=0.4, psi=0.3, mb=1.0, mc=3.0,
         ml=2.0, Jc=0.25, Jl=0.02, g=-9.81)
JOINTS = {"O0": ("ground", "crank"), "O1": ("ground", "rocker"), "A": ("crank", "coupler"),
          "B": ("coupler", "rocker"), "O2": ("ground", "extra"), "C": ("extra", "coupler"),
          "P": ("coupler", "lamp")}
BODIES = ("crank", "rocker", "extra", "coupler", "lamp")
LOOP = ("O0", "O1", "A", "B", "O2", "C")


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _kinematics(t: float):
    """Joint points, and per body (mass, inertia, com, com acceleration, angular acc)."""
    a, d, e, w, arm = P["a"], P["d"], P["e"], P["w"], P["l"]
    theta = P["th0"] + w * t
    u = np.array([np.cos(theta), np.sin(theta)])
    psi = P["psi"] * np.sin(np.pi * t)
    dpsi = P["psi"] * np.pi * np.cos(np.pi * t)
    ddpsi = -P["psi"] * np.pi ** 2 * np.sin(np.pi * t)
    points = {"O0": np.zeros(2), "O1": np.array([d, 0.0]), "O2": np.array([e, 0.0])}
    points.update(A=a * u, B=points["O1"] + a * u, C=points["O2"] + a * u,
                  P=np.array([3 * d / 4, 0.0]) + a * u)
    translate = -a * w ** 2 * u  # every coupler point's acceleration
    hang = arm * np.array([np.sin(psi), -np.cos(psi)])
    hang_acc = (arm * ddpsi * np.array([np.cos(psi), np.sin(psi)])
                + arm * dpsi ** 2 * np.array([-np.sin(psi), np.cos(psi)]))
    bar_j = P["mb"] * a ** 2 / 12
    bodies = {
        "crank": (P["mb"], bar_j, points["O0"] + a * u / 2, translate / 2, 0.0),
        "rocker": (P["mb"], bar_j, points["O1"] + a * u / 2, translate / 2, 0.0),
        "extra": (P["mb"], bar_j, points["O2"] + a * u / 2, translate / 2, 0.0),
        "coupler": (P["mc"], P["Jc"], np.array([d / 2, 0.0]) + a * u, translate, 0.0),
        "lamp": (P["ml"], P["Jl"], points["P"] + hang, translate + hang_acc, ddpsi),
    }
    return points, bodies


def _hand_system(t: float):
    """Newton-Euler of the 5 bodies, A x = b, x = (Fx, Fy of each joint in JOINTS order,
    then the torques of drive (on crank) and swing (on lamp, minus on coupler))."""
    points, bodies = _kinematics(t)
    row = {name: 3 * k for k, name in enumerate(BODIES)}
    matrix = np.zeros((15, 16))
    rhs = np.zeros(15)
    for k, (name, (i, j)) in enumerate(JOINTS.items()):
        for body, sign in ((j, 1.0), (i, -1.0)):  # F on j, -F on i, at the joint's point
            if body == "ground":
                continue
            arm = points[name] - bodies[body][2]
            r = row[body]
            matrix[r, 2 * k] += sign
            matrix[r + 1, 2 * k + 1] += sign
            matrix[r + 2, 2 * k] += -sign * arm[1]
            matrix[r + 2, 2 * k + 1] += sign * arm[0]
    matrix[row["crank"] + 2, 14] = 1.0
    matrix[row["lamp"] + 2, 15] = 1.0
    matrix[row["coupler"] + 2, 15] = -1.0
    for body, (m, inertia, _, acc, alpha) in bodies.items():
        r = row[body]
        rhs[r:r + 2] = m * acc - m * np.array([0.0, P["g"]])
        rhs[r + 2] = inertia * alpha
    return matrix, rhs


def _symkin_unknowns(traj, k: int) -> np.ndarray:
    """symkin's solution at point k in the order of the hand-written unknowns."""
    names = traj.forces.joint_names
    forces = [traj.reaction[k, names.index(name), :2] for name in JOINTS]
    return np.concatenate([*forces, traj.effort[k]])


@pytest.fixture(scope="module", params=BACKENDS)
def traj(request):
    kernel = compiled(MECHANISM, request.param)  # from its goldens
    return symkin.solve(kernel)


def test_the_extra_bars_equation_is_the_one_removed(traj) -> None:
    assert traj.removed == ("joints[5] C revolute extra-coupler (y)",)
    assert traj.forces.joint_names == tuple(JOINTS)
    assert traj.forces.driver_names == ("drive", "swing")


def test_determinate_components_are_the_hand_derived_ones(traj) -> None:
    expected = np.zeros((7, 3), dtype=bool)
    expected[:, 2] = True  # a revolute carries no moment: 0 in every solution
    expected[list(JOINTS).index("P")] = True  # the lamp's hinge is outside the loop
    np.testing.assert_array_equal(traj.forces.reaction_determinate, expected)
    np.testing.assert_array_equal(traj.forces.effort_determinate, [True, True])
    assert traj.forces.indeterminate() == [f"{n}.{c}" for n in LOOP for c in ("Fx", "Fy")]


def test_minimum_norm_solution_is_lstsq_of_the_hand_written_system(traj) -> None:
    scale = max(np.abs(traj.reaction).max(), np.abs(traj.effort).max())
    for k, t in enumerate(traj.t):
        matrix, rhs = _hand_system(float(t))
        reference = np.linalg.lstsq(matrix, rhs, rcond=None)[0]
        ours = _symkin_unknowns(traj, k)
        # every body's Newton-Euler equations hold, and the solution is the minimum-norm one
        np.testing.assert_allclose(matrix @ ours, rhs, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(ours, reference, rtol=0, atol=1e-9 * scale)
    assert np.abs(traj.reaction[..., 2]).max() < 1e-9 * scale


def test_minimum_norm_is_orthogonal_to_the_self_stress(traj) -> None:
    """The hand-derived self-stress (bar forces f u with f_B = 1, f_C = -d/e, f_A = d/e - 1,
    signed as 'body i on body j') is a null vector of the hand system, and the reported
    solution has no component along it: adding any multiple of it makes the norm larger."""
    d, e = P["d"], P["e"]
    for k, t in enumerate(traj.t[::10]):
        theta = P["th0"] + P["w"] * t
        u = np.array([np.cos(theta), np.sin(theta)])
        f_a, f_b, f_c = d / e - 1, 1.0, -d / e
        # on each bar: ground pushes +f u at the ground pivot, the coupler -f u at the top
        stress = {"O0": f_a * u, "O1": f_b * u, "O2": f_c * u,
                  "A": f_a * u, "B": -f_b * u, "C": f_c * u, "P": np.zeros(2)}
        null = np.concatenate([*(stress[n] for n in JOINTS), [0.0, 0.0]])
        matrix, _ = _hand_system(float(t))
        np.testing.assert_allclose(matrix @ null, 0, atol=1e-12)
        ours = _symkin_unknowns(traj, 10 * k)
        assert abs(ours @ null) < 1e-9 * np.linalg.norm(ours) * np.linalg.norm(null)


def test_determinate_components_equal_closed_forms(traj) -> None:
    """The lamp hinge's force (coupler on lamp) is m_l (a_L - g); the swing motor's torque
    balances the lamp's moments about its centre of mass; the drive's torque follows from
    the power balance of the whole mechanism (motor power + gravity power = dT/dt)."""
    names = traj.forces.joint_names
    scale = max(np.abs(traj.reaction).max(), np.abs(traj.effort).max())
    for k, t in enumerate(traj.t):
        points, bodies = _kinematics(float(t))
        m, inertia, com, acc, alpha = bodies["lamp"]
        hinge = m * acc - m * np.array([0.0, P["g"]])
        swing = inertia * alpha - _cross(points["P"] - com, hinge)
        np.testing.assert_allclose(traj.reaction[k, names.index("P"), :2], hinge, rtol=0,
                                   atol=1e-9 * scale)
        np.testing.assert_allclose(traj.effort[k, 1], swing, rtol=0, atol=1e-9 * scale)


def test_drive_torque_by_the_power_balance(traj) -> None:
    """sum over bodies of m a_c . v_c + J alpha omega = drive * w + swing * dpsi + m g . v_c,
    with the velocities written out here (closed form)."""
    a, w, arm = P["a"], P["w"], P["l"]
    for k, t in enumerate(traj.t):
        theta = P["th0"] + w * t
        du = np.array([-np.sin(theta), np.cos(theta)]) * w
        psi = P["psi"] * np.sin(np.pi * t)
        dpsi = P["psi"] * np.pi * np.cos(np.pi * t)
        _, bodies = _kinematics(float(t))
        velocity = {"crank": a * du / 2, "rocker": a * du / 2, "extra": a * du / 2,
                    "coupler": a * du,
                    "lamp": a * du + arm * dpsi * np.array([np.cos(psi), np.sin(psi)])}
        omega = {"crank": w, "rocker": w, "extra": w, "coupler": 0.0, "lamp": dpsi}
        kinetic_rate = sum(m * acc @ velocity[b] + inertia * alpha * omega[b]
                           for b, (m, inertia, _, acc, alpha) in bodies.items())
        gravity = sum(m * P["g"] * velocity[b][1] for b, (m, *_) in bodies.items())
        drive = (kinetic_rate - gravity - traj.effort[k, 1] * dpsi) / w
        np.testing.assert_allclose(traj.effort[k, 0], drive, rtol=0,
                                   atol=1e-9 * np.abs(traj.effort).max())


def test_files_without_removed_rows_keep_their_outputs(tmp_path: Path) -> None:
    kernel = compiled(ROOT / "examples" / "crank_slider_load.yaml", "numpy")
    traj = symkin.solve(kernel)
    assert traj.forces.determinate is None and traj.forces.indeterminate() == []
    traj.save(tmp_path / "run.npz")
    with np.load(tmp_path / "run.npz") as data:
        assert "reaction_determinate" not in data and "effort_determinate" not in data


def test_cli_writes_the_flags_and_names_the_indeterminate_reactions(
        tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    out = tmp_path / "run.npz"
    assert cli.main(["run", str(MECHANISM), "--backend", "c", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "not unique" in err and "minimum-norm" in err
    assert "O0.Fx, O0.Fy, O1.Fx" in err and "P.Fx" not in err
    with np.load(out) as data:
        assert data["reaction_determinate"].shape == (7, 3)
        assert data["reaction_determinate"].dtype == bool
        np.testing.assert_array_equal(data["effort_determinate"], [True, True])
        assert data["reaction"].shape == (data["t"].size, 7, 3)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_repeated_joint_and_driver_share_the_load_equally(backend: str) -> None:
    """four_bar_dynamics with its rocker pivot and its motor written twice: every row of the
    copies is removed (a joint with no kept row still has its reaction). Any split of the
    load between a joint and its copy solves the equations; the minimum-norm one is half
    each, and the halves add up to the four-bar's own (checked by Newton-Euler elsewhere)."""
    data = yaml.safe_load((ROOT / "examples" / "four_bar_dynamics.yaml").read_text())
    data["joints"].append(dict(data["joints"][3], name="O4bis"))
    data["drivers"].append(dict(data["drivers"][0], name="drive2"))
    twice = symkin.solve(kernel_from(data, backend))
    once = symkin.solve(compiled(ROOT / "examples" / "four_bar_dynamics.yaml", backend))
    assert len(twice.removed) == 3
    scale = max(np.abs(once.reaction).max(), np.abs(once.effort).max())
    for k in (0, 1):
        np.testing.assert_allclose(twice.effort[:, k], once.effort[:, 0] / 2, rtol=0,
                                   atol=1e-9 * scale)
    for k in (3, 4):
        np.testing.assert_allclose(twice.reaction[:, k], once.reaction[:, 3] / 2, rtol=0,
                                   atol=1e-9 * scale)
    np.testing.assert_allclose(twice.reaction[:, :3], once.reaction[:, :3], rtol=0,
                               atol=1e-9 * scale)
    assert twice.forces.indeterminate() == ["crank_drive.effort", "drive2.effort", "O4.Fx",
                                            "O4.Fy", "O4bis.Fx", "O4bis.Fy"]


def test_a_sweep_reports_the_minimum_norm_reactions_too() -> None:
    """symkin.sweep over two lamp masses: each set's reactions are those symkin.solve gives
    that set (the minimum-norm ones), so its envelope is of the reported values."""
    kernel = compiled(MECHANISM, "numpy")
    result = symkin.sweep(kernel, {"ml": [2.0, 3.0]})
    effort, reaction = result.forces
    for j, mass in enumerate((2.0, 3.0)):
        p = kernel.p_values.copy()
        p[kernel.parameter_names.index("ml")] = mass
        alone = symkin.solve(kernel, params=p)
        scale = np.abs(alone.reaction).max()
        np.testing.assert_allclose(reaction[j], alone.reaction, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(effort[j], alone.effort, rtol=0, atol=1e-9 * scale)


class _StubKernel:
    """A kernel whose loads are its multipliers (loads_full(lam) = lam), with a random Phi_q
    and one removed row: the completion's algebra alone, against numpy.linalg.lstsq."""

    removed = ("extra",)

    def __init__(self, rng: np.random.Generator, singular_at: int) -> None:
        self.kept = rng.normal(size=(5, 4, 4))
        self.kept[singular_at, 3] = self.kept[singular_at, 0]  # two equal rows: singular
        self.extra = rng.normal(size=(5, 1, 4))

    def phi_q(self, q, t, p):
        return self.kept[int(t)]

    def removed_q(self, q, t, p):
        return self.extra[int(t)]

    def loads_full(self, q, lam, t, p):
        return np.asarray(lam, dtype=float)


def test_completion_is_lstsq_and_a_singular_row_stays_nan() -> None:
    """Rows with finite multipliers: the minimum-norm solution of [Phi_q; removed]^T lam =
    rhs, as lstsq finds it; the singular row (NaN multipliers) stays NaN."""
    from symkin.runtime.loads import indeterminate

    rng = np.random.default_rng(7)
    kernel = _StubKernel(rng, singular_at=2)
    t = np.arange(5.0)
    q = np.zeros((5, 4))
    rhs = rng.normal(size=(5, 4))
    lam = np.array([np.linalg.lstsq(kernel.kept[k].T, rhs[k], rcond=None)[0]
                    for k in range(5)])
    lam[2] = np.nan  # as the kernel's multipliers_grid leaves a singular row
    loads = np.column_stack([lam, np.zeros(5)])  # the kept rows' solution, removed lam 0
    found = indeterminate.complete(kernel, t, q, np.zeros(0), lam, loads)
    for k in (0, 1, 3, 4):
        full = np.vstack([kernel.kept[k], kernel.extra[k]])
        reference = np.linalg.lstsq(full.T, rhs[k], rcond=None)[0]
        np.testing.assert_allclose(found.loads[k], reference, rtol=0, atol=1e-12)
        np.testing.assert_allclose(np.concatenate([found.multipliers[k],
                                                   found.removed_multipliers[k]]),
                                   reference, rtol=0, atol=1e-12)
    assert np.isnan(found.loads[2]).all() and np.isnan(found.multipliers[2]).all()
    assert not found.determinate.any()  # a generic Phi_q: every multiplier can change


def test_an_exactly_singular_row_is_nan_and_the_others_still_complete() -> None:
    """A Phi_q with a zero row (exactly singular) in the batch: that row has no unique
    completion and stays NaN, the others are completed one by one."""
    from symkin.runtime.loads import indeterminate

    rng = np.random.default_rng(3)
    kernel = _StubKernel(rng, singular_at=1)
    kernel.kept[1, 3] = 0.0
    rhs = rng.normal(size=(5, 4))
    lam = rng.normal(size=(5, 4))  # finite everywhere: the batch meets the singular row
    for k in (0, 2, 3, 4):
        lam[k] = np.linalg.solve(kernel.kept[k].T, rhs[k])
    found = indeterminate.complete(kernel, np.arange(5.0), np.zeros((5, 4)), np.zeros(0),
                                   lam, np.column_stack([lam, np.zeros(5)]))
    for k in (0, 2, 3, 4):
        full = np.vstack([kernel.kept[k], kernel.extra[k]])
        reference = np.linalg.lstsq(full.T, rhs[k], rcond=None)[0]
        np.testing.assert_allclose(found.loads[k], reference, rtol=0, atol=1e-12)
    assert np.isnan(found.loads[1]).all()
