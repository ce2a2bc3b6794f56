"""Edges of forward dynamics found in review after the branches met: a gravity that varies
with time, --at, an NPZ named in capitals, a stop before the first row, an infinite load,
exact numbers in the equations of motion, and the Octave driver of an under-driven file."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from motion_support import PENDULUM, write

import symkin
from symkin import cli


@pytest.fixture
def pendulum(tmp_path: Path) -> Path:
    return write(tmp_path, "pendulum.yaml", PENDULUM.replace("PHI0", "0.4"))


def test_a_gravity_that_varies_with_time_is_accepted(tmp_path: Path) -> None:
    # g(t) = 9.81 (1 + 0.1 sin t): the forces section allows t in a load's expressions
    varying = PENDULUM.replace("PHI0", "0.4").replace("g: [0, -g]", 'g: [0, "-g*(1 + 0.1*sin(t))"]')
    mech = symkin.load(write(tmp_path, "pendulum_g.yaml", varying))
    trajectory = symkin.solve(symkin.compile(symkin.derive(mech), backend="numpy"))
    assert trajectory.t.size == 11 and np.isfinite(trajectory.q).all()


def test_at_is_refused_for_a_mechanism_its_forces_move(
        pendulum: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["run", str(pendulum), "--backend", "numpy", "--at", "0.3"]) == \
        cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "--at solves one configuration" in err and "Traceback" not in err


def test_an_npz_named_in_capitals_holds_the_run(pendulum: Path, tmp_path: Path) -> None:
    out = tmp_path / "OUT.NPZ"
    assert cli.main(["run", str(pendulum), "--backend", "numpy", "-o", str(out)]) == 0
    with np.load(out) as found:
        assert found["q"].shape == (11, 3) and "kinetic_energy" in found.files
    assert sorted(p.name for p in tmp_path.iterdir()) == ["OUT.NPZ", "pendulum.yaml"]


def test_a_stop_before_the_first_row_is_a_message(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # no mass at all on the rod's rotation (inertia 0, com at the pivot): its freedom has no
    # kinetic energy, so the motion cannot start
    massless = PENDULUM.replace("PHI0", "0.4").replace("com: [L, 0]", "com: [0, 0]") \
        + "initial: {velocities: {rod.phi: 1.0}}\n"
    path = write(tmp_path, "massless.yaml", massless)
    status = cli.main(["run", str(path), "--backend", "numpy"])
    err = capsys.readouterr().err
    assert status in (cli.EXIT_BAD_INPUT, 1) and "Traceback" not in err, err


def test_an_infinite_load_flags_its_row(tmp_path: Path) -> None:
    # a torque 1/(t - 0.5) on the rod: infinite at t = 0.5, a grid point
    text = PENDULUM.replace("PHI0", "0.4").replace(
        "  - {type: gravity, g: [0, -g]}\n",
        "  - {type: gravity, g: [0, -g]}\n  - {type: torque, body: rod, m: \"1/(t - 0.5)\"}\n")
    text = text.replace("time: {t0: 0, t1: 1, dt: 0.1}", "time: {t0: 0.5, t1: 0.6, dt: 0.05}")
    mech = symkin.load(write(tmp_path, "torque.yaml", text))
    kernel = symkin.compile(symkin.derive(mech), backend="numpy")
    try:
        trajectory = symkin.solve(kernel)
    except symkin.SolveError as stop:  # the motion may not get past an infinite torque
        assert "Traceback" not in str(stop)
        return
    bad = ~np.isfinite(trajectory.forces.table()).all(axis=1)
    assert bad.any() and trajectory.flagged[bad].all()


def test_an_exact_long_decimal_reaches_numpy_as_a_double(tmp_path: Path) -> None:
    # L written with 20 digits is an exact rational; the lambdified equations must not
    # hand NumPy a Python int (sqrt of a wide integer)
    text = PENDULUM.replace("PHI0", "0.4").replace("L: 1.3", "L: 1.30000000000000000001")
    text = text.replace("mass: m,", "mass: sqrt(123456789012345678901234567)/11111111111111,")
    mech = symkin.load(write(tmp_path, "long.yaml", text))
    trajectory = symkin.solve(symkin.compile(symkin.derive(mech), backend="numpy"))
    assert np.isfinite(trajectory.q).all()


def test_the_octave_driver_of_an_under_driven_file_says_why(pendulum: Path,
                                                            tmp_path: Path) -> None:
    files = symkin.generate(symkin.derive(pendulum), backend="octave", out_dir=tmp_path / "m")
    solve = next(Path(f) for f in files if str(f).endswith("_solve.m"))
    text = solve.read_text(encoding="utf-8")
    assert re.search(r"error\('pendulum_solve:underDriven'", text)


def test_a_tiny_number_in_a_massive_body_derives_and_a_subnormal_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # found by the fuzz campaign: a point at 1e-200 (an exact 1/10**200) kept SymPy's
    # simplify busy for minutes in the mass matrix; 5e-324 (subnormal) is refused at its line
    tiny = PENDULUM.replace("PHI0", "0.4").replace("tip: [L, 0]", "tip: [L, 1.0e-200]") \
        .replace("com: [L, 0]", "com: [L, 1.0e-200]")
    mech = symkin.load(write(tmp_path, "tiny.yaml", tiny))
    trajectory = symkin.solve(symkin.compile(symkin.derive(mech), backend="numpy"))
    assert np.isfinite(trajectory.q).all()
    path = write(tmp_path, "subnormal.yaml", tiny.replace("1.0e-200", "5.0e-324"))
    assert cli.main(["show", str(path)]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "subnormal.yaml:4:" in err and "below the smallest normal double" in err
