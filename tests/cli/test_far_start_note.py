"""A start assembled far from q0 gets a note naming the bodies (a slide given by its direction
where the local layout asks for its normal), and the usual starts get none.

The reference is the loop closure worked out by hand: the textbook crank-slider (a = 1, b = 5,
c = 4) with q0 at its textbook start, but the guide's v = [1, 0] (the direction) instead of
[0, 1] (the normal). The slider then runs on the vertical line x = 0 through sB = (0, c), and
the rod from the crank tip (0, 1) reaches it at (0, 1 + b) = (0, 6), standing upright: the
slider moved from (4, 4) by sqrt(4^2 + 2^2), the rod turned from atan(3/4) to pi/2.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, symkin_main
from driver_support import kernel_of

import symkin
from symkin.runtime.solving.start import FAR, far_from_guess

ROOT = Path(__file__).resolve().parents[2]

GUIDE_BY_DIRECTION = """
name: guide_by_direction
parameters: {a: 1.0, b: 5.0, c: 4.0}
bodies:
  crank:  {q0: [0, 0, 1.5707963267948966], points: {tip: [a, 0]}}
  rod:    {q0: [0, 1, 0.6435011087932844], points: {P: [b, 0]}}
  slider: {q0: [4, 4, 0]}
joints:
  - {type: revolute,  i: ground, j: crank,  sA: [0, 0], sB: [0, 0]}
  - {type: revolute,  i: crank,  j: rod,    sA: tip,    sB: [0, 0]}
  - {type: revolute,  i: rod,    j: slider, sA: [b, 0], sB: [0, 0]}
  - {type: prismatic, i: slider, j: ground, sA: [0, 0], sB: [0, c], v: [V], phi0: 0}
drivers:
  - {type: angle, i: crank, j: ground, theta: "t**2 + pi/2"}
time: {t0: 0, t1: 0.5, dt: 0.05}
"""


def _run(path: Path, backend: str = "numpy") -> Ran:
    return symkin_main("run", str(path), "--backend", backend, cwd=ROOT)


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_the_far_bodies_and_how_far_match_the_loop_closure(backend):
    kernel = kernel_of(GUIDE_BY_DIRECTION.replace("V", "1, 0"), backend)  # one derivation
    trajectory = symkin.solve(kernel)
    moved, scale = far_from_guess(kernel, np.asarray(kernel.q0, dtype=float), trajectory.q[0],
                                  0.0, trajectory.params)
    assert [m.body for m in moved] == ["rod", "slider"]
    rod, slider = moved
    assert slider.distance == pytest.approx(math.hypot(4, 2), abs=1e-9)
    assert rod.turn == pytest.approx(math.pi / 2 - math.atan(3 / 4), abs=1e-9)
    assert scale == pytest.approx(5.0)  # the rod's length, the longest lever arm
    assert rod.distance < FAR * scale and slider.turn == 0.0


def test_cli_notes_it_and_still_exits_0(tmp_path):
    path = tmp_path / "guide.yaml"
    path.write_text(GUIDE_BY_DIRECTION.replace("V", "1, 0"))
    done = _run(path)
    assert done.returncode == 0, done.stderr
    assert "the assembled start is far from q0" in done.stderr
    assert "rod (moved" in done.stderr and "slider (moved 4.47" in done.stderr
    assert "`v` is the slide's normal" in done.stderr


@pytest.mark.parametrize("mechanism", ["examples/crank_slider.yaml", "examples/four_bar.yaml",
                                       "examples/quick_return.yaml"])
def test_no_note_for_a_good_guess_or_the_chapters_start_from_zero(mechanism):
    done = _run(ROOT / mechanism)
    assert done.returncode == 0, done.stderr
    assert "far from q0" not in done.stderr


def test_no_note_with_the_normal(tmp_path):
    path = tmp_path / "guide.yaml"
    path.write_text(GUIDE_BY_DIRECTION.replace("V", "0, 1"))
    done = _run(path)
    assert done.returncode == 0 and "far from q0" not in done.stderr
