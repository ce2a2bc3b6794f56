"""The senses (a spatial revolute's axis cosine, an angle driver's cos(theta - psi)) are
checked along the motion, not only at the start: Phi = 0 also holds with the crank half a
turn away, and a step too large for Newton to follow can land there with nothing else to
show for it. Here a crank's angle jumps by 3 rad between two grid points (a Heaviside step):
Newton from the last row converges to theta - pi, the nearer root of the driver's row. That
row and the ones after it are flagged, with a warning that names the time and the driver."""

from __future__ import annotations

import math
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin import cli
from symkin.errors import SymkinWarning

CRANK = """\
name: flip
space: 3d
layout: drawn
bodies:
  ground: {points: {O: [0, 0, 0]}}
  crank: {points: {O: [0, 0, 0], A: [0, 1, 0]}}
joints:
  - {type: revolute, name: bearing, i: ground, j: crank, at: O, axis: [1, 0, 0]}
drivers:
  - {type: angle, name: turn, joint: bearing, theta: "THETA"}
time: {t0: 0, t1: 1, dt: 0.25}
"""
STEP = "3*Heaviside(t - 0.6)"  # 0 up to t = 0.5, 3 from t = 0.75: one step of 3 rad
FILE_NAMES = {STEP: "jumping", "3*t": "turning"}
BACKENDS = ["numpy", pytest.param("c", marks=pytest.mark.skipif(
    shutil.which("gcc") is None, reason="gcc is not installed"))]


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("senses")


def _kernel(folder: Path, theta: str, backend: str):
    """The crank driven by theta, written once per theta (its derivation and sources shared by
    the backends and the CLI test: codegen_support.compiled)."""
    path = folder / f"crank_{FILE_NAMES[theta]}.yaml"
    if not path.exists():
        path.write_text(CRANK.replace("THETA", theta), encoding="utf-8")
    return path, compiled(path, backend)


def _angle(trajectory) -> np.ndarray:
    """The crank's turn about x from its Euler parameters: 2 atan2(e1, e0)."""
    names = list(trajectory.coordinates)
    e0, e1 = (trajectory.q[:, names.index(f"crank.{n}")] for n in ("e0", "e1"))
    return 2 * np.arctan2(e1, e0)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_jump_to_the_crank_half_a_turn_away_is_flagged_at_its_time(folder, backend):
    _, kernel = _kernel(folder, STEP, backend)
    with pytest.warns(SymkinWarning, match=(
            r"the motion left the mechanism's assembly at row 3 \(t = 0.75\): drivers\[0\] "
            r"turn angle ground-crank \(sense\) reversed .*2 row\(s\) in all, flagged")):
        trajectory = symkin.solve(kernel)
    # what Newton found: theta - pi, a solution of Phi = 0 that is not the crank at theta
    assert _angle(trajectory)[3] == pytest.approx(3.0 - math.pi, abs=1e-9)
    assert trajectory.flagged.tolist() == [False, False, False, True, True]


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_motion_newton_follows_is_not_flagged(folder, backend):
    _, kernel = _kernel(folder, "3*t", backend)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SymkinWarning)
        trajectory = symkin.solve(kernel)
    np.testing.assert_allclose(_angle(trajectory), 3 * trajectory.t, rtol=0, atol=1e-9)
    assert not trajectory.flagged.any()


def test_the_cli_says_where_and_flags_the_rows(folder, tmp_path, capsys):
    path, _ = _kernel(folder, STEP, "numpy")
    out = tmp_path / "rows.csv"
    assert cli.main(["run", str(path), "--backend", "numpy", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "the motion left the mechanism's assembly at row 3 (t = 0.75)" in err, err
    header = out.read_text().splitlines()[0].split(",")
    flagged = np.loadtxt(out, delimiter=",", skiprows=1)[:, header.index("flagged")]
    assert flagged.tolist() == [0, 0, 0, 1, 1]
