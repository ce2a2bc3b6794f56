"""A curve or cam profile written for s in [a, b] (`range: [a, b]`,
symkin/runtime/outputs/ranges.py): a piecewise formula has values past its range (its last piece
extended), so a contact that runs past the end would be solved on a curve the file does not
describe. The motion stops at the first point past the range, naming the pair; the rows before it
are kept and exact. Both backends, the C one compiled and run.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from driver_support import BACKENDS, kernel_for

import symkin
from symkin import cli
from symkin.errors import MechanismError, SolveError

END = 1.5  # the curve is meant for s in [0, END]


def _guide(**extra) -> dict:
    """A pin pushed along x (x = 0.2 + t) on the curve y = s^2 for s < 1, 2 s - 1 beyond:
    on the curve, s = x."""
    return {"name": "guide", "parameters": {"e": END},
            "bodies": {"pin": {"q0": [0.2, 0.04, 0], "points": {"P": [0, 0]}}},
            "joints": [{"type": "point_on_curve", "name": "c1", "i": "ground", "j": "pin",
                        "point": "P", "curve": ["s", "Piecewise((s**2, s < 1), (2*s - 1, True))"],
                        "s0": 0.2, **extra}],
            "drivers": [{"type": "custom", "name": "push", "equations": ["pin.x - 0.2 - t"]},
                        {"type": "angle", "i": "pin", "j": "ground", "theta": 0}],
            "time": {"t0": 0, "t1": 2, "dt": 0.05}}


@pytest.fixture(scope="module")
def guided():
    return symkin.derive(symkin.from_dict(_guide(range=[0, "e"])))


@pytest.mark.parametrize("backend", BACKENDS)
def test_leaving_the_range_stops_the_motion_naming_the_pair(guided, backend: str) -> None:
    """s = 0.2 + t passes 1.5 at t = 1.3: the first grid point past it is t = 1.35 (s = 1.55);
    the rows before it follow y = s^2 / 2s - 1 (closed form) and stay in the range."""
    kernel = kernel_for(guided, backend)
    assert kernel.backend == backend
    with pytest.raises(SolveError) as error:
        symkin.solve(kernel)
    failure = error.value
    assert failure.reason == "out of range" and math.isclose(failure.t, 1.35)
    assert ("c1.s = 1.55 left its range [0, 1.5] (joints[0] c1 point_on_curve) at t = 1.35"
            in str(failure))
    kept = failure.trajectory
    s = kept.q[:, kept.coordinates.index("c1.s")]
    y = kept.q[:, kept.coordinates.index("pin.y")]
    assert kept.t[-1] == pytest.approx(1.3) and s.max() <= END + 1e-9
    assert np.abs(s - (0.2 + kept.t)).max() < 1e-9
    assert np.abs(y - np.where(s < 1, s**2, 2 * s - 1)).max() < 1e-9


def test_without_a_range_the_curve_goes_on() -> None:
    """The same file without `range`: the formula is followed as written, to the end."""
    system = symkin.derive(symkin.from_dict(_guide()))
    run = symkin.solve(kernel_for(system, "numpy"))
    assert run.t[-1] == pytest.approx(2.0)


@pytest.mark.parametrize(("bounds", "s0", "said", "where"), [
    ([1, 1], 1, "the range [1, 1] is empty", "joints[0].range"),
    ([0.5, 1], 0.2, "s0 = 0.2 is outside the range [0.5, 1]", "joints[0].s0"),
    ([0, "f"], 0.2, "unknown name 'f'", "joints[0].range[1]"),
])
def test_bad_ranges_are_refused_where_they_are(bounds, s0, said: str, where: str) -> None:
    data = _guide(range=bounds)
    data["joints"][0]["s0"] = s0
    with pytest.raises(MechanismError, match=re.escape(said)) as error:
        symkin.from_dict(data)
    assert where in str(error.value)


def _cam(**extra) -> dict:
    """A disk cam turning counter-clockwise under a radial roller on the y axis: the contact
    parameter runs down from pi/2, past 0 near t = pi/2."""
    return {"name": "disk", "parameters": {},
            "bodies": {"cam": {"q0": [0, 0, 0]},
                       "follower": {"q0": [0, 3, 0], "points": {"R": [0, 0]}}},
            "joints": [{"type": "revolute", "i": "ground", "j": "cam", "sA": [0, 0],
                        "sB": [0, 0]},
                       {"type": "prismatic", "i": "follower", "j": "ground", "sA": [0, 0],
                        "sB": [0, 0], "v": [1, 0]},
                       {"type": "cam", "name": "k1", "i": "cam", "j": "follower",
                        "profile": {"polar": "2 + 0.4*cos(s)"},
                        "follower": {"roller": 0.5, "at": "R"}, "s0": "pi/2", **extra}],
            "drivers": [{"type": "angle", "i": "cam", "j": "ground", "theta": "t"}],
            "time": {"t0": 0, "t1": 3, "dt": 0.1}}


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_cam_contact_past_its_profiles_range_stops(backend: str) -> None:
    system = symkin.derive(symkin.from_dict(_cam(range=[0, "2*pi"])))
    with pytest.raises(SolveError) as error:
        symkin.solve(kernel_for(system, backend))
    assert "left its range [0, 6.28319] (joints[2] k1 cam)" in str(error.value)
    kept = error.value.trajectory
    s = kept.q[:, kept.coordinates.index("k1.s")]
    assert kept.t.size >= 10 and s.min() >= 0 and 1.2 < error.value.t < 2.0


def test_cli_exits_1_naming_the_pair_with_the_rows_before(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    mechanism = tmp_path / "guide.json"
    mechanism.write_text(json.dumps(_guide(range=[0, "e"])))
    # symkin run in this process (a real process's exit code is tests/cli's)
    code = cli.main(["run", str(mechanism), "--backend", "numpy", "-o",
                     str(tmp_path / "out.npz")])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err, err
    assert "c1.s = 1.55 left its range [0, 1.5] (joints[0] c1 point_on_curve)" in err
    saved = np.load(tmp_path / "out.npz")
    assert saved["t"][-1] == pytest.approx(1.3)


# ----- the checks and the follower's side over the profile's own range ----------------------

def test_undercut_is_checked_over_the_profiles_range_only() -> None:
    """rho = 2 + 0.4 cos 3s has hollows (at s = pi/3, pi, 5 pi/3) tighter than a roller of 1.5:
    refused over a whole turn. Near s = pi/2 its curvature (rho^2 + 2 rho'^2 - rho rho'') /
    (rho^2 + rho'^2)^(3/2) = 6.88 / 5.44^1.5 > 0: a profile meant only for s in pi/2 +- 0.05
    is convex there and accepted."""
    lobed = _cam()
    lobed["joints"][2].update(profile={"polar": "2 + 0.4*cos(3*s)"},
                              follower={"roller": 1.5, "at": "R"})
    with pytest.raises(MechanismError, match="undercutting"):
        symkin.from_dict(lobed)
    lobed["joints"][2]["range"] = ["pi/2 - 0.05", "pi/2 + 0.05"]
    symkin.from_dict(lobed)


def _wedge(follower_y: float) -> dict:
    """An open profile: the straight flank y = x / 2 (s in [-2, 4], through the cam's frame
    origin, so it has no turning sense about it), on a cam pushed left (x = -t) under a roller
    of radius 0.3 on a vertical guide at x = 0, above or below the flank by q0."""
    return {"name": "wedge", "parameters": {},
            "bodies": {"cam": {"q0": [0, 0, 0]},
                       "follower": {"q0": [0, follower_y, 0], "points": {"R": [0, 0]}}},
            "joints": [{"type": "prismatic", "i": "cam", "j": "ground", "sA": [0, 0],
                        "sB": [0, 0], "v": [0, 1]},  # v: the slide's normal
                       {"type": "prismatic", "i": "follower", "j": "ground", "sA": [0, 0],
                        "sB": [0, 0], "v": [1, 0]},
                       {"type": "cam", "name": "k1", "i": "cam", "j": "follower",
                        "profile": ["s", "s/2"], "follower": {"roller": 0.3, "at": "R"},
                        "s0": 0, "range": [-2, 4]}],
            "drivers": [{"type": "custom", "name": "push", "equations": ["cam.x + t"]}],
            "time": {"t0": 0, "t1": 2, "dt": 0.1}}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("side", [1, -1])
def test_an_open_profiles_roller_stays_on_its_side_at_q0(side: int, backend: str) -> None:
    """The roller's centre is 0.3 from the flank on the side it starts: y = t / 2 +- 0.3
    sqrt(1 + 1/4) (the flank at x = 0 is at height t / 2 when the cam has moved by -t)."""
    system = symkin.derive(symkin.from_dict(_wedge(0.5 * side)))
    run = symkin.solve(kernel_for(system, backend))
    y = run.q[:, system.coordinates.index("follower.y")]
    expected = run.t / 2 + side * 0.3 * math.sqrt(1.25)
    assert np.abs(y - expected).max() < 1e-9
    assert np.abs(run.dq[:, system.coordinates.index("follower.y")] - 0.5).max() < 1e-8
    assert run.t[-1] == pytest.approx(2.0)


def test_a_profile_with_a_range_is_drawn_over_it() -> None:
    """The flank's mark runs from s = -2 to 4: (-2, -1) to (4, 2) in the cam's frame."""
    from symkin.symbolic import drawing

    outlines = drawing.outlines(symkin.derive(symkin.from_dict(_wedge(0.5))))
    (profile,) = [v for k, v in outlines.items() if k.startswith("curve:cam:cam profile:")]
    assert np.allclose(profile[0], [-2, -1]) and np.allclose(profile[-1], [4, 2])
