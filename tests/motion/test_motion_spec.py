"""The file's forward-dynamics keys: an under-driven file with masses is accepted, one without
masses, bad initial velocities and bad tolerances are refused at their line (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest

from symkin import cli
from symkin.spec.validate import load

PENDULUM = """\
name: pendulum
parameters: {L: 1.0, m: 2.0, g: 9.81}
bodies:
  rod: {q0: [0, 0, 0], MASSES points: {tip: [L, 0]}}
joints:
  - {type: revolute, i: ground, j: rod, sA: [0, 0], sB: [0, 0]}
forces:
  - {type: gravity, g: [0, -g]}
time: {t0: 0, t1: 1, dt: 0.1}
"""
WITH_MASS = PENDULUM.replace("MASSES", "mass: m, inertia: 0.1, com: [L, 0],")


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "mech.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _refusal(tmp_path: Path, text: str, capsys: pytest.CaptureFixture[str]) -> str:
    path = _write(tmp_path, text)
    assert cli.main(["show", str(path)]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.startswith(f"symkin: error: {path}:")
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def test_an_under_driven_file_with_masses_is_accepted(tmp_path: Path) -> None:
    mech = load(_write(tmp_path, WITH_MASS + "initial: {velocities: {rod.phi: 1.5}}\n"
                       "integrator: {rtol: 1e-9, atol: 1e-12}\n"))
    assert mech.initial is not None and mech.initial.velocities == {"rod.phi": 1.5}
    assert mech.integrator is not None and mech.integrator.rtol == 1e-9


def test_the_keys_left_out_keep_the_hash(tmp_path: Path) -> None:
    # a file without the new keys hashes as before they existed
    plain = load(_write(tmp_path, WITH_MASS))
    assert '"initial"' not in plain.canonical_json()
    assert '"integrator"' not in plain.canonical_json()


def test_a_free_mechanism_without_masses_is_refused(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    err = _refusal(tmp_path, PENDULUM.replace("MASSES", ""), capsys)
    assert "no body has a mass" in err and "needs masses" in err
    assert ":1: at drivers:" in err


@pytest.mark.parametrize(("extra", "line", "fragment"), [
    ("initial: {velocities: {rod.psi: 1.0}}\n", 10,
     "'rod.psi' is not a velocity of this mechanism"),
    ("initial: {velocities: {rod.phi: t}}\n", 10, "is not a finite constant"),
    ("initial: {velocities: {rod.phi: sqrt(-1)}}\n", 10, "is not a finite constant"),
    ("integrator: {rtol: -1e-8}\n", 10, "rtol = -1e-08 is not a positive number"),
    ("integrator: {atol: 0}\n", 10, "atol = 0.0 is not a positive number"),
    ("integrator: {rtol: 2}\n", 10, "is not below 1"),
])
def test_bad_forward_dynamics_keys_are_refused_at_their_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: str, line: int,
        fragment: str) -> None:
    err = _refusal(tmp_path, WITH_MASS + extra, capsys)
    assert f":{line}: at " in err
    assert fragment in err


def test_initial_velocities_of_a_driven_file_are_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    driven = WITH_MASS.replace("forces:", "drivers:\n  - {type: angle, i: rod, j: ground, "
                               "theta: t}\nforces:")
    err = _refusal(tmp_path, driven + "initial: {velocities: {rod.phi: 1.0}}\n", capsys)
    assert "drivers fix every freedom" in err
