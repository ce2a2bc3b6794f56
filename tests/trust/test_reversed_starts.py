"""No path runs from a solution of Phi = 0 that is no assembly: an input-driven run, a sweep's
batch and a forward-dynamics run refuse such a start (reason "no assembly"), as the time loop
and scan do (runtime.solving.assembly.reversed_senses).

References, derived here, on the RSSR of the examples (crank about z at A0 = 0 with A =
(a, 0, 0), rocker about x at B0 with B = B0 + R (0, c, 0), a rod from A to B):
- the crank turned half a turn, e = (0, 0, 0, 1), puts A at (-a, 0, 0): the rod's length
  L^2 = 0.48 then needs sin psi = -0.625 for the rocker (tests/trust/test_scan_counts.py);
  the angle driver's row holds there (the driver's angle is 0), its sense is -1;
- the rocker turned half a turn about y, e = (0, 0, 1, 0), maps (0, c, 0) to itself: B and
  every row stay as drawn, but the rocker's axis is now -x, the revolute's sense is -1.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.runtime.driver import SolveFailure

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
RSSR = (EXAMPLES / "rssr.yaml").read_text(encoding="utf-8")


def _block(kernel, body: str) -> list[int]:
    return [list(kernel.coordinates).index(f"{body}.e{k}") for k in range(4)]


def _crank_turned_by_pi(kernel) -> np.ndarray:
    q0 = np.array(kernel.q0, dtype=float)
    q0[_block(kernel, "crank")] = [0.0, 0.0, 0.0, 1.0]
    psi = math.asin(-0.625)
    q0[_block(kernel, "rocker")] = [math.cos(psi / 2), math.sin(psi / 2), 0.0, 0.0]
    return q0


def _refused(caught: pytest.ExceptionInfo[SolveFailure], label: str) -> None:
    assert caught.value.reason == "no assembly"
    assert caught.value.rows == (label,)
    assert caught.value.trajectory.t.size == 0


@pytest.fixture(scope="module")
def rssr_input(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("inputs") / "rssr_input.yaml"
    path.write_text(RSSR.replace('theta: "2*pi*t"', "theta: input"), encoding="utf-8")
    return path


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_an_input_run_from_the_crank_half_a_turn_away_is_refused(rssr_input, backend) -> None:
    kernel = compiled(rssr_input, backend)  # one derivation for both backends
    q0 = _crank_turned_by_pi(kernel)
    assert np.abs(kernel.phi(q0, 0.0, np.r_[kernel.p_values, 0.0, 0.0, 0.0])).max() < 1e-12
    t = np.linspace(0.0, 0.1, 6)
    with pytest.raises(SolveFailure, match="half a turn") as caught:
        symkin.solve(kernel, t=t, q0=q0, inputs={kernel.input_names[0]: 2 * np.pi * t})
    _refused(caught, "drivers[0] angle ground-crank (sense)")
    # from the file's q0 the same inputs run
    assert symkin.solve(kernel, t=t, inputs={kernel.input_names[0]: 2 * np.pi * t}
                        ).t.size == 6


def test_a_sweep_reports_a_set_started_half_a_turn_away_as_no_assembly() -> None:
    kernel = compiled(EXAMPLES / "rssr.yaml", "c")
    assert kernel.batch_solver is not None  # the C batch solves the sets, not symkin.solve
    q0 = _crank_turned_by_pi(kernel)
    params = np.array([kernel.p_values, kernel.p_values])
    starts = np.array([kernel.q0, q0], dtype=float)
    result = symkin.sweep(kernel, params, np.linspace(0.0, 0.1, 6), workers=1, q0=starts)
    assert list(result.reasons) == ["", "no assembly"]
    assert result.status[1] != 0 and result.solved[1] == 0
    assert "half a turn" in result.messages[1]


ROCKER_MASSES = RSSR.replace(
    "  crank: {points:", "  crank: {mass: 1.0, inertia: [0.01, 0.01, 0.01], points:").replace(
    "  rocker: {points:", "  rocker: {mass: 1.0, inertia: [0.02, 0.02, 0.02], "
    "com: [0, 0.2, 0], points:").replace(
    "drivers:\n  - {type: angle, joint: crank_pivot, theta: \"2*pi*t\"}\n",
    "forces:\n  - {type: gravity, g: [0, 0, -9.81]}\n")


def test_a_motion_from_the_rocker_turned_half_a_turn_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "rssr_falling.yaml"
    path.write_text(ROCKER_MASSES, encoding="utf-8")
    kernel = symkin.compile(symkin.derive(path), backend="numpy")
    q0 = np.array(kernel.q0, dtype=float)
    q0[_block(kernel, "rocker")] = [0.0, 0.0, 1.0, 0.0]
    assert np.abs(kernel.model.phi(q0, 0.0, kernel.p_values)).max() < 1e-12
    t = np.linspace(0.0, 0.05, 3)
    with pytest.raises(SolveFailure, match="reversed") as caught:
        symkin.solve(kernel, t=t, q0=q0)
    _refused(caught, "joints[1] rocker_pivot revolute ground-rocker (sense)")
    assert symkin.solve(kernel, t=t).t.size == 3  # from the file's q0 it moves
