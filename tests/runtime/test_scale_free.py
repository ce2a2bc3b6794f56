"""The same mechanism drawn at 10^-9 ... 10^6 times its size solves alike on both backends: the
motion scaled (against the closed form of Example 2.7, scaled by hand), the same flags, the
same limit time (the closed form acos(-1/4) of the non-Grashof four-bar).

Before, the crank-slider in millimetres (10^3, 10^4) stopped "singular at t = 0", at 10^5 and
10^6 it "could not be assembled", at 10^-9 it was "singular", and at 10^-6 every point was
flagged.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
import pytest
from codegen_support import derived, sources
from driver_support import BACKENDS, kernel_of, mechanism_file

import symkin
from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.runtime.solving import units

SCALES = (1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e4, 1e5, 1e6)

CRANK_SLIDER = """
name: crank_slider_scaled
parameters: {{a: {a!r}, b: {b!r}, c: {c!r}}}
bodies:
  crank:  {{q0: [0, 0, 0], points: {{tip: [a, 0]}}}}
  rod:    {{q0: [0, 0, 0], points: {{P: [b, 0]}}}}
  slider: {{q0: [0, 0, 0]}}
joints:
  - {{type: revolute,  i: ground, j: crank,  sA: [0, 0], sB: [0, 0]}}
  - {{type: revolute,  i: crank,  j: rod,    sA: tip,    sB: [0, 0]}}
  - {{type: revolute,  i: rod,    j: slider, sA: [b, 0], sB: [0, 0]}}
  - {{type: prismatic, i: slider, j: ground, sA: [0, 0], sB: [0, c], v: [0, 1], phi0: 0}}
drivers:
  - {{type: angle, i: crank, j: ground, theta: "t**2 + pi/2"}}
time: {{t0: 0, t1: 1.5, dt: 0.05}}
"""

NON_GRASHOF = """
name: non_grashof_scaled
parameters: {{a: {a!r}, d: {d!r}}}
bodies:
  crank:   {{q0: [0, 0, 0], points: {{A: [a, 0]}}}}
  coupler: {{q0: [{x2!r}, 0, 1.3], points: {{B: [a, 0]}}}}
  rocker:  {{q0: [{x3!r}, 0, 1.8], points: {{B: [a, 0]}}}}
joints:
  - {{type: revolute, name: O2, i: ground,  j: crank,   sA: [0, 0], sB: [0, 0]}}
  - {{type: revolute, name: A,  i: crank,   j: coupler, sA: A,      sB: [0, 0]}}
  - {{type: revolute, name: B,  i: coupler, j: rocker,  sA: B,      sB: B}}
  - {{type: revolute, name: O4, i: rocker,  j: ground,  sA: [0, 0], sB: [d, 0]}}
drivers:
  - {{type: angle, name: input, i: crank, j: ground, theta: "t"}}
time: {{t0: 0, t1: 2.5, dt: 0.05}}
"""


PARALLELOGRAM = """
name: parallelogram_scaled
parameters: {{L: {L!r}}}
bodies:
  r0: {{q0: [0, 0, 0.5], points: {{tip: [L, 0]}}}}
  r1: {{q0: [L, 0, 0.5], points: {{tip: [L, 0]}}}}
  c0: {{q0: [0.88*L, 0.48*L, 0]}}
joints:
  - {{type: revolute, name: O0, i: ground, j: r0, sA: [0, 0], sB: [0, 0]}}
  - {{type: revolute, name: O1, i: ground, j: r1, sA: [L, 0], sB: [0, 0]}}
  - {{type: revolute, name: A0, i: r0, j: c0, sA: tip, sB: [0, 0]}}
  - {{type: revolute, name: B0, i: c0, j: r1, sA: [L, 0], sB: tip}}
drivers:
  - {{type: angle, name: drive, i: r0, j: ground, theta: "0.5 - t"}}
time: {{t0: 0, t1: 1, dt: 0.05}}
"""


# Every parameter of the three drawings is a length; the drawing at scale s is the one at
# scale 1 with every parameter and every position of q0 times s (the angles unchanged).
UNIT = {CRANK_SLIDER: {"a": 1.0, "b": 5.0, "c": 4.0},
        NON_GRASHOF: {"a": 2.0, "d": 3.0, "x2": 2.0, "x3": 3.0},
        PARALLELOGRAM: {"L": 1.0}}
# The drawings whose C at every scale differs from the C at scale 1 in its nominal values
# only. Not the four-bars: their sparse LU's pivot order, chosen at generation time from the
# numbers of the sample configuration, changes with the scale (so each scale of theirs is
# built from its own file).
SAME_C = (CRANK_SLIDER,)


def _drawn(template: str, s: float) -> str:
    return template.format(**{name: s * value for name, value in UNIT[template].items()})


def _in_c(template: str, s: float) -> tuple[Any, dict[str, Any]]:
    """The C kernel of the drawing at scale s, and the solve arguments that make it so: the
    drawing at scale 1, compiled once for every scale, run with the scaled file's own
    parameters and q0 — its nominal values, all its C holds otherwise
    (test_a_drawing_at_any_scale_generates_the_same_c_but_its_values; one C build instead of
    one per scale, 1.7 s of gcc each). Only for a drawing in SAME_C."""
    assert template in SAME_C
    drawn = derived(mechanism_file(_drawn(template, s)))
    return kernel_of(_drawn(template, 1.0), "c"), {
        "params": np.array(drawn.p_values, dtype=float), "q0": np.array(drawn.q0, dtype=float)}


def _at_scale(template: str, s: float, backend: str) -> tuple[Any, dict[str, Any]]:
    """The kernel of the drawing at scale s and symkin.solve's arguments for it: built from
    the scaled file itself, but a C kernel of a drawing in SAME_C (_in_c)."""
    if backend == "c" and template in SAME_C:
        return _in_c(template, s)
    return kernel_of(_drawn(template, s), backend), {}


def _as_scaled(line: str, values: dict[str, str]) -> str:
    """A generated line with its digests blanked and the nominal values written as in
    ``values`` (their text at scale 1 -> at s)."""
    digests = re.sub(r"\b[0-9a-f]{64}\b", "<sha256>", line)
    number = re.compile(r"(?<![\w.])-?\d+(?:\.\d*)?(?:e[-+]?\d+)?(?![\w.])")
    return number.sub(lambda m: values.get(m.group(0), m.group(0)), digests)


SCALED = [(CRANK_SLIDER, s) for s in SCALES if s != 1.0]


@pytest.mark.parametrize(("template", "s"), SCALED, ids=[f"{s:g}" for _, s in SCALED])
def test_a_drawing_at_any_scale_generates_the_same_c_but_its_values(template: str,
                                                                   s: float) -> None:
    """The C sources of the file drawn at scale s equal those of the file at scale 1 line for
    line, but for the lines that hold its nominal values (written scaled) and the digests:
    so the C runs here of the scale-1 kernel with the scaled file's parameters and q0 are
    the scaled file's own runs."""
    files = [mechanism_file(_drawn(template, k)) for k in (1.0, s)]
    unit, scaled = (sources(file, "c") for file in files)
    values: dict[str, str] = {}
    for one, other in zip(*((*derived(f).p_values, *derived(f).q0) for f in files)):
        assert values.setdefault(repr(one), repr(other)) == repr(other)  # one text each
    assert sorted(unit) == sorted(scaled)
    changed = 0
    for name in unit:
        ours, theirs = unit[name].splitlines(), scaled[name].splitlines()
        assert len(ours) == len(theirs), name
        for line, (mine, other) in enumerate(zip(ours, theirs)):
            if mine != other:  # only where the values (or the digests) are
                assert _as_scaled(mine, values) == _as_scaled(other, {}), \
                    f"{name}:{line + 1}: {mine!r} -> {other!r}"
                changed += 1
    assert changed  # the values are in the sources, and were mapped


def _example_2_7(t: np.ndarray, s: float) -> dict[str, np.ndarray]:
    """The textbook closed form (a, b, c = 1, 5, 4) drawn s times larger."""
    a, b, c = s, 5 * s, 4 * s
    phi1 = t**2 + math.pi / 2
    x2, y2 = a * np.cos(phi1), a * np.sin(phi1)
    phi2 = np.arcsin((c - y2) / b)
    return {"crank.phi": phi1, "rod.x": x2, "rod.y": y2, "rod.phi": phi2,
            "slider.x": x2 + b * np.cos(phi2), "slider.y": np.full_like(t, c)}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("s", SCALES)
def test_crank_slider_at_any_scale_follows_the_scaled_closed_form(tmp_path, backend, s):
    kernel, scaled = _at_scale(CRANK_SLIDER, s, backend)
    trajectory = symkin.solve(kernel, **scaled)
    assert trajectory.t.size == 31
    assert not trajectory.flagged.any()  # as at s = 1: no point flagged
    for name, expected in _example_2_7(trajectory.t, s).items():
        column = trajectory.q[:, kernel.coordinates.index(name)]
        tolerance = 1e-10 if name.endswith(".phi") else 1e-10 * s
        np.testing.assert_allclose(column, expected, rtol=0, atol=tolerance, err_msg=name)
    # Velocities scale too: the slider's speed against a central difference of the closed
    # form.
    h = 1e-6
    slider = lambda t: _example_2_7(np.array([t]), s)["slider.x"][0]  # noqa: E731
    k = 10
    speed = (slider(trajectory.t[k] + h) - slider(trajectory.t[k] - h)) / (2 * h)
    assert trajectory.dq[k, kernel.coordinates.index("slider.x")] == pytest.approx(
        speed, rel=1e-6)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("s", (1e-6, 1.0, 1e3, 1e6))
def test_the_limit_position_is_found_at_the_same_time_at_any_scale(tmp_path, backend, s):
    kernel, scaled = _at_scale(NON_GRASHOF, s, backend)
    with pytest.raises(SolveError) as caught:
        symkin.solve(kernel, **scaled)
    failure = caught.value
    assert isinstance(failure, driver.SolveFailure) and failure.reason == "limit position"
    assert failure.reached == pytest.approx(math.acos(-0.25), abs=1e-8)
    assert failure.trajectory.t.size == 37  # the grid points before t* = 1.8235
    assert int(failure.trajectory.flagged.sum()) == 0
    crank_x = failure.trajectory.q[:, kernel.coordinates.index("coupler.x")]
    np.testing.assert_allclose(crank_x, 2 * s * np.cos(failure.trajectory.t), atol=1e-10 * s)




@pytest.mark.parametrize("backend", BACKENDS)
def test_a_singular_passage_is_flagged_alike_at_any_scale(tmp_path, backend):
    """The parallelogram driven through its change point (all bars on the x axis at t = 0.5):
    the same points flagged and the same passage at every scale; positions L (cos, sin) of
    the crank angle 0.5 - t."""
    flags = {}
    for scale in (1e-6, 1.0, 1e3, 1e6):
        kernel, scaled = _at_scale(PARALLELOGRAM, scale, backend)
        trajectory = symkin.solve(kernel, **scaled)
        flags[scale] = trajectory.flagged.tolist()
        assert [round(t, 6) for t, _, _ in trajectory.singular] == [0.5]
        theta = 0.5 - trajectory.t
        coupler = trajectory.q[:, kernel.coordinates.index("c0.x")]
        np.testing.assert_allclose(coupler, scale * np.cos(theta), rtol=0, atol=1e-6 * scale)
    assert any(flags[1.0])  # the passage is flagged ...
    assert all(flags[scale] == flags[1.0] for scale in flags)  # ... alike at every scale


def test_the_unit_is_one_for_a_mechanism_of_ordinary_size():
    from driver_support import derive, kernel_for

    kernel = kernel_for(derive("non_grashof"), "numpy")
    p = np.array(kernel.p_values, dtype=float)
    assert units.unit_for(kernel, np.asarray(kernel.q0, dtype=float), 0.0, p) == 1.0
    assert units.unit_for(kernel, np.asarray(kernel.q0, dtype=float), 0.0, 1e3 * p) == 1e3
    assert units.unit_for(kernel, np.asarray(kernel.q0, dtype=float), 0.0, 1e-6 * p) == 1e-6


@pytest.mark.parametrize("s", (1e-6, 1e3, 1e6))
def test_scan_finds_the_same_branches_at_any_scale(tmp_path, s):
    """Two assemblies at t0 (slider right and left of the crank): slider.x = +-sqrt(b^2 - (c -
    a)^2) = +-4 s, the rod at atan(3/4) or pi - atan(3/4)."""
    from symkin.runtime.scanning.scan import scan

    kernel, _ = _at_scale(CRANK_SLIDER, s, "numpy")
    report = scan(kernel)
    x = sorted(float(b.q[kernel.coordinates.index("slider.x")]) for b in report.branches)
    np.testing.assert_allclose(x, [-4 * s, 4 * s], rtol=1e-9)
    rod = sorted(float(b.q[kernel.coordinates.index("rod.phi")]) for b in report.branches)
    np.testing.assert_allclose(rod, [math.atan(0.75), math.pi - math.atan(0.75)], atol=1e-9)
    assert report.motions[0].stop is None and not report.branches[0].near_singular


@pytest.mark.parametrize("s", (1e-6, 1e-3, 1e3, 1e6))
def test_c_solves_any_scale_in_its_generated_loop_with_the_decisions_of_numpy(
        tmp_path, monkeypatch, s):
    """A C run in another unit runs the generated grid loop deciding in that unit (the C
    options' ``unit``), never the Python loop, and takes NumPy's decisions: the same flags and
    condition estimates, the motion equal to rounding (the closed form is checked above)."""
    (c_kernel, scaled), (numpy_kernel, _) = (_at_scale(CRANK_SLIDER, s, b)
                                             for b in ("c", "numpy"))
    assert c_kernel.scale_free

    def refuse(*args):
        raise AssertionError("the Python grid loop ran")

    advanced = []
    advance = units.ScaledGridSolver.advance
    monkeypatch.setattr(driver, "_python_loop", refuse)
    monkeypatch.setattr(units.ScaledGridSolver, "advance",
                        lambda self, a, b: advanced.append((a, b)) or advance(self, a, b))
    in_c = symkin.solve(c_kernel, **scaled)
    assert advanced == [(0, 31)]  # one call of the generated loop, in the unit
    monkeypatch.undo()
    in_numpy = symkin.solve(numpy_kernel)
    assert np.array_equal(in_c.flagged, in_numpy.flagged) and not in_c.flagged.any()
    np.testing.assert_allclose(in_c.cond, in_numpy.cond, rtol=1e-6)
    positions = np.array([name.endswith((".x", ".y")) for name in c_kernel.coordinates])
    scale = np.where(positions, s, 1.0)
    np.testing.assert_allclose(in_c.q / scale, in_numpy.q / scale, rtol=0, atol=1e-12)
    np.testing.assert_allclose(in_c.d2q / scale, in_numpy.d2q / scale, rtol=0, atol=1e-10)


def test_the_c_option_unit_decides_a_millimetre_drawing_as_one_in_metres(tmp_path):
    """The generated loop itself, called with unit 1 and unit 1000 on the crank-slider drawn
    in millimetres: in its own unit the Jacobian's condition is a million times that in
    metres, and the point is counted singular; in unit 1000 the 31 points solve, with the
    condition estimates of the drawing in metres."""
    metres, _ = _in_c(CRANK_SLIDER, 1.0)
    millimetres, drawn = _in_c(CRANK_SLIDER, 1e3)
    options = driver.default_options(millimetres)
    t = np.linspace(0.0, 1.5, 31)
    reference = symkin.solve(metres, t=t)
    conds = {}
    for unit in (1.0, 1e3):
        solver = millimetres.grid_solver(options, drawn["q0"], drawn["params"], unit)
        rows = [np.zeros((31, 9)) for _ in range(3)]
        cond, flagged = np.zeros(31), np.zeros(31, dtype=bool)
        solver.bind(t, *rows, cond, flagged)
        solved = solver.advance(0, 31)
        solver.release()
        conds[unit] = (solved, cond[:solved])
    assert conds[1.0][0] < 31  # stopped: counted singular in the drawing's own unit
    assert conds[1e3][0] == 31
    np.testing.assert_allclose(conds[1e3][1], reference.cond, rtol=1e-6)
