"""Contact points marked in the pictures (symkin/present/animation.py ``contacts``, drawn by the
GIF and the HTML report): a gear pair's pitch point, a cam's contact (reported as
NAME.contact_x / NAME.contact_y beside its pressure angle). The report's numbers are read back
from the written page and compared with the NPZ the same run wrote and with closed forms
derived here; both backends, the C one compiled, through the CLI (``symkin.cli.main`` in this
process: a real process's exit is tests/cli's)."""

from __future__ import annotations

import base64
import json
import math
from pathlib import Path

import numpy as np
import pytest

from symkin import cli

ROOT = Path(__file__).resolve().parents[2]
RS, RP, W = 1.0, 0.5, 2.0  # examples/planetary.yaml
E, RADIUS, ROLLER = 0.5, 2.0, 0.5  # the eccentric disk cam below


def _run(mechanism: Path, backend: str, folder: Path, capsys: pytest.CaptureFixture[str],
         *options: str) -> tuple[dict, list[dict], list[dict]]:
    """symkin run with -o, --html and --animate; (npz, page data, page frames)."""
    code = cli.main(["run", str(mechanism), "--backend", backend, "-o", str(folder / "r.npz"),
                     "--html", str(folder / "r.html"), "--animate", str(folder / "r.gif"),
                     *options])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert f"({backend} backend" in captured.out
    text = (folder / "r.html").read_text(encoding="utf-8")
    decoder = json.JSONDecoder()
    start = text.index('"symkin-report"', text.index("Plotly.newPlot(")) + len('"symkin-report"')
    data, _ = decoder.raw_decode(text, text.index("[", start))
    frames, _ = decoder.raw_decode(text, text.index("[", text.index("Plotly.addFrames(")))
    assert (folder / "r.gif").read_bytes()[:6] == b"GIF89a"
    return dict(np.load(folder / "r.npz")), data, frames


def _numbers(value: object) -> np.ndarray:
    if isinstance(value, dict):
        return np.frombuffer(base64.b64decode(value["bdata"]), dtype=value["dtype"])
    return np.asarray(value, dtype=float)


def _marked(data: list[dict], frames: list[dict], name: str) -> list[np.ndarray]:
    """Each trace called ``name``: its point in every frame, (T, 2)."""
    indices = [k for k, trace in enumerate(data) if trace.get("name") == name]
    assert indices, [trace.get("name") for trace in data]
    found = []
    for index in indices:
        points = []
        for frame in frames:
            trace = frame["data"][frame["traces"].index(index)]
            points.append([_numbers(trace["x"])[0], _numbers(trace["y"])[0]])
        found.append(np.array(points))
    return found


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_gear_pitch_points_are_where_the_pitch_circles_touch(
        backend: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The arm turns at w_arm = W RS / (2 RS + 2 RP) (Willis, ring fixed); the sun-planet
    pitch point is RS from the sun's centre towards the planet's, the planet-ring one RS + 2 RP
    from the ring's centre (the planet's far side): both on the arm's line."""
    # 31 frames (--dt 0.1, half the file's): every frame is checked, fewer are drawn
    saved, data, frames = _run(ROOT / "examples" / "planetary.yaml", backend, tmp_path,
                               capsys, "--dt", "0.1")
    t = saved["t"]
    arm = W * RS / (2 * RS + 2 * RP) * t
    line = np.stack([np.cos(arm), np.sin(arm)], axis=1)
    sun_planet, planet_ring = _marked(data, frames, "pitch point")
    assert np.abs(sun_planet - RS * line).max() < 1e-9
    assert np.abs(planet_ring - (RS + 2 * RP) * line).max() < 1e-9


def _disk_cam(folder: Path) -> Path:
    """A circle of radius 2 centred 0.5 from the cam's axis, turning at 1 rad/s under a radial
    roller of radius 0.5 guided along the y axis."""
    data = {"name": "disk", "parameters": {},
            "bodies": {"cam": {"q0": [0, 0, 0]},
                       "follower": {"q0": [0, 3, 0], "points": {"R": [0, 0]}}},
            "joints": [{"type": "revolute", "i": "ground", "j": "cam", "sA": [0, 0],
                        "sB": [0, 0]},
                       {"type": "prismatic", "i": "follower", "j": "ground", "sA": [0, 0],
                        "sB": [0, 0], "v": [1, 0]},
                       {"type": "cam", "name": "k1", "i": "cam", "j": "follower",
                        "profile": [f"{E} + {RADIUS}*cos(s)", f"{RADIUS}*sin(s)"],
                        "follower": {"roller": ROLLER, "at": "R"}, "s0": "pi/2"}],
            "drivers": [{"type": "angle", "i": "cam", "j": "ground", "theta": "t"}],
            "time": {"t0": 0, "t1": 3, "dt": 0.1}}
    path = folder / "disk.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_cam_contact_is_marked_where_roller_and_profile_touch(
        backend: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The circle's centre is C = E (cos t, sin t); the roller's centre (0, y) is R + rr from
    it, y = C_y + sqrt((R + rr)^2 - C_x^2); the contact is C + R (roller - C) / (R + rr).
    The page marks it, the NPZ holds the same numbers (k1.contact_x, k1.contact_y)."""
    saved, data, frames = _run(_disk_cam(tmp_path), backend, tmp_path, capsys)
    t = saved["t"]
    centre = E * np.stack([np.cos(t), np.sin(t)], axis=1)
    roller = np.stack([0 * t, centre[:, 1] + np.sqrt((RADIUS + ROLLER) ** 2
                                                     - centre[:, 0] ** 2)], axis=1)
    expected = centre + RADIUS * (roller - centre) / (RADIUS + ROLLER)
    (marked,) = _marked(data, frames, "contact k1")
    assert np.abs(marked - expected).max() < 1e-9
    written = np.stack([saved["k1.contact_x"], saved["k1.contact_y"]], axis=1)
    np.testing.assert_allclose(marked, written, rtol=1e-12, atol=1e-12)
    assert math.isclose(float(np.hypot(*(written - centre).T).max()), RADIUS, rel_tol=1e-9)
