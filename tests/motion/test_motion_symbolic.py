"""The equations of motion's energies: V's gradient by finite differences is minus the
conservative forces, and only dampers and other forces count as non-conservative."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from codegen_support import derived

import symkin
from symkin.symbolic import motion, motion_numeric

SPRUNG = """\
name: sprung
parameters: {L: 1.0, m: 2.0, g: 9.81, k: 30.0, c: 0.7}
bodies:
  rod: {q0: [0, 0, 0], mass: m, inertia: 0.1, com: [0.6, 0.1], points: {tip: [L, 0]}}
joints:
  - {type: revolute, i: ground, j: rod, sA: [0, 0], sB: [0, 0]}
forces:
  - {type: gravity, g: [0, -g]}
  - {type: spring, i: ground, A: [0.5, 1.5], j: rod, B: tip, k: k, length0: 0.4, damping: DAMP}
time: {t0: 0, t1: 1, dt: 0.1}
"""


def _functions(tmp_path: Path, damping: str) -> motion_numeric.Functions:
    path = tmp_path / "sprung.yaml"
    path.write_text(SPRUNG.replace("DAMP", damping), encoding="utf-8")
    return motion_numeric.numeric(symkin.derive(path))


def test_the_potential_is_what_the_conservative_forces_derive_from(tmp_path: Path) -> None:
    f = _functions(tmp_path, "0")
    q = np.array([0.0, 0.0, 0.7])
    dq = np.array([0.0, 0.0, 1.3])
    p = f.p_values
    # Q (without h: at dq = 0 the velocity terms vanish) against -dV/dq, central differences
    h = 1e-6
    gradient = [(f.potential(q + h * e, 0.0, p) - f.potential(q - h * e, 0.0, p)) / (2 * h)
                for e in np.eye(3)]
    assert f.applied(q, 0 * dq, 0.0, p) == pytest.approx(-np.array(gradient), abs=1e-7)
    assert f.nonconservative(q, dq, 0.0, p) == pytest.approx(np.zeros(3), abs=1e-12)


def test_a_damper_is_non_conservative(tmp_path: Path) -> None:
    f = _functions(tmp_path, "c")
    q = np.array([0.0, 0.0, 0.7])
    dq = np.array([0.0, 0.0, 1.3])
    p = f.p_values
    # the damper's power -c L'^2 with L' by finite differences of the spring's length
    tip = lambda phi: np.array([np.cos(phi), np.sin(phi)]) - [0.5, 1.5]  # noqa: E731
    length = lambda phi: np.linalg.norm(tip(phi))  # noqa: E731
    rate = (length(0.7 + 1e-6) - length(0.7 - 1e-6)) / 2e-6 * 1.3
    power = f.nonconservative(q, dq, 0.0, p) @ dq
    assert power == pytest.approx(-0.7 * rate ** 2, rel=1e-8)


def test_a_driven_file_has_no_equations_of_motion() -> None:
    system = derived(Path(__file__).parents[2] / "examples" / "four_bar_dynamics.yaml")
    assert motion.derive(system) is None
