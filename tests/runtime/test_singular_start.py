"""A mechanism assembled at a singular or limit configuration is reported before any step, the
same on both backends, naming the joints and drivers involved.

The references are closed forms derived here: the drawings below are placed exactly at a limit
(a four-bar whose coupler and rocker are collinear, |O4 A| = b + c by the law of cosines; a
slider-crank at its outer dead centre, x = a + b; a slotted lever whose slot was drawn through
the pin along the normal, so the slot line touches the pin's circle), and a regular start
right beside each is solved as before.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cli_support import symkin_main
from driver_support import BACKENDS, kernel_of, mechanism_file

import symkin
from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.runtime.solving import start

ROOT = Path(__file__).resolve().parents[2]

# Non-Grashof four-bar a = b = c = 2, d = 3 drawn with the input at angle theta, B where the
# coupler's and the rocker's circles meet (above the line A-O4). At the limit,
# cos(theta*) = (a^2 + d^2 - (b + c)^2) / (2 a d) = -1/4, B is the midpoint of A-O4.
FOUR_BAR = """
name: four_bar_limit
layout: drawn
parameters: {{d: 3.0, w: {w}}}
bodies:
  ground:  {{points: {{O2: [0, 0], O4: [d, 0]}}}}
  crank:   {{points: {{O2: [0, 0], A: [{ax}, {ay}]}}}}
  coupler: {{points: {{A: [{ax}, {ay}], B: [{bx}, {by}]}}}}
  rocker:  {{points: {{O4: [d, 0], B: [{bx}, {by}]}}}}
joints:
  - {{type: revolute, name: O2, i: ground,  j: crank,   at: O2}}
  - {{type: revolute, name: A,  i: crank,   j: coupler, at: A}}
  - {{type: revolute, name: B,  i: coupler, j: rocker,  at: B}}
  - {{type: revolute, name: O4, i: rocker,  j: ground,  at: O4}}
drivers:
  - {{type: angle, name: input, i: crank, j: ground, theta: "w*t"}}
time: {{t0: 0, t1: 0.5, dt: 0.05}}
"""

# Slider-crank a = 1, b = 3 driven by the slider's position from x = x0 (a + b: the dead
# centre, crank and rod collinear along the slide).
SLIDER_CRANK = """
name: slider_crank_limit
parameters: {{a: 1.0, b: 3.0, x0: {x0}}}
bodies:
  crank:  {{q0: [0, 0, {phi}]}}
  rod:    {{q0: [{ax}, {ay}, {rod}]}}
  slider: {{q0: [{x0}, 0, 0]}}
joints:
  - {{type: revolute,  name: O,     i: ground, j: crank,  sA: [0, 0], sB: [0, 0]}}
  - {{type: revolute,  name: A,     i: crank,  j: rod,    sA: [a, 0], sB: [0, 0]}}
  - {{type: revolute,  name: B,     i: rod,    j: slider, sA: [b, 0], sB: [0, 0]}}
  - {{type: prismatic, name: guide, i: slider, j: ground, sA: [0, 0], sB: [0, 0], v: [0, 1]}}
drivers:
  - {{type: slide, name: push, i: ground, j: slider, sA: [0, 0], sB: [0, 0], u: [1, 0],
      f: "x0 - t"}}
time: {{t0: 0, t1: 0.5, dt: 0.05}}
"""

# A slotted lever (quick-return core) whose slot was drawn along the normal of O4-A: the slot
# line then touches the circle of radius |O4 A| about O4 at A, a limit of the lever at t0.
PIN_SLOT = """
name: slot_as_normal
layout: drawn
parameters: {r: 1.0, h: 2.0, w: 2*pi}
bodies:
  ground: {points: {O2: [0, h], O4: [0, 0]}}
  crank:  {points: {O2: [0, h], A: [r, h]}}
  lever:  {points: {O4: [0, 0], A: [r, h]}}
joints:
  - {type: revolute, name: O2,   i: ground, j: crank, at: O2}
  - {type: revolute, name: O4,   i: ground, j: lever, at: O4}
  - {type: pin_slot, name: slot, i: crank,  j: lever, at: A, axis: [AXIS]}
drivers:
  - {type: angle, name: crank_drive, i: crank, j: ground, theta: "w*t"}
time: {t0: 0, t1: 1, dt: 0.01}
"""


def _kernel(tmp_path: Path, text: str, backend: str):
    """The kernel of a drawing and its file: one derivation for both backends."""
    return kernel_of(text, backend), mechanism_file(text)


def _four_bar(theta: float, w: float) -> str:
    """The four-bar drawn at input angle theta (b = c = 2: B on the perpendicular bisector of
    A-O4, at height sqrt(4 - (|A O4| / 2)^2) from its midpoint; 0 at the limit)."""
    a = np.array([2 * math.cos(theta), 2 * math.sin(theta)])
    o4 = np.array([3.0, 0.0])
    half = np.linalg.norm(o4 - a) / 2
    height = math.sqrt(max(4 - half * half, 0.0))
    normal = np.array([-(o4 - a)[1], (o4 - a)[0]]) / (2 * half)
    b = (a + o4) / 2 + height * normal
    ax, ay, bx, by = (repr(float(v)) for v in (*a, *b))
    return FOUR_BAR.format(w=w, ax=ax, ay=ay, bx=bx, by=by)


def _slider_crank(x0: float) -> str:
    """The slider-crank assembled exactly (a closed form) at slider position x0."""
    a, b = 1.0, 3.0
    phi = math.acos((a * a + x0 * x0 - b * b) / (2 * a * x0))  # law of cosines, crank up
    ax, ay = a * math.cos(phi), a * math.sin(phi)
    return SLIDER_CRANK.format(x0=repr(x0), phi=repr(phi), ax=repr(ax), ay=repr(ay),
                               rod=repr(math.atan2(-ay, x0 - ax)))


def _failure(kernel) -> driver.SolveFailure:
    with pytest.raises(SolveError) as caught:
        symkin.solve(kernel)
    assert isinstance(caught.value, driver.SolveFailure), caught.value
    return caught.value


LIMIT_THETA = math.acos(-0.25)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("w", [1.0, -1.0])  # beyond the limit (no motion) and back into range
def test_four_bar_drawn_at_its_limit_is_reported_before_any_step(tmp_path, backend, w):
    kernel, _ = _kernel(tmp_path, _four_bar(LIMIT_THETA, w), backend)
    failure = _failure(kernel)
    assert failure.reason == "singular" and failure.t == 0.0
    assert failure.trajectory.t.size == 1  # only the assembled start, nothing stepped
    assert "at t = 0 in a singular or limit configuration" in str(failure)
    assert any(name.startswith("joints[2] B") for name in failure.aligned)
    assert any(name.startswith("joints[3] O4") for name in failure.aligned)
    assert failure.drivers == ("drivers[0] input angle crank-ground",)


@pytest.mark.parametrize("backend", BACKENDS)
def test_four_bar_drawn_beside_its_limit_solves(tmp_path, backend):
    """A hundredth of a radian before the limit, moving away from it: the motion is solved,
    and the coupler-rocker angle follows the law of cosines."""
    theta = LIMIT_THETA - 0.01
    kernel, _ = _kernel(tmp_path, _four_bar(theta, -1.0), backend)
    trajectory = symkin.solve(kernel)
    crank = theta - trajectory.t  # the drawing at theta, driven by w = -1
    ax, ay = 2 * np.cos(crank), 2 * np.sin(crank)
    distance = np.hypot(3 - ax, ay)  # |A O4|; b = c = 2
    inner = np.arccos((8 - distance**2) / 8)  # the angle at B between coupler and rocker
    coupler = trajectory.q[:, kernel.coordinates.index("coupler.phi")]
    rocker = trajectory.q[:, kernel.coordinates.index("rocker.phi")]
    # Frames take the drawing's axes: the relative angle is 0 at t0 and turns as the angle
    # at B does.
    np.testing.assert_allclose(np.abs(rocker - coupler), np.abs(inner - inner[0]), atol=1e-9)


@pytest.mark.parametrize("backend", BACKENDS)
def test_slider_crank_at_its_dead_centre_is_reported_before_any_step(tmp_path, backend):
    kernel, _ = _kernel(tmp_path, _slider_crank(4.0 - 1e-13), backend)
    failure = _failure(kernel)
    # So close to the dead centre that Newton finds Phi_q singular: no row solved.
    assert failure.reason == "singular" and failure.trajectory.t.size == 0
    assert "in a singular or limit configuration" in str(failure)
    assert failure.drivers == ("drivers[0] push slide ground-slider",)
    assert {"joints[0] O revolute ground-crank", "joints[1] A revolute crank-rod"} \
        <= set(failure.aligned)


@pytest.mark.parametrize("backend", BACKENDS)
def test_slider_crank_beside_its_dead_centre_solves(tmp_path, backend):
    kernel, _ = _kernel(tmp_path, _slider_crank(3.99), backend)
    trajectory = symkin.solve(kernel)
    x = 3.99 - trajectory.t
    phi = np.arccos((1 + x * x - 9) / (2 * x))
    np.testing.assert_allclose(trajectory.q[:, kernel.coordinates.index("crank.phi")], phi,
                               atol=1e-9)


@pytest.mark.parametrize("backend", BACKENDS)
def test_slot_drawn_along_its_normal_stops_at_t0_the_same_on_both_backends(tmp_path, backend):
    kernel, _ = _kernel(tmp_path, PIN_SLOT.replace("AXIS", "-h, r"), backend)
    failure = _failure(kernel)
    assert failure.reason == "singular" and failure.trajectory.t.size == 1
    assert any(name.startswith("joints[2] slot pin_slot") for name in failure.aligned)
    assert failure.drivers == ("drivers[0] crank_drive angle crank-ground",)
    assert "`axis` is a slide's or slot's direction" in str(failure)


@pytest.mark.parametrize("backend", BACKENDS)
def test_slot_drawn_along_its_direction_turns_the_lever_as_the_closed_form(tmp_path, backend):
    """The same lever with the slot drawn along O4-A: the lever points at the pin,
    phi = atan2(h + r sin wt, r cos wt), continuous (no winding)."""
    kernel, _ = _kernel(tmp_path, PIN_SLOT.replace("AXIS", "r, h"), backend)
    trajectory = symkin.solve(kernel)
    wt = 2 * math.pi * trajectory.t
    expected = np.unwrap(np.arctan2(2 + np.sin(wt), np.cos(wt)))
    lever = trajectory.q[:, kernel.coordinates.index("lever.phi")]
    np.testing.assert_allclose(lever - lever[0], expected - expected[0], atol=1e-9)


def test_the_start_check_is_scale_free():
    """The scaled Jacobian of a mechanism drawn in millimetres equals the one in metres."""
    from driver_support import derive, kernel_for

    kernel = kernel_for(derive("non_grashof"), "numpy")
    q = np.array([0, 0, 1.0, 2 * math.cos(1.0), 2 * math.sin(1.0), 0.3, 3, 0, 1.2])
    p = np.array(kernel.p_values, dtype=float)
    metres, scale_m = start.scaled_nonzeros(kernel, kernel.phi_q_nz(q, 0.0, p))
    angles = np.array([name.endswith(".phi") for name in kernel.coordinates])
    q_mm = np.where(angles, q, 1000 * q)
    millimetres, scale_mm = start.scaled_nonzeros(kernel, kernel.phi_q_nz(q_mm, 0.0, 1000 * p))
    assert scale_mm == pytest.approx(1000 * scale_m, rel=1e-12)
    np.testing.assert_allclose(millimetres, metres, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("backend", BACKENDS)
def test_cli_says_it_before_any_step_and_exits_1(tmp_path, backend):
    path = tmp_path / "slot.yaml"
    path.write_text(PIN_SLOT.replace("AXIS", "-h, r"))
    out = tmp_path / "out.csv"
    done = symkin_main("run", str(path), "--backend", backend, "-o", str(out), cwd=ROOT)
    assert done.returncode == 1, done.stderr
    assert "singular or limit configuration" in done.stderr and "slot" in done.stderr
    assert len(out.read_text().splitlines()) == 2  # the header and the start


# The textbook crank-slider (Example 2.5: a = 1, b = 5, offset c = 4) drawn at its outer dead
# centre and driven by the slider: crank and rod collinear, |O B| = a + b, B at height c, so
# B.x = sqrt((a + b)^2 - c^2) and A = (a / (a + b)) B.
TEXTBOOK_DEAD_CENTRE = """
name: crank_slider_dead_centre
layout: drawn
parameters: {a: 1.0, b: 5.0, c: 4.0}
bodies:
  ground: {points: {O: [0, 0]}}
  crank:  {points: {O: [0, 0], A: [a*sqrt((a + b)**2 - c**2)/(a + b), a*c/(a + b)]}}
  rod:    {points: {A: [a*sqrt((a + b)**2 - c**2)/(a + b), a*c/(a + b)],
                     B: [sqrt((a + b)**2 - c**2), c]}}
  slider: {points: {B: [sqrt((a + b)**2 - c**2), c]}}
joints:
  - {type: revolute,  i: ground, j: crank,  at: O}
  - {type: revolute,  i: crank,  j: rod,    at: A}
  - {type: revolute,  i: rod,    j: slider, at: B}
  - {type: prismatic, i: slider, j: ground, at: B, axis: [1, 0]}
drivers:
  - {type: slide, name: push, i: ground, j: slider, sA: O, sB: B, u: [1, 0],
     f: "sqrt((a + b)**2 - c**2) - t"}
time: {t0: 0, t1: 0.5, dt: 0.05}
"""


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("drawing", ["textbook", "exact"])
def test_crank_slider_drawn_at_its_dead_centre_is_refused_error_first(tmp_path, backend,
                                                                      drawing):
    """Refused at the start whatever size a larger mechanism is allowed (runtime.solving.start: 9
    coordinates keep the small threshold), and the error is the first thing said: the
    warning about the one row solved (the exact drawing's is flagged) comes after it."""
    path = tmp_path / "dead_centre.yaml"
    path.write_text(TEXTBOOK_DEAD_CENTRE if drawing == "textbook" else _slider_crank(4.0))
    done = symkin_main("run", str(path), "--backend", backend, cwd=ROOT)
    assert done.returncode == 1, done.stderr
    lines = done.stderr.splitlines()
    assert lines[0].startswith("symkin: error:"), done.stderr
    assert "at t = 0 in a singular or limit configuration" in lines[0]
    assert "drivers[0] push slide ground-slider" in lines[0]
    if drawing == "exact":
        assert any(line.startswith("symkin: warning: 1 point flagged at t = 0")
                   for line in lines[1:]), done.stderr
