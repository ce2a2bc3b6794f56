"""How the higher pairs are drawn (symkin/symbolic/drawing.py ``curve:`` marks, drawn by the
GIF and the HTML report): pitch circles with a radius that turns with the gear, the rack's
line, curves and cam profiles, each a polyline in its body's frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from codegen_support import derived
from driver_support import kernel_for

import symkin
from symkin.present import animation, html
from symkin.symbolic import drawing

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_gears_are_pitch_circles_whose_mark_turns(tmp_path: Path) -> None:
    system = derived(EXAMPLES / "planetary.yaml")  # the run's shared derivation
    outlines = drawing.outlines(system)
    keys = [k for k in outlines if k.startswith("curve:")]
    assert [k.split(":")[1] for k in keys] == ["sun", "sun", "planet", "planet", "planet",
                                               "planet", "ground", "ground"]
    circle = outlines[keys[0]]
    assert np.abs(np.hypot(*circle.T) - 1.0).max() < 1e-12  # the sun's pitch radius
    # 31 points of the file's 0..3 s (every 0.1 s, half its dt): the GIF draws a frame per
    # point, and the mark turns through the same angles
    run = symkin.solve(kernel_for(system, "numpy"), t=np.linspace(0.0, 3.0, 31))
    found = dict((f"{k}", p) for k, (_, p) in zip(keys, animation.marks(run, outlines)))
    radius = found[keys[1]]  # the sun's turning radius, [0, 0] to [rs, 0] in its frame
    tip = radius[:, -1]
    sun = run.q[:, system.coordinates.index("sun.phi")]
    assert np.abs(tip - np.stack([np.cos(sun), np.sin(sun)], 1)).max() < 1e-12
    assert animation.animate(run, tmp_path / "p.gif", outlines).stat().st_size > 0
    page = html.report(run, tmp_path / "p.html", outlines).read_text()
    assert "pitch circle" in page


def test_rack_line_curve_and_cam_profile_are_drawn() -> None:
    rack = drawing.outlines(derived(EXAMPLES / "rack_linkage.yaml"))
    (key, line), = [(k, v) for k, v in rack.items() if k.startswith("curve:")]
    assert key.startswith("curve:rack:rack:")
    assert np.abs(line[:, 1]).max() == 0 and line[0, 0] == -5.0 and line[-1, 0] == 5.0
    cam = symkin.from_dict({
        "name": "disk", "parameters": {},
        "bodies": {"cam": {"q0": [0, 0, 0]},
                   "follower": {"q0": [0, 2.5, 0], "points": {"R": [0, 0]}}},
        "joints": [{"type": "revolute", "i": "ground", "j": "cam", "sA": [0, 0], "sB": [0, 0]},
                   {"type": "prismatic", "i": "follower", "j": "ground", "sA": [0, 0],
                    "sB": [0, 0], "v": [1, 0]},
                   {"type": "cam", "name": "k1", "i": "cam", "j": "follower",
                    "profile": {"polar": "2"}, "follower": {"roller": 0.5, "at": "R"},
                    "s0": "pi/2"}],
        "drivers": [{"type": "angle", "i": "cam", "j": "ground", "theta": "t"}],
        "time": {"t0": 0, "t1": 1, "dt": 0.5}})
    profile = [v for k, v in drawing.outlines(symkin.derive(cam)).items()
               if k.startswith("curve:cam:cam profile:")]
    assert len(profile) == 1 and np.abs(np.hypot(*profile[0].T) - 2).max() < 1e-12
