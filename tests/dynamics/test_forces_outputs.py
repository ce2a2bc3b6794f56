"""The contracts of inverse dynamics: the generated C entry points (one step with the
solver's own factors, and the whole grid), the NPZ arrays and CSV columns, the CLI, the
drawn layout's centre of mass, and files without masses or forces left as they were."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from codegen_support import compiled, derived
from motion_support import kernel_from

import symkin
from symkin import cli

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def test_c_multipliers_per_step_use_the_solvers_factors() -> None:
    """<prefix>_solve_step then <prefix>_multipliers (one transposed solve with the factors
    the step left) give the multipliers of the grid solve, step by step, in compiled C."""
    kernel = compiled(EXAMPLES / "four_bar_dynamics.yaml", "c")
    traj = symkin.solve(kernel)
    ffi, lib, name, n = kernel.ffi, kernel.lib, kernel.name, kernel.nq
    options = ffi.new(f"{name}_options *")
    getattr(lib, f"{name}_default_options")(options)
    state, work = ffi.new(f"{name}_state *"), ffi.new(f"{name}_workspace *")
    report = ffi.new(f"{name}_report *")
    p = ffi.new(f"{name}_real[]", list(kernel.p_values))
    lam = ffi.new(f"{name}_real[]", n)
    state.q[0:n] = list(kernel.q0)
    state.started = 0
    scale = np.abs(traj.forces.multipliers).max()
    for k, t in enumerate(traj.t):
        assert getattr(lib, f"{name}_solve_step")(options, p, t, state, work, report) == 0
        getattr(lib, f"{name}_multipliers")(p, state, work, lam)
        np.testing.assert_allclose(np.array(ffi.unpack(lam, n)), traj.forces.multipliers[k],
                                   rtol=0, atol=1e-10 * scale)


def test_backends_agree_and_names_follow_the_file() -> None:
    c, numpy = (symkin.solve(compiled(EXAMPLES / "four_bar_dynamics.yaml", b))
                for b in ("c", "numpy"))
    scale = np.abs(c.reaction).max()
    np.testing.assert_allclose(c.reaction, numpy.reaction, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(c.effort, numpy.effort, rtol=0, atol=1e-10 * scale)
    assert c.forces.driver_names == ("crank_drive",)
    assert c.forces.joint_names == ("O2", "A", "B", "O4")
    assert c.effort.shape == (c.t.size, 1) and c.reaction.shape == (c.t.size, 4, 3)


def test_npz_and_csv_carry_efforts_and_reactions(tmp_path: Path) -> None:
    traj = symkin.solve(compiled(EXAMPLES / "crank_slider_load.yaml", "numpy"))
    data = np.load(traj.save(tmp_path / "run.npz"))
    assert list(data["driver_names"]) == ["motor"]
    assert list(data["joint_names"]) == ["O", "A", "B", "slide"]
    assert data["effort"].shape == (traj.t.size, 1)
    np.testing.assert_array_equal(data["reaction"], traj.reaction)
    with open(traj.save(tmp_path / "run.csv"), newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert float(rows[3]["motor.effort"]) == traj.effort[3, 0]
    assert float(rows[3]["slide.Fy"]) == traj.reaction[3, 3, 1]
    assert float(rows[3]["A.M"]) == traj.reaction[3, 1, 2]


def test_cli_run_writes_the_columns(tmp_path: Path) -> None:
    out = tmp_path / "run.csv"
    assert cli.main(["run", str(EXAMPLES / "four_bar_dynamics.yaml"), "-o", str(out)]) == 0
    header = out.read_text().splitlines()[0].split(",")
    for column in ("crank_drive.effort", "O2.Fx", "O2.Fy", "O2.M", "O4.M"):
        assert column in header


def test_file_without_masses_has_no_forces(tmp_path: Path) -> None:
    traj = symkin.solve(compiled(EXAMPLES / "four_bar.yaml", "numpy"))
    assert traj.forces is None and traj.effort is None
    assert "effort" not in np.load(traj.save(tmp_path / "run.npz")).files


PENDULUM_LOCAL = {
    "name": "pendulum", "parameters": {"L": 2.0, "m": 3.0},
    "bodies": {"arm": {"q0": [0, 0, 0.3], "points": {"tip": ["L", 0]}, "mass": "m",
                       "inertia": 0.5, "com": ["L/2", 0.1]}},
    "joints": [{"type": "revolute", "name": "pivot", "i": "ground", "j": "arm",
                "sA": [0, 0], "sB": [0, 0]}],
    "drivers": [{"type": "angle", "name": "motor", "i": "arm", "j": "ground",
                 "theta": "0.3 + 2*t"}],
    "forces": [{"type": "gravity", "g": [0, -9.81]},
               {"type": "force", "name": "tip_load", "body": "arm", "at": "tip",
                "f": [0, "-5*arm.phi_t"]}],
    "time": {"t0": 0, "t1": 1, "dt": 0.1},
}


def test_pendulum_closed_form() -> None:
    """One body about a fixed pivot: T = (J + m|c|^2) alpha - moment of gravity and the load."""
    traj = symkin.solve(kernel_from(PENDULUM_LOCAL, "numpy"))
    phi = 0.3 + 2 * traj.t
    c = np.array([1.0, 0.1])
    com_x = np.cos(phi) * c[0] - np.sin(phi) * c[1]
    gravity_moment = com_x * 3.0 * -9.81
    load_moment = 2.0 * np.cos(phi) * (-5 * 2.0)
    torque = -(gravity_moment + load_moment)  # alpha = 0
    np.testing.assert_allclose(traj.effort[:, 0], torque, rtol=1e-12, atol=1e-12)


def test_drawn_layout_com_is_global_as_drawn() -> None:
    """The same pendulum drawn at phi = 0.3: com and the load's point given globally."""
    c, s = np.cos(0.3), np.sin(0.3)
    drawn = {**PENDULUM_LOCAL, "layout": "drawn",
             "bodies": {"arm": {"points": {"O": [0, 0], "tip": [2 * c, 2 * s]},
                                "frame": {"origin": "O", "angle": 0.3}, "mass": "m",
                                "inertia": 0.5,
                                "com": [1.0 * c - 0.1 * s, 1.0 * s + 0.1 * c]}},
             "joints": [{"type": "revolute", "name": "pivot", "i": "ground", "j": "arm",
                         "at": "O"}]}
    local = symkin.solve(kernel_from(PENDULUM_LOCAL, "numpy"))
    from_drawing = symkin.solve(kernel_from(drawn, "numpy"))
    np.testing.assert_allclose(from_drawing.effort, local.effort, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(from_drawing.reaction, local.reaction, rtol=1e-12, atol=1e-9)


def test_sweep_envelope_of_efforts_and_reactions(tmp_path: Path, capsys) -> None:
    """The sweep's envelope is the min/max over the sets that symkin.solve gives set by set
    (the peak motor torque over a study), printed by the CLI and saved in its NPZ."""
    path = EXAMPLES / "crank_slider_load.yaml"
    kernel = compiled(path, "c")
    loads = [100.0, 150.0, 200.0]
    result = symkin.sweep(kernel, {"F0": loads}, workers=1)
    efforts = [symkin.solve(kernel, params={"F0": f}).effort[:, 0] for f in loads]
    envelope = {name: (low, high) for name, low, high, _, _ in result.force_envelope()}
    np.testing.assert_allclose(envelope["motor.effort"], (min(e.min() for e in efforts),
                                                          max(e.max() for e in efforts)),
                               rtol=1e-12)
    out = tmp_path / "sweep.npz"
    assert cli.main(["sweep", str(path), "--vary", "F0=100:200:3", "--workers", "1",
                     "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"motor.effort: min {envelope['motor.effort'][0]:.6g}" in printed
    saved = np.load(out)
    assert saved["effort"].shape == (3, saved["t"].size, 1)
    assert list(saved["joint_names"]) == ["O", "A", "B", "slide"]
    np.testing.assert_allclose(saved["effort"][1, :, 0], efforts[1], rtol=1e-12)


def test_cli_plot_writes_the_forces_figure(tmp_path: Path) -> None:
    plot = tmp_path / "run.png"
    assert cli.main(["run", str(EXAMPLES / "crank_slider_load.yaml"), "--plot", str(plot)]) == 0
    assert plot.stat().st_size > 0
    assert (tmp_path / "run_forces.png").stat().st_size > 0
    kinematic = tmp_path / "kinematics" / "run.png"
    assert cli.main(["run", str(EXAMPLES / "four_bar.yaml"), "--plot", str(kinematic)]) == 0
    assert sorted(p.name for p in kinematic.parent.iterdir()) == ["run.png"]


def test_float_and_dense_c_builds_agree() -> None:
    """The float build (its own tolerances) and the dense-LU build give the same efforts."""
    path = EXAMPLES / "four_bar_dynamics.yaml"
    reference = symkin.solve(compiled(path, "c")).effort
    scale = np.abs(reference).max()
    dense = symkin.solve(compiled(path, "c", linalg="dense")).effort
    single = symkin.solve(compiled(path, "c", real="float")).effort
    np.testing.assert_allclose(dense, reference, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(single, reference, rtol=0, atol=1e-4 * scale)


def test_a_point_named_E_and_a_static_spring() -> None:
    """A point named E (the constant's name is free for points) as a spring's end; the arm
    held still by its motor: the effort is the spring's moment, k (L - L0) times its lever."""
    data = {**PENDULUM_LOCAL,
            "bodies": {"arm": {"q0": [0, 0, 0], "points": {"E": [2, 0]}}},
            "drivers": [{"type": "angle", "name": "hold", "i": "arm", "j": "ground",
                         "theta": 0}],
            "forces": [{"type": "spring", "name": "s", "i": "arm", "A": "E", "j": "ground",
                        "B": [2, 3], "k": 10, "length0": 1, "damping": 4}]}
    for backend in ("c", "numpy"):
        traj = symkin.solve(kernel_from(data, backend))
        # tension 10 (3 - 1) = 20 pulls E = (2, 0) up towards (2, 3): moment 2 * 20 = 40 CCW,
        # so the motor holds with -40; the pivot takes the force: ground -> arm (0, -20)
        np.testing.assert_allclose(traj.effort[:, 0], -40.0, rtol=1e-13)
        np.testing.assert_allclose(traj.reaction[:, 0, :2], [[0.0, -20.0]] * traj.t.size,
                                   atol=1e-12)


def test_reaction_arrows_start_at_the_joints_points(tmp_path: Path) -> None:
    """The mechanism view draws each joint's reaction at its point on body i: the outlines
    place joint A of the four-bar at the crank's point A, joint B at the coupler's B."""
    from symkin.present.animation import joint_points
    from symkin.symbolic.drawing import outlines

    system = derived(EXAMPLES / "four_bar_dynamics.yaml")
    traj = symkin.solve(compiled(EXAMPLES / "four_bar_dynamics.yaml", "numpy"))
    where = joint_points(traj, outlines(system))
    assert sorted(where) == sorted(traj.forces.joint_names)
    np.testing.assert_allclose(where["A"], traj.point("crank", "A")[0], atol=1e-12)
    np.testing.assert_allclose(where["B"], traj.point("coupler", "B")[0], atol=1e-12)
    np.testing.assert_allclose(where["O2"], 0.0, atol=1e-12)
    assert not any(key.startswith("joint:") for key in
                   outlines(derived(EXAMPLES / "four_bar.yaml")))
    report = tmp_path / "report.html"
    assert cli.main(["run", str(EXAMPLES / "four_bar_dynamics.yaml"), "--html",
                     str(report)]) == 0
    assert "joint reactions (i on j)" in report.read_text()
