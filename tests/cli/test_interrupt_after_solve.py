"""Ctrl-C after every row is solved but before the run hands them on (its efforts and
reactions, the removed rows' check, a motion's forces) still writes the rows solved and exits
130 saying what was cut short, as an interrupt within the loop does: never a bare
"interrupted" with no file. The interrupt is injected where that work runs."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin import cli
from symkin.runtime.dynamics import run as motion_run
from symkin.runtime.loads import forces
from symkin.runtime.outputs import redundant
from symkin.runtime.solving.run_outcome import SolveInterrupted

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
GRID = ["--t0", "0", "--t1", "0.5", "--dt", "0.05"]  # 11 rows
ROWS = 11
BACKENDS = ["numpy", pytest.param("c", marks=pytest.mark.skipif(
    shutil.which("gcc") is None, reason="gcc is not installed"))]

PENDULUM = """\
name: pendulum
parameters: {L: 1.3, m: 2.0, g: 9.81}
bodies:
  rod: {q0: [0, 0, -1.0], mass: m, inertia: 0, com: [L, 0], points: {tip: [L, 0]}}
joints:
  - {type: revolute, name: pivot, i: ground, j: rod, sA: [0, 0], sB: [0, 0]}
forces:
  - {type: gravity, g: [0, -g]}
time: {t0: 0, t1: 1, dt: 0.1}
"""


def _interrupt(*args: object, **kwargs: object) -> None:
    raise KeyboardInterrupt


def _run(mechanism: Path, out: Path, *extra: str) -> int:
    return cli.main(["run", str(mechanism), *GRID, "-o", str(out), *extra])


def _rows(path: Path) -> np.ndarray:
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


@pytest.mark.parametrize("backend", BACKENDS)
def test_ctrl_c_while_the_efforts_are_computed_writes_every_row(tmp_path, capsys,
                                                                 monkeypatch, backend):
    monkeypatch.setattr(forces, "compute", _interrupt)
    out = tmp_path / "rows.csv"
    status = _run(EXAMPLES / "crank_slider_load.yaml", out, "--backend", backend)
    err = capsys.readouterr().err
    assert status == cli.EXIT_INTERRUPTED, err
    assert "interrupted while the efforts and reactions were computed, after the solve. " \
           f"Solved {ROWS} of {ROWS} time points." in err, err
    assert f"the solved rows are written to {out}" in err
    rows = _rows(out)
    assert rows.shape[0] == ROWS and np.isfinite(rows).all()
    np.testing.assert_allclose(rows[:, 0], np.linspace(0, 0.5, ROWS), rtol=0, atol=1e-15)


def test_ctrl_c_while_the_removed_rows_are_checked_writes_every_row(tmp_path, capsys,
                                                                    monkeypatch):
    monkeypatch.setattr(redundant, "residuals", _interrupt)
    out = tmp_path / "rows.csv"
    status = _run(EXAMPLES / "parallelogram_extra_bar.yaml", out, "--backend", "numpy")
    err = capsys.readouterr().err
    assert status == cli.EXIT_INTERRUPTED, err
    assert "interrupted while the solved rows were checked" in err, err
    assert _rows(out).shape[0] == ROWS


def test_ctrl_c_while_a_motions_forces_are_computed_writes_every_row(tmp_path, capsys,
                                                                     monkeypatch):
    pendulum = tmp_path / "pendulum.yaml"
    pendulum.write_text(PENDULUM, encoding="utf-8")
    monkeypatch.setattr(motion_run, "_forces", _interrupt)
    out = tmp_path / "rows.csv"
    status = _run(pendulum, out, "--backend", "numpy")
    err = capsys.readouterr().err
    assert status == cli.EXIT_INTERRUPTED, err
    assert "interrupted while the efforts and reactions were computed" in err, err
    header = out.read_text().splitlines()[0].split(",")
    rows = _rows(out)
    assert rows.shape[0] == ROWS and "energy.kinetic" in header
    # the rows are the motion's: the pendulum's energy is kept to the integrator's tolerance
    energy = rows[:, header.index("energy.kinetic")] + rows[:, header.index(
        "energy.potential")]
    assert np.ptp(energy) < 1e-6 * np.abs(energy).max()


def test_the_api_hands_on_the_rows_without_the_efforts(monkeypatch):
    kernel = compiled(EXAMPLES / "crank_slider_load.yaml", "numpy")  # one derivation a run
    monkeypatch.setattr(forces, "compute", _interrupt)
    t = np.linspace(0, 0.5, ROWS)
    with pytest.raises(SolveInterrupted) as caught:
        symkin.solve(kernel, t=t)
    stop = caught.value
    assert stop.trajectory.t.size == ROWS and stop.trajectory.forces is None
    assert stop.t == 0.5 and stop.during == "the efforts and reactions were computed"
