"""Redundant constraints: the parallelogram with an extra parallel bar and a lamp hung from
its coupler (examples/parallelogram_extra_bar_loads.yaml) without its motors, falling under
gravity. One row of Φ_q depends on the others all along; the motion is unique, the bars'
axial split is not. Reference: Lagrange's equations in the bars' angle θ and the lamp's
angle ψ alone (the coupler translates on a circle of radius a), derived here."""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import sympy as sp
from motion_support import kernel as built
from motion_support import shared, write
from scipy.integrate import solve_ivp

import symkin
from symkin import cli

EXAMPLE = Path(__file__).parents[2] / "examples" / "parallelogram_extra_bar_loads.yaml"


def _falling(text: str) -> str:
    """The example without its drivers."""
    lines = text.splitlines()
    return "\n".join(line for line in lines
                     if not line.startswith("drivers:")
                     and not line.lstrip().startswith("- {type: angle")) + "\n"


@functools.cache
def _reference() -> Any:
    """(θ, ψ, θ', ψ') -> (θ'', ψ'') of the example's numbers, by Lagrange's equations
    (derived once for the tests here)."""
    th, ps, dth, dps = sp.symbols("theta psi dtheta dpsi")
    g, a, arm, mb, mc, ml, jl = 9.81, 1.0, 0.4, 1.0, 3.0, 2.0, 0.02
    pin = a * sp.Matrix([sp.cos(th), sp.sin(th)])  # P moves with the coupler
    lamp = pin + arm * sp.Matrix([sp.sin(ps), -sp.cos(ps)])  # its centre hangs l below P
    rate = lamp.diff(th) * dth + lamp.diff(ps) * dps
    kinetic = (3 * mb * a ** 2 / 3 + mc * a ** 2) * dth ** 2 / 2 \
        + ml * (rate.T * rate)[0] / 2 + jl * dps ** 2 / 2
    potential = g * ((3 * mb * a / 2 + mc * a) * sp.sin(th) + ml * lamp[1])
    q, dq = [th, ps], [dth, dps]
    mass = sp.hessian(kinetic, dq)
    force = sp.Matrix([-sum((mass[i, j].diff(q[k]) - mass[j, k].diff(q[i]) / 2) * dq[j] * dq[k]
                            for j in range(2) for k in range(2)) - potential.diff(q[i])
                       for i in range(2)])
    return sp.lambdify((th, ps, dth, dps), mass.LUsolve(force))


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_a_parallelogram_with_an_extra_bar_falls_as_by_hand(tmp_path: Path,
                                                            backend: str) -> None:
    text = _falling(EXAMPLE.read_text(encoding="utf-8"))
    kernel = built(shared("falling.yaml", text), backend)
    trajectory = symkin.solve(kernel, t=np.linspace(0, 1, 11))
    accel = _reference()
    reference = solve_ivp(lambda t, y: [y[2], y[3], *np.ravel(accel(*y))], (0, 1),
                          [math.pi / 3, 0.0, 0.0, 0.0], method="DOP853", rtol=1e-12,
                          atol=1e-12, t_eval=trajectory.t)
    crank = trajectory.coordinates.index("crank.phi")
    lamp = trajectory.coordinates.index("lamp.phi")
    assert trajectory.q[:, crank] + math.pi / 3 == pytest.approx(reference.y[0], abs=1e-7)
    assert trajectory.q[:, lamp] == pytest.approx(reference.y[1], abs=1e-7)
    # the bars line up with the ground once (θ = 0), a change point: the row after it is
    # flagged, the only one (tests/motion/test_dynamics_singular.py)
    crossed = int(np.argmax(reference.y[0] < 0))
    assert crossed > 0 and np.flatnonzero(trajectory.flagged).tolist() == [crossed]
    assert len(trajectory.singular) == 1
    assert reference.t[crossed - 1] < trajectory.singular[0][0] < reference.t[crossed]
    # the lamp's hinge carries a determinate load, the three bars' bearings do not
    determinate = trajectory.forces.reaction_determinate
    names = trajectory.forces.joint_names
    assert determinate[names.index("P")].all()
    assert not determinate[names.index("O0")].all()
    # the file keeps the default tolerances (rtol 1e-8): the balance within 1e-6 of the
    # largest energy, the criterion
    out = dict(trajectory.outputs)
    total = out["kinetic_energy"] + out["potential_energy"] - out["work_nonconservative"]
    assert np.ptp(total) <= 1e-6 * np.abs(out["potential_energy"]).max()


def test_its_initial_velocities_and_tolerances_are_the_motions(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The rows left after the dependent one is removed decide whether the forces move it,
    for the ``initial`` and ``integrator`` keys as for the run: without its motors, thrown at
    θ' = 0.8 with the lamp at rest, it moves as Lagrange's equations say; with its motors the
    same keys are refused at their line."""
    keys = ("initial: {velocities: {crank.phi: 0.8, lamp.phi: 0.0}}\n"
            "integrator: {rtol: 1e-11, atol: 1e-12}\n")
    example = EXAMPLE.read_text(encoding="utf-8")
    kernel = built(shared("thrown.yaml", _falling(example) + keys), "numpy")
    trajectory = symkin.solve(kernel, t=np.linspace(0, 0.5, 6))
    accel = _reference()
    reference = solve_ivp(lambda t, y: [y[2], y[3], *np.ravel(accel(*y))], (0, 0.5),
                          [math.pi / 3, 0.0, 0.8, 0.0], method="DOP853", rtol=1e-12,
                          atol=1e-12, t_eval=trajectory.t)
    crank = trajectory.coordinates.index("crank.phi")
    lamp = trajectory.coordinates.index("lamp.phi")
    assert trajectory.dq[0, crank] == pytest.approx(0.8, abs=1e-12)
    assert trajectory.q[:, crank] + math.pi / 3 == pytest.approx(reference.y[0], abs=1e-8)
    assert trajectory.q[:, lamp] == pytest.approx(reference.y[1], abs=1e-8)
    driven = write(tmp_path, "driven.yaml", example + keys)
    assert cli.main(["show", str(driven)]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.startswith(f"symkin: error: {driven}:{example.count(chr(10)) + 1}: ")
    assert err.count("\n") == 1
    assert "'initial' applies to a mechanism that moves under its forces" in err


TWICE = """\
name: twice_hinged
parameters: {L: 1.0, m: 1.0}
bodies:
  bar: {q0: [0.5, 0, 0], mass: m, inertia: m*L**2/12}
joints:
  - {type: revolute, name: O, i: ground, j: bar, sA: [0, 0], sB: [-L/2, 0]}
  - {type: revolute, name: O_again, i: ground, j: bar, sA: [0, 0], sB: [-L/2, 0]}
forces:
  - {type: gravity, g: [0, -9.81]}
time: {t0: 0, t1: 1, dt: 0.05}
"""


def test_an_over_constrained_file_with_masses_and_a_free_motion_moves(tmp_path: Path) -> None:
    """The hinge written twice and no driver: 4 rows on 3 coordinates, rank 2 at t0 and
    nearby. Without masses that freedom is refused (tests/symbolic/test_redundancy.py); with
    them the forces move it: the repeated rows are removed and the bar swings as a pendulum,
    J_O theta'' = -m g (L/2) cos(theta) with J_O = m L^2/3, released horizontal."""
    system = symkin.derive(write(tmp_path, "twice.yaml", TWICE))
    assert len(system.removed) == 2
    trajectory = symkin.solve(symkin.compile(system, backend="numpy"))
    reference = solve_ivp(lambda t, y: [y[1], -9.81 / 2 * math.cos(y[0]) * 3], (0, 1),
                          [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12,
                          t_eval=trajectory.t)
    assert trajectory.q[:, 2] == pytest.approx(reference.y[0], abs=1e-7)
