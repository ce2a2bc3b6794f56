"""The point_on_curve and cam pairs (symkin/pairs/planar/point_on_curve.py, cam.py) against
closed forms derived here: a pin on an ellipse pushed round by a slotted rod, and a disk cam
whose roller follower rises, dwells and returns on the cycloidal law; both backends, the C one
compiled and run. Then the coordinate NAME.s they add (named, reported, written), the drawn
layout, and the edges: a cusp, undercutting, a flat face on a hollow, s outside the curve's
range, a missing or clashing name."""

from __future__ import annotations

import csv
import functools
import json
import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from cli_support import symkin_main
from codegen_support import compiled, derived
from driver_support import BACKENDS, kernel_for

import symkin
from symkin.errors import MechanismError, SolveError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
T = sp.Symbol("t", real=True)
A_, B_, W_ = 2.0, 1.0, 1.0


def _ellipse(**pair) -> dict:
    """A rod turning about the centre of an ellipse fixed in the ground (the curve, on i);
    a block slides along the rod, its origin (the pin P) held on the ellipse."""
    return {"name": "ellipse", "parameters": {"a": A_, "b": B_, "w": W_},
            "bodies": {"rod": {"q0": [0, 0, 0]},
                       "block": {"q0": ["a", 0, 0], "points": {"P": [0, 0]}}},
            "joints": [{"type": "revolute", "i": "ground", "j": "rod", "sA": [0, 0],
                        "sB": [0, 0]},
                       {"type": "prismatic", "i": "block", "j": "rod", "sA": [0, 0],
                        "sB": [0, 0], "v": [0, 1]},
                       {"type": "point_on_curve", "name": "c1", "i": "ground", "j": "block",
                        "point": "P", "curve": ["a*cos(s)", "b*sin(s)"], "s0": 0, **pair}],
            "drivers": [{"type": "angle", "i": "rod", "j": "ground", "theta": "w*t"}],
            "time": {"t0": 0, "t1": 3, "dt": 0.05}}


def _ellipse_closed_form() -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """P = rho(theta) [cos theta, sin theta], rho = a b / sqrt(b^2 cos^2 + a^2 sin^2), and
    its parameter s = atan2(a sin theta, b cos theta) (theta = w t below pi)."""
    theta = W_ * T
    rho = A_ * B_ / sp.sqrt(B_**2 * sp.cos(theta) ** 2 + A_**2 * sp.sin(theta) ** 2)
    return rho * sp.cos(theta), rho * sp.sin(theta), sp.atan2(A_ * sp.sin(theta),
                                                              B_ * sp.cos(theta))


def _derivatives(expr: sp.Expr, t: np.ndarray) -> list[np.ndarray]:
    return [np.broadcast_to(sp.lambdify(T, sp.diff(expr, T, k), "numpy")(t), t.shape)
            for k in range(3)]


@pytest.fixture(scope="module")
def ellipse():
    return symkin.derive(symkin.from_dict(_ellipse()))


@pytest.mark.parametrize("backend", BACKENDS)
def test_pin_on_an_ellipse_follows_the_closed_form(ellipse, backend: str) -> None:
    kernel = kernel_for(ellipse, backend)
    assert kernel.backend == backend
    run = symkin.solve(kernel)
    for name, exact in zip(("block.x", "block.y", "c1.s"), _ellipse_closed_form()):
        k = ellipse.coordinates.index(name)
        q, dq, d2q = _derivatives(exact, run.t)
        assert np.abs(run.q[:, k] - q).max() < 1e-9, name
        assert np.abs(run.dq[:, k] - dq).max() < 1e-8, name
        assert np.abs(run.d2q[:, k] - d2q).max() < 1e-6, name
    assert not run.flagged.any()


def test_the_coordinate_s_is_named_reported_and_written(ellipse, tmp_path: Path) -> None:
    assert ellipse.coordinates[-1] == "c1.s"
    assert [str(r) for r in ellipse.rows[4:6]] == [
        "joints[2] c1 point_on_curve ground-block (x)",
        "joints[2] c1 point_on_curve ground-block (y)"]
    run = symkin.solve(kernel_for(ellipse, "numpy"))
    assert run.bodies == ("rod", "block")
    path = run.save(tmp_path / "run.csv")
    header = next(csv.reader(path.open()))
    assert {"c1.s", "c1.s_t", "c1.s_tt"} <= set(header)
    data = np.load(run.save(tmp_path / "run.npz"))
    assert list(data["coordinates"])[-1] == "c1.s"


def test_drawn_ellipse_is_global_and_carried_by_its_body() -> None:
    """The same ellipse drawn about (1, 2) on a plate whose frame is turned by 0.5 and held
    by the ground: the pin's motion is the local one shifted by (1, 2)."""
    drawn = {"name": "ellipse_drawn", "layout": "drawn",
             "parameters": {"a": A_, "b": B_, "w": W_},
             "bodies": {"ground": {"points": {"O": [1, 2]}},
                        "plate": {"frame": {"origin": [0, 0], "angle": 0.5},
                                  "points": {"O": [1, 2], "Q": [3, 2]}},
                        "rod": {"points": {"O": [1, 2]}},
                        "block": {"points": {"P": ["1 + a", 2]}}},
             "joints": [{"type": "revolute", "i": "ground", "j": "plate", "at": "O"},
                        {"type": "revolute", "i": "ground", "j": "rod", "at": "O"},
                        {"type": "prismatic", "i": "block", "j": "rod", "at": "P",
                         "axis": [1, 0]},
                        {"type": "point_on_curve", "name": "c1", "i": "plate", "j": "block",
                         "point": "P", "curve": ["1 + a*cos(s)", "2 + b*sin(s)"], "s0": 0}],
             "drivers": [{"type": "angle", "i": "rod", "j": "ground", "theta": "w*t"},
                         {"type": "angle", "i": "plate", "j": "ground", "theta": 0.5}],
             "time": {"t0": 0, "t1": 3, "dt": 0.05}}
    system = symkin.derive(symkin.from_dict(drawn))
    run = symkin.solve(kernel_for(system, "numpy"))
    x, y, s = _ellipse_closed_form()
    for name, exact, shift in (("block.x", x, 1.0), ("block.y", y, 2.0), ("c1.s", s, 0.0)):
        k = system.coordinates.index(name)
        assert np.abs(run.q[:, k] - shift - _derivatives(exact, run.t)[0]).max() < 1e-9


def test_drawn_point_off_its_curve_is_refused() -> None:
    drawn = {"name": "off", "layout": "drawn", "parameters": {},
             "bodies": {"block": {"points": {"P": [2.1, 0]}}},
             "joints": [{"type": "point_on_curve", "name": "c1", "i": "ground", "j": "block",
                         "point": "P", "curve": ["2*cos(s)", "sin(s)"], "s0": 0}],
             "drivers": [{"type": "custom", "equations": ["block.phi"]}],
             "time": {"t0": 0, "t1": 1, "dt": 0.5}}
    said = r"does not close: joints\[0\] 'c1' \(point_on_curve ground\W+block\) is off by 0.1"
    with pytest.raises(MechanismError, match=said + ".*its curve at s0"):
        symkin.from_dict(drawn)


@pytest.mark.parametrize(("change", "said", "where"), [
    ({"name": None}, "a point_on_curve pair needs a name", "joints[2].name"),
    ({"name": "rod"}, "the name 'rod' is a body's", "joints[2].name"),
    ({"curve": ["a*cos(s)", "sqrt(1 - s**2)"], "s0": 2}, "no finite real value",
     "joints[2].curve[1]"),
    ({"curve": ["a*cos(s)", "b*sin(q)"]}, "unknown name 'q'", "joints[2].curve[1]"),
])
def test_bad_curves_are_refused_where_they_are(change: dict, said: str, where: str) -> None:
    data = _ellipse()
    data["joints"][2] = {k: v for k, v in {**data["joints"][2], **change}.items()
                         if v is not None}
    with pytest.raises(MechanismError, match=said) as error:
        symkin.from_dict(data)
    assert where in str(error.value)


def test_s_leaving_the_curves_range_is_said_at_its_time() -> None:
    """A pin driven along x on the upper half of the unit circle, [s, sqrt(1 - s^2)]: the
    curve ends at s = 1 (reached at t = 0.8); the run stops there and says why, never a
    silently wrong number."""
    data = {"name": "half_circle", "parameters": {},
            "bodies": {"pin": {"q0": [0.2, 0.98, 0], "points": {"P": [0, 0]}}},
            "joints": [{"type": "point_on_curve", "name": "c1", "i": "ground", "j": "pin",
                        "point": "P", "curve": ["s", "sqrt(1 - s**2)"], "s0": 0.2}],
            "drivers": [{"type": "displacement", "i": "ground", "j": "pin", "sA": [0, 0],
                         "sB": [0, 0], "f": ["0.2 + t", "0"]},
                        {"type": "angle", "i": "pin", "j": "ground", "theta": 0}],
            "time": {"t0": 0, "t1": 1, "dt": 0.05}}
    data["drivers"][0] = {"type": "custom", "name": "push", "equations": ["pin.x - 0.2 - t"]}
    system = symkin.derive(symkin.from_dict(data))
    with pytest.raises(SolveError) as error:
        symkin.solve(kernel_for(system, "numpy"))
    assert error.value.t is not None and 0.7 <= error.value.t <= 0.85


# ----- the cam -------------------------------------------------------------------------------

H, A1, B1, C1, R0 = 1.0, 2.0, 3.0, 5.0, 3.0


def _cycloidal(theta: sp.Expr) -> sp.Expr:
    """The follower's lift y(theta): cycloidal rise over [0, a], dwell at h to b, cycloidal
    return to c, dwell at 0 to 2 pi."""
    rise = H * (theta / A1 - sp.sin(2 * sp.pi * theta / A1) / (2 * sp.pi))
    u = (theta - B1) / (C1 - B1)
    back = H * (1 - u + sp.sin(2 * sp.pi * u) / (2 * sp.pi))
    return sp.Piecewise((rise, theta < A1), (H, theta < B1), (back, theta < C1), (0, True))


@pytest.fixture(scope="module")
def cam():
    return derived(EXAMPLES / "cam_cycloidal.yaml")  # shared with the goldens' in a worker


@pytest.fixture(scope="module")
def cam_kernel(cam):
    """The cam's kernel of a backend, built once for the tests here and its sources generated
    once per run (lowering its 600-character profile takes many seconds)."""
    return functools.cache(lambda backend: compiled(EXAMPLES / "cam_cycloidal.yaml", backend))


@pytest.mark.parametrize("backend", BACKENDS)
def test_cam_follower_rises_dwells_and_returns_on_the_cycloidal_law(cam, cam_kernel,
                                                                   backend: str) -> None:
    """The cam turns clockwise at 1 rad/s, so the follower on the x axis meets the profile
    at the cam angle theta = t: x = R0 + y(t), its velocity y'(t) and acceleration y''(t);
    the contact parameter is s = t."""
    kernel = cam_kernel(backend)
    assert kernel.backend == backend
    run = symkin.solve(kernel)
    law = R0 + _cycloidal(T)
    k = cam.coordinates.index("follower.x")
    q, dq, d2q = _derivatives(law, run.t)
    assert np.abs(run.q[:, k] - q).max() < 1e-9
    assert np.abs(run.dq[:, k] - dq).max() < 1e-8
    assert np.abs(run.d2q[:, k] - d2q).max() < 1e-6
    s = cam.coordinates.index("k1.s")
    assert np.abs(run.q[:, s] - run.t).max() < 1e-9
    assert np.abs(run.dq[:, s] - 1).max() < 1e-8
    # the law's own numbers: a full rise h, the peak speed 2h/a at the middle of the rise
    assert run.q[:, k].max() == pytest.approx(R0 + H, abs=1e-9)
    assert np.abs(run.dq[:, k]).max() == pytest.approx(2 * H / A1, rel=1e-3)
    assert not run.flagged.any()


def test_cam_profile_is_a_600_character_piecewise_admitted_by_the_bounds(cam) -> None:
    profile = cam.mechanism.joints[2].profile
    assert all(550 <= len(text) <= 1000 for text in profile)


def _cam(profile, follower: dict, **extra) -> dict:
    return {"name": "disk", "parameters": {},
            "bodies": {"cam": {"q0": [0, 0, 0]},
                       "follower": {"q0": [0, 3, 0], "points": {"R": [0, 0]}}},
            "joints": [{"type": "revolute", "i": "ground", "j": "cam", "sA": [0, 0],
                        "sB": [0, 0]},
                       {"type": "prismatic", "i": "follower", "j": "ground", "sA": [0, 0],
                        "sB": [0, 0], "v": [1, 0]},
                       {"type": "cam", "name": "k1", "i": "cam", "j": "follower",
                        "profile": profile, "follower": follower, "s0": "pi/2", **extra}],
            "drivers": [{"type": "angle", "i": "cam", "j": "ground", "theta": "t"}],
            "time": {"t0": 0, "t1": 6, "dt": 0.1}}


def test_flat_face_on_an_eccentric_circle() -> None:
    """A circle of radius 2 centred 0.5 from the cam's axis, under a flat face normal to the
    follower's axis y: the face's height is 0.5 sin(theta + pi/2)... the circle's centre
    height plus its radius: y = 0.5 cos(t) + 2 + ... exactly 0.5 sin(t + pi/2) + 2."""
    data = _cam(["0.5 + 2*cos(s)", "2*sin(s)"], {"flat": True, "at": "R", "normal": [0, 1]})
    data["bodies"]["follower"]["q0"] = [0, 2, 0]
    system = symkin.derive(symkin.from_dict(data))
    run = symkin.solve(kernel_for(system, "numpy"))
    k = system.coordinates.index("follower.y")
    assert np.abs(run.q[:, k] - (2 + 0.5 * np.sin(run.t))).max() < 1e-9
    assert np.abs(run.d2q[:, k] + 0.5 * np.sin(run.t)).max() < 1e-6


def test_roller_on_a_circle_stays_outside_whatever_the_orientation() -> None:
    """A circle of radius 2 centred 0.5 off the axis, written clockwise or counter-clockwise:
    the roller (radius 0.5) stays outside, its centre at 0.5 sin(t) + sqrt(2.5^2 - ...)."""
    heights = []
    for profile in (["0.5 + 2*cos(s)", "2*sin(s)"], ["0.5 + 2*cos(s)", "-2*sin(s)"]):
        data = _cam(profile, {"roller": 0.5, "at": "R"})
        data["joints"][2]["s0"] = "pi/2" if profile[1][0] != "-" else "-pi/2"
        data["bodies"]["follower"]["q0"] = [0, 2.5, 0]
        system = symkin.derive(symkin.from_dict(data))
        run = symkin.solve(kernel_for(system, "numpy"))
        heights.append(run.q[:, system.coordinates.index("follower.y")])
    # centre of the circle at (0.5 cos t, 0.5 sin t); the roller's centre on x = 0 at 2.5
    centre_x, centre_y = 0.5 * np.cos(run.t), 0.5 * np.sin(run.t)
    exact = centre_y + np.sqrt(2.5**2 - centre_x**2)
    for height in heights:
        assert np.abs(height - exact).max() < 1e-9


@pytest.mark.parametrize(("profile", "follower", "said"), [
    (["cos(s)**3", "sin(s)**3"], {"roller": 0.1, "at": "R"}, r"cusp \(c'\(s\) = 0\) at s = "),
    ({"polar": "2 + 0.4*cos(3*s)"}, {"roller": 1.5, "at": "R"},
     r"undercutting: the roller.s radius 1.5 is not smaller than the radius of curvature "
     r"1.28 of the concave profile at s = 3.14159"),
    ({"polar": "2 + 0.4*cos(3*s)"}, {"flat": True, "at": "R", "normal": [0, 1]},
     "a flat face would bridge the hollow and lose contact"),
    ({"polar": "2"}, {"roller": -1, "at": "R"}, "the roller's radius -1 is not positive"),
    ({"polar": "2"}, {"roller": 1, "at": "Z"}, "body 'follower' has no point named 'Z'"),
])
def test_cam_edges_are_refused_with_where_they_occur(profile, follower: dict,
                                                     said: str) -> None:
    with pytest.raises(MechanismError, match=said) as error:
        symkin.from_dict(_cam(profile, follower))
    assert "joints[2]" in str(error.value)


def test_a_small_roller_in_the_same_hollow_is_accepted() -> None:
    symkin.from_dict(_cam({"polar": "2 + 0.4*cos(3*s)"}, {"roller": 0.05, "at": "R"}))


def test_drawn_cam_polar_profile_turns_with_its_frame() -> None:
    """A cam drawn with its frame turned by 0.3: the polar angle is global as drawn, so the
    follower's motion is the same as with an unturned frame."""
    def drawn(angle: float) -> dict:
        return {"name": "cam_drawn", "layout": "drawn", "parameters": {},
                "bodies": {"ground": {"points": {"O": [0, 0]}},
                           "cam": {"frame": {"origin": [0, 0], "angle": angle},
                                   "points": {"O": [0, 0]}},
                           "follower": {"points": {"R": [0, 2.8]}}},
                "joints": [{"type": "revolute", "i": "ground", "j": "cam", "at": "O"},
                           {"type": "prismatic", "i": "follower", "j": "ground", "at": "R",
                            "axis": [0, 1]},
                           {"type": "cam", "name": "k1", "i": "cam", "j": "follower",
                            "profile": {"polar": "2 + 0.3*sin(s)"},
                            "follower": {"roller": 0.5, "at": "R"}, "s0": "pi/2"}],
                "drivers": [{"type": "angle", "i": "cam", "j": "ground",
                             "theta": f"{angle} + t"}],
                "time": {"t0": 0, "t1": 3, "dt": 0.1}}
    runs = []
    for angle in (0.0, 0.3):
        system = symkin.derive(symkin.from_dict(drawn(angle)))
        run = symkin.solve(kernel_for(system, "numpy"))
        runs.append(run.q[:, system.coordinates.index("follower.y")])
    assert np.abs(runs[0] - runs[1]).max() < 1e-12
    assert runs[0][0] == pytest.approx(2.8, abs=1e-12)
    assert not math.isclose(runs[0].min(), runs[0].max())


def test_cam_pressure_angle_and_curvature_radius_follow_the_law(cam, cam_kernel,
                                                               tmp_path: Path) -> None:
    """For a radial roller follower, tan(pressure angle) = y'(theta) / (R0 + y(theta)) (the
    pitch curve's normal against the follower's axis), undefined (NaN) in the dwells where
    the follower rests; the profile's radius of curvature is the pitch curve's, of the polar
    curve R = R0 + y: (R^2 + R'^2)^(3/2) / (R^2 + 2 R'^2 - R R''), less the roller's radius.
    Written as CSV columns and NPZ arrays k1.pressure_angle and k1.curvature_radius."""
    run = symkin.with_outputs(cam, symkin.solve(cam_kernel("numpy")))
    outputs = dict(run.outputs)
    y, dy, d2y = _derivatives(_cycloidal(T), run.t)
    moving = np.abs(dy) > 1e-6
    angle = outputs["k1.pressure_angle"]
    assert np.abs(angle[moving] - np.arctan(np.abs(dy[moving]) / (R0 + y[moving]))).max() < 1e-9
    assert np.isnan(angle[np.abs(dy) == 0]).all()
    R = R0 + y
    pitch = (R**2 + dy**2) ** 1.5 / (R**2 + 2 * dy**2 - R * d2y)
    assert np.abs(outputs["k1.curvature_radius"] - (pitch - 0.5)).max() < 1e-9
    # the contact: the roller's radius 0.5 from its centre (R0 + y, 0), along the normal that
    # makes the pressure angle with the follower's axis
    contact = np.stack([outputs["k1.contact_x"], outputs["k1.contact_y"]], axis=1)
    gap = np.stack([R0 + y, 0 * y], axis=1) - contact
    assert np.abs(np.hypot(*gap.T) - 0.5).max() < 1e-9
    tilt = np.abs(np.arctan2(gap[:, 1], gap[:, 0]))
    assert np.abs(tilt[moving] - np.arctan(np.abs(dy[moving]) / (R0 + y[moving]))).max() < 1e-9
    header = next(csv.reader(run.save(tmp_path / "cam.csv").open()))
    assert header[-5:] == ["k1.pressure_angle", "k1.curvature_radius", "k1.contact_x",
                           "k1.contact_y", "flagged"]
    saved = np.load(run.save(tmp_path / "cam.npz"))
    assert np.array_equal(saved["k1.curvature_radius"], outputs["k1.curvature_radius"])


def _cli(cwd: Path, *args: str) -> tuple[int, str]:
    """symkin run in this process (cli_support.symkin_main; a real process's exit code is
    tests/cli's): code, stderr."""
    ran = symkin_main("run", *args, cwd=cwd)
    assert "Traceback" not in ran.stderr, ran.stderr
    return ran.returncode, ran.stderr


def test_cli_undercut_exits_2_and_curve_end_exits_1(tmp_path: Path) -> None:
    """Undercutting is a mistake in the file (exit 2, located, no traceback); the end of a
    curve met during the motion stops the run at its time naming the pair (exit 1), with the
    rows solved so far written (the CSV has the column c1.s)."""
    data = _cam({"polar": "2 + 0.4*cos(3*s)"}, {"roller": 1.5, "at": "R"})
    bad = tmp_path / "undercut.yaml"
    bad.write_text(json.dumps(data))
    code, err = _cli(tmp_path, str(bad), "--backend", "numpy")
    assert code == 2
    assert "joints[2].profile.polar: undercutting" in err
    mechanism = Path(__file__).resolve().parents[1] / "mechanisms" / "half_circle_end.yaml"
    code, err = _cli(tmp_path, str(mechanism), "--backend", "numpy", "-o",
                     str(tmp_path / "half.csv"))
    assert code == 1
    assert "near t = 0.79999" in err and "c1 point_on_curve" in err
    header = next(csv.reader((tmp_path / "half.csv").open()))
    assert "c1.s" in header
