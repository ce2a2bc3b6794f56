"""The 3D report of a run its forces move (runtime.dynamics) has the planar report's energy
column (present.html_energy) beside the scene and the efforts: kinetic and potential energy,
the work W and the balance T + V - W, each curve the run's own NPZ array, with a time cursor
that follows the slider. The run is a spherical pendulum: a bob on a ball joint under
gravity, set turning about the vertical; with no other force its T + V stays what it was at
t0, T0 = m |w x r|^2 / 2 + I |w|^2 / 2 and V0 = m g z, worked out here by hand."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.present.test_view3d import _cli, _figure, _numbers

M, G, I = 2.0, 9.81, 0.01
R = np.array([0.6, 0.0, -0.8])  # the bob's centre from the pivot
W = np.array([0.0, 0.0, 2.0])  # its angular velocity at t0
PENDULUM = f"""\
name: spherical_pendulum
space: 3d
layout: drawn
parameters: {{m: {M}, g: {G}}}
bodies:
  ground: {{points: {{O: [0, 0, 0]}}}}
  bob: {{mass: m, inertia: [{I}, {I}, {I}], com: B,
        points: {{O: [0, 0, 0], B: [{R[0]}, {R[1]}, {R[2]}]}}}}
joints:
  - {{type: spherical, name: pivot, i: ground, j: bob, at: O}}
forces:
  - {{type: gravity, g: [0, 0, -g]}}
initial: {{velocities: {{bob.omega_x: 0, bob.omega_y: 0, bob.omega_z: {W[2]}}}}}
time: {{t0: 0, t1: 1, dt: 0.05}}
"""
CURVES = {"kinetic T": "kinetic_energy", "potential V": "potential_energy",
          "work W": "work_nonconservative"}


@pytest.fixture(scope="module")
def pendulum_run(tmp_path_factory) -> tuple[Path, Path]:
    pytest.importorskip("plotly")
    folder = tmp_path_factory.mktemp("spherical_pendulum")
    (folder / "pendulum.yaml").write_text(PENDULUM, encoding="utf-8")
    result = _cli("pendulum.yaml", "--backend", "numpy", "-o", "p.npz", "--html", "p.html",
                  cwd=folder)
    assert result.returncode == 0, result.stderr
    return folder / "p.npz", folder / "p.html"


def test_the_energy_column_shows_the_runs_energies(pendulum_run) -> None:
    npz, page = pendulum_run
    saved = np.load(npz)
    data, _, layout = _figure(page)
    by_name = {trace.get("name"): trace for trace in data}
    for name, array in CURVES.items():
        np.testing.assert_array_equal(_numbers(by_name[name]["y"]), saved[array])
    kinetic, potential = saved["kinetic_energy"], saved["potential_energy"]
    balance = _numbers(by_name["T + V - W"]["y"])
    np.testing.assert_allclose(balance, kinetic + potential - saved["work_nonconservative"],
                               rtol=0, atol=1e-12)
    # the hand reference: T0, V0 and T + V kept along the motion (no other force works)
    t0 = 0.5 * M * np.sum(np.cross(W, R) ** 2) + 0.5 * I * W @ W
    assert kinetic[0] == pytest.approx(t0, rel=1e-12) and t0 == pytest.approx(1.46)
    assert potential[0] == pytest.approx(M * G * R[2], rel=1e-12)
    assert np.abs(balance - (t0 + M * G * R[2])).max() < 1e-6
    assert np.ptp(kinetic) > 0.1  # the bob swings: the check is not of a resting run
    # its own column of three panels, titled as the planar report's, under the time axis
    axes = {layout[f"yaxis{by_name[name]['yaxis'][1:]}"]["title"]["text"]
            for name in ("kinetic T", "work W", "T + V - W")}
    assert axes == {"energy", "work W", "T + V - W"}
    columns = {by_name[name]["xaxis"] for name in ("kinetic T", "work W", "T + V - W")}
    assert not columns & {by_name["pivot"]["xaxis"]}  # not the reactions' column


def test_the_energy_cursors_follow_the_slider(pendulum_run) -> None:
    npz, page = pendulum_run
    t = np.load(npz)["t"]
    data, frames, _ = _figure(page)
    energy_axes = {data[k]["xaxis"] for k, trace in enumerate(data)
                   if trace.get("name") in {*CURVES, "T + V - W"}}
    cursors = [k for k, trace in enumerate(data)
               if trace.get("name") is None and trace.get("xaxis") in energy_axes]
    assert len(cursors) == 3  # one per panel
    assert len(frames) == t.size
    for k, frame in enumerate(frames):
        for index in cursors:
            shown = frame["data"][frame["traces"].index(index)]
            np.testing.assert_array_equal(_numbers(shown["x"]), [t[k], t[k]])
