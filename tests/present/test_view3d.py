"""The 3D pictures of spatial mechanisms: the HTML report (plotly scene, frames, slider) and the
isometric GIF. References: the NPZ `r` written by the same run (the figure must carry exactly
those numbers), and the RSSR crank pin's closed form A(t) = a (cos 2πt, sin 2πt, 0)."""

from __future__ import annotations

import base64
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, symkin_main
from codegen_support import compiled

from symkin.present import view3d
from tests.present.test_present import _browse, _console_lines

ROOT = Path(__file__).resolve().parents[2]
RSSR = ROOT / "examples" / "rssr.yaml"
A = 0.1  # rssr.yaml: the crank pin's radius
STEP = ("--dt", "0.05")  # 21 time points (the file's 101 draw and check no other way)
POINTS = 21


def _cli(*arguments: str, cwd: Path) -> Ran:
    return symkin_main("run", *arguments, cwd=cwd)  # in this process: tests/cli_support.py


def _numbers(value: object) -> np.ndarray:
    """A plotly array from the page's JSON: a plain list or a typed array (dtype, bdata)."""
    if isinstance(value, dict):
        return np.frombuffer(base64.b64decode(value["bdata"]), dtype=value["dtype"])
    return np.asarray(value, dtype=float)


def _figure(page: Path) -> tuple[list[dict], list[dict], dict]:
    """(data, frames, layout) as written into the page (read back from its script)."""
    text = page.read_text(encoding="utf-8")
    decoder = json.JSONDecoder()
    start = text.index('"symkin-report"', text.index("Plotly.newPlot(")) + len('"symkin-report"')
    data, end = decoder.raw_decode(text, text.index("[", start))
    layout, _ = decoder.raw_decode(text, text.index("{", end))
    frames, _ = decoder.raw_decode(text, text.index("[", text.index("Plotly.addFrames(")))
    return data, frames, layout


@pytest.fixture(scope="module", params=["numpy", "c"])
def rssr_run(request, tmp_path_factory) -> tuple[Path, Path, Path]:
    """rssr solved by the CLI with both backends (c: the compiled kernel): npz, html, gif."""
    folder = tmp_path_factory.mktemp(f"rssr_{request.param}")
    result = _cli(str(RSSR), "--backend", request.param, *STEP, "-o", "r.npz", "--html",
                  "r.html", "--animate", "r.gif", cwd=folder)
    assert result.returncode == 0, result.stderr
    assert f"({request.param} backend" in result.stdout
    return folder / "r.npz", folder / "r.html", folder / "r.gif"


def test_report_frames_carry_the_trajectory_points(rssr_run) -> None:
    npz, page, _ = rssr_run
    saved = np.load(npz)
    t, r, names = saved["t"], saved["r"], [str(n) for n in saved["points"]]
    _, frames, layout = _figure(page)
    assert len(frames) == t.size == POINTS  # fewer than MAX_FRAMES: every time point is a frame
    assert len(layout["sliders"][0]["steps"]) == len(frames)
    bodies = {"crank": [names.index("crank.A0"), names.index("crank.A")],
              "rocker": [names.index("rocker.B0"), names.index("rocker.B")]}
    for k, frame in enumerate(frames):
        assert float(frame["name"]) == pytest.approx(t[k], rel=1e-5, abs=1e-12)
        for trace, columns in zip(frame["data"], bodies.values()):
            drawn = np.stack([_numbers(trace[axis]) for axis in "xyz"], axis=1)
            np.testing.assert_array_equal(drawn, r[k, columns])
    # independent of the solver: the crank pin on its circle, turned by the driver 2πt
    pin = np.array([[_numbers(f["data"][0][axis])[1] for axis in "xyz"] for f in frames])
    expected = A * np.stack([np.cos(2 * np.pi * t), np.sin(2 * np.pi * t), 0 * t], axis=1)
    assert np.abs(pin - expected).max() < 1e-9


def test_report_starts_at_the_first_frame_and_is_self_contained(rssr_run) -> None:
    _, page, _ = rssr_run
    data, frames, layout = _figure(page)
    moving = [trace for trace in data if trace.get("name") in ("crank", "rocker")]
    assert [trace["type"] for trace in moving] == ["scatter3d", "scatter3d"]
    for trace, first in zip(moving, frames[0]["data"]):
        for axis in "xyz":
            np.testing.assert_array_equal(_numbers(trace[axis]), _numbers(first[axis]))
    assert layout["scene"]["aspectmode"] == "cube"
    assert "<script src=" not in page.read_text(encoding="utf-8")


def test_report_in_headless_chromium(rssr_run, tmp_path: Path) -> None:
    from PIL import Image

    from symkin.present import series

    _, page, _ = rssr_run
    webgl = ("--enable-unsafe-swiftshader", "--use-angle=swiftshader")
    shot = tmp_path / "rssr.png"
    loaded = _browse(page, *webgl, "--dump-dom", f"--screenshot={shot}")  # one browser
    assert loaded.returncode == 0 and shot.exists(), loaded.stderr
    # The software WebGL's performance notes and plotly's Canvas2D readback hint are the
    # browser's own remarks about drawing speed; any other console line (an error) fails.
    benign = ("willReadFrequently", "GL Driver Message (OpenGL, Performance")
    logged = [line for line in _console_lines(loaded.stderr)
              if not any(remark in line for remark in benign)]
    assert logged == [], loaded.stderr
    dom = loaded.stdout
    assert "gl-container" in dom and "slider-container" in dom and "updatemenu" in dom
    pixels = np.asarray(Image.open(shot).convert("RGB"), dtype=int)[60:650, :1250]
    for colour in series.palette(2):  # crank and rocker drawn in the scene, in their colours
        rgb = np.array([int(colour[k:k + 2], 16) for k in (1, 3, 5)])
        assert (np.abs(pixels - rgb).sum(axis=2) < 40).sum() > 50, f"no {colour} body drawn"


def test_gif_has_a_frame_per_time_point(rssr_run) -> None:
    from PIL import Image

    from symkin.present import series

    _, _, gif = rssr_run
    image = Image.open(gif)
    assert image.n_frames == POINTS and image.size == view3d.DEFAULT_SIZE
    image.seek(5)
    pixels = np.asarray(image.convert("RGB"), dtype=int)
    for colour in series.palette(2):
        rgb = np.array([int(colour[k:k + 2], 16) for k in (1, 3, 5)])
        assert (np.abs(pixels - rgb).sum(axis=2) < 40).sum() > 50, f"no {colour} body drawn"


def test_isometric_projection_of_the_axes() -> None:
    """z straight up, x and y 30 degrees below the horizontal on either side, equal lengths."""
    c, s = np.sqrt(3) / 2, 0.5
    np.testing.assert_allclose(view3d.isometric(np.eye(3)),
                               [[c, -s], [-c, -s], [0.0, 1.0]], atol=1e-15)
    np.testing.assert_allclose(view3d.isometric(np.ones(3)), [0.0, 0.0], atol=1e-15)


def test_many_time_points_are_thinned_to_max_frames(tmp_path: Path) -> None:
    import symkin

    trajectory = symkin.solve(compiled(RSSR, "numpy"), t=np.linspace(0, 1, 401))
    frames = view3d.frame_indices(trajectory)
    assert frames.size == view3d.MAX_FRAMES and frames[0] == 0 and frames[-1] == 400
    page = view3d.report(trajectory, tmp_path / "r.html")
    _, written, _ = _figure(page)
    assert len(written) == view3d.MAX_FRAMES
    r, _, _ = trajectory.point_arrays()
    last = np.stack([_numbers(written[-1]["data"][1][axis]) for axis in "xyz"], axis=1)
    np.testing.assert_array_equal(last, r[-1, 2:4])


def test_no_named_point_is_refused_with_a_message(tmp_path: Path) -> None:
    import symkin
    from symkin.errors import UsageError

    trajectory = symkin.solve(compiled(RSSR, "numpy"))
    bare = dataclasses.replace(trajectory, points=(), point_vectors=np.zeros((0, 3)))
    for draw, name in ((view3d.report, "r.html"), (view3d.animate, "a.gif")):
        with pytest.raises(UsageError, match="names no point on a moving body"):
            draw(bare, tmp_path / name)
        assert not (tmp_path / name).exists()


def test_a_partial_run_draws_without_warnings(tmp_path: Path) -> None:
    """A run stopped half way (NaN rows): both pictures are written, no NaN reaches limits."""
    import warnings

    import symkin

    trajectory = symkin.solve(compiled(RSSR, "numpy"), t=np.linspace(0, 1, POINTS))
    q = trajectory.q.copy()
    q[10:] = np.nan
    partial = dataclasses.replace(trajectory, q=q)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        page = view3d.report(partial, tmp_path / "r.html")
        view3d.animate(partial, tmp_path / "a.gif")
    _, _, layout = _figure(page)
    for axis in "xyz":
        assert all(np.isfinite(layout["scene"][f"{axis}axis"]["range"]))


def test_a_body_with_more_than_two_points_is_a_closed_polygon(tmp_path: Path) -> None:
    """The Stewart platform's six attachments: seven vertices per frame, the last the first."""
    import symkin

    spec = ROOT / "examples" / "stewart.yaml"
    trajectory = symkin.solve(compiled(spec, "numpy"))
    r, _, _ = trajectory.point_arrays()
    columns = [k for k, (body, _) in enumerate(trajectory.points) if body == "platform"]
    assert len(columns) == 6
    _, frames, _ = _figure(view3d.report(trajectory, tmp_path / "s.html"))
    for k, frame in enumerate(frames):
        drawn = np.stack([_numbers(frame["data"][0][axis]) for axis in "xyz"], axis=1)
        np.testing.assert_array_equal(drawn[:6], r[k, columns])
        np.testing.assert_array_equal(drawn[6], r[k, columns[0]])
