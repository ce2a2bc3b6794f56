"""symkin run and symkin.solve of a mechanism its forces move: the summary, the energy
columns, located refusals, Ctrl-C with the rows kept (the backends' kernels:
test_motion_backends)."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from codegen_support import compiled
from motion_support import PENDULUM, write

import symkin
from symkin import cli
from symkin.runtime.solving.run_outcome import SolveInterrupted


@pytest.fixture
def pendulum(tmp_path: Path) -> Path:
    return write(tmp_path, "pendulum.yaml", PENDULUM.replace("PHI0", "0.4"))


def test_run_says_dynamics_and_writes_the_energy_columns(
        pendulum: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out.csv"
    assert cli.main(["run", str(pendulum), "--backend", "numpy", "-o", str(out)]) == 0
    summary = capsys.readouterr().out
    assert "solved 11 time points, t = 0 to 1 (dynamics)" in summary
    with out.open(encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    kinetic = np.array([float(row["energy.kinetic"]) for row in rows])
    potential = np.array([float(row["energy.potential"]) for row in rows])
    work = np.array([float(row["energy.work"]) for row in rows])
    assert kinetic[0] == 0.0 and kinetic[-1] > 1.0  # released from rest, falling
    assert np.ptp(kinetic + potential - work) <= 1e-8 * np.abs(potential).max()


def test_run_writes_the_npz_arrays(pendulum: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.npz"
    assert cli.main(["run", str(pendulum), "--backend", "numpy", "-o", str(out)]) == 0
    with np.load(out) as found:
        for name in ("kinetic_energy", "potential_energy", "work_nonconservative",
                     "constraint_residual", "effort", "reaction"):
            assert name in found.files
        assert found["constraint_residual"].max() <= 1e-10
        # released from rest at 0.4 rad: the bob accelerates along the tangent only,
        # φ'' = -g cos φ / L, so the pivot's force is m a - m g (Newton, by hand)
        weight, phi = 2.0 * 9.81, 0.4
        expected = [weight * np.cos(phi) * np.sin(phi), weight - weight * np.cos(phi) ** 2]
        assert found["reaction"][0, 0, :2] == pytest.approx(expected, abs=1e-9)


def test_contradicting_initial_velocities_are_refused_at_their_line(
        pendulum: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the pivot holds the rod's origin: its x rate must be 0
    pendulum.write_text(pendulum.read_text(encoding="utf-8")
                        + "initial: {velocities: {rod.phi: 1.0, rod.x: 0.5}}\n",
                        encoding="utf-8")
    assert cli.main(["run", str(pendulum), "--backend", "numpy"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{pendulum}:11: at initial.velocities.rod.x: the initial velocities rod.x " \
           "contradict the constraints" in err
    assert "Traceback" not in err


def test_ctrl_c_keeps_the_rows_solved(crank_slider: Any) -> None:
    def interrupt(done: int, total: int) -> None:
        if done == 5:
            raise KeyboardInterrupt

    with pytest.raises(SolveInterrupted) as caught:
        symkin.solve(crank_slider, progress=interrupt)
    assert caught.value.trajectory.t.size == 5
    assert dict(caught.value.trajectory.outputs)["kinetic_energy"].shape == (5,)


def test_generate_writes_the_dynamics_step(pendulum: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert cli.main(["generate", str(pendulum), "--backend", "c", "-o", str(out)]) == 0
    headers = list(out.glob("*_dynamics.h"))
    assert len(headers) == 1 and "_dynamics_step(" in headers[0].read_text()


@pytest.mark.parametrize(("command", "status", "fragment"), [
    (["scan"], 2, "symkin scan works on a mechanism whose drivers fix its motion"),
    (["sweep", "--vary", "L=1:2:3", "-o", "OUT.npz"], 2, "symkin sweep works on a mechanism"),
])
def test_commands_for_driven_kinematics_say_so(
        pendulum: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
        command: list[str], status: int, fragment: str) -> None:
    words = [word.replace("OUT", str(tmp_path / "out")) for word in command]
    assert cli.main([words[0], str(pendulum), *words[1:]]) == status
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err


def test_the_html_report_has_the_energy_column(pendulum: Path, tmp_path: Path) -> None:
    pytest.importorskip("plotly")
    page = tmp_path / "report.html"
    assert cli.main(["run", str(pendulum), "--backend", "numpy", "--html", str(page)]) == 0
    text = page.read_text(encoding="utf-8")
    for name in ("kinetic T", "potential V", "work W", "T + V - W"):
        assert f'"name":"{name}"' in text


def test_a_driven_run_s_report_has_no_energy_column(tmp_path: Path) -> None:
    """The report of a driven example's run, from its committed NumPy kernel (the command's
    --html writes the same report: test_the_html_report_has_the_energy_column)."""
    pytest.importorskip("plotly")
    from symkin.present import html

    example = Path(__file__).parents[2] / "examples" / "four_bar_dynamics.yaml"
    trajectory = symkin.solve(compiled(example, "numpy"))
    assert trajectory.forces is not None  # its inverse dynamics ran: a driven run with masses
    page = html.report(trajectory, tmp_path / "report.html", {})
    text = page.read_text(encoding="utf-8")
    assert '"name":"T + V - W"' not in text and '"name":"kinetic T"' not in text


def test_a_free_freedom_without_mass_stops_with_a_message(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    massless = write(tmp_path, "massless.yaml", PENDULUM.replace("PHI0", "0.4").replace(
        "parameters: {L: 1.3, m: 2.0", "parameters: {L: 1.3, m: 0.0"))
    assert cli.main(["run", str(massless), "--backend", "numpy"]) == cli.EXIT_FAILED
    err = capsys.readouterr().err
    assert "the kinetic energy does not decide the freedoms" in err
    assert "Traceback" not in err and err.count("\n") <= 2


def test_a_stiff_spring_stops_at_the_work_bound_with_the_rows_kept(
        crank_slider_c: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """A spring of 1e9 N/m on the free crank-slider: the explicit integrator needs steps of
    about 1e-5 s. It ran for minutes with no word before the bound (integrator.
    MAX_STEPS_PER_ROW); now it stops at the first row the bound cannot reach, saying why and
    what to do, with the rows before it kept. (The bound lowered tenfold here, to keep the
    test short: the full one stops the same run after some 7 s of CPU.)"""
    from symkin.runtime.dynamics import integrator

    monkeypatch.setattr(integrator, "MAX_STEPS_PER_ROW", integrator.MAX_STEPS_PER_ROW // 10)
    with pytest.raises(symkin.SolveError) as stop:
        symkin.solve(crank_slider_c, params={"k": 1e9})
    message = str(stop.value)
    assert "2000 steps did not reach the next output time" in message and "--dt" in message
    assert "stiff" in message and len(message) < 400
    assert stop.value.reason == "too many substeps"  # type: ignore[attr-defined]
    trajectory = stop.value.trajectory  # type: ignore[attr-defined]
    assert trajectory.t.size >= 1 and np.isfinite(trajectory.q).all()
