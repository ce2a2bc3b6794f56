"""Pictures of a run: the plot's selection, units and colours, the animation's pivots, slide
axes, size and frame rate, and the interactive HTML report opened in a real headless browser.

The browser test needs Chromium; without it the test skips with a reason, unless
SYMKIN_REQUIRE_TOOLS names chromium (CI installed it: then its absence is an error).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled, derived

import symkin
from symkin.errors import MechanismError, UsageError
from symkin.present import animation, html, plots, series
from symkin.present.series import Units
from symkin.symbolic import drawing

ROOT = Path(__file__).resolve().parents[2]
MECHANISMS = Path(__file__).resolve().parents[1] / "mechanisms"
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"
SIX_BAR = MECHANISMS / "watt_six_bar.yaml"


def _run(path: Path, backend: str = "numpy"):
    """The file's trajectory and outlines, its System and kernel shared by the run."""
    kernel = compiled(path, backend)
    assert kernel.backend == backend
    return symkin.solve(kernel), drawing.outlines(derived(path))


@pytest.fixture(scope="module")
def six_bar():
    return _run(SIX_BAR)


@pytest.fixture(scope="module")
def crank_slider():
    return _run(TEXTBOOK)


# ----- selection, units, colours -------------------------------------------------------------

def test_default_selection_shows_each_moving_point_once(six_bar) -> None:
    trajectory, _ = six_bar
    # Ground pivots (O2, O4, O6) do not move; crank.A = coupler.A, coupler.B = rocker.B,
    # rocker.C = link.C and link.D = output.D are the two halves of revolute joints.
    assert series.default_selection(trajectory) == [
        "crank.phi", "coupler.phi", "rocker.phi", "link.phi", "output.phi",
        "crank.A", "coupler.B", "coupler.M", "rocker.C", "link.D"]


def test_unknown_selection_lists_the_valid_names(six_bar) -> None:
    trajectory, _ = six_bar
    with pytest.raises(UsageError) as caught:
        series.check_selection(["crank.phi", "coupler.Q"], trajectory.coordinates,
                               trajectory.points)
    message = str(caught.value)
    assert "coupler.Q" in message and "crank.phi" in message.split("choose from:")[1]
    assert "coupler.M" in message.split("choose from:")[1]


def test_colours_never_repeat_within_a_panel(six_bar) -> None:
    trajectory, _ = six_bar
    every = series.names(trajectory.coordinates, trajectory.points)  # 27 quantities
    curves = series.curves(trajectory, every, Units())
    for kind in (series.LENGTH, series.ANGLE):
        colours = [c.colour for c in curves if c.kind == kind]
        assert len(colours) == len(set(colours)) > 4
    assert len(set(series.palette(40))) == 40


def test_units_label_axes_and_show_degrees(crank_slider) -> None:
    trajectory, _ = crank_slider
    units = Units.of({"length": "mm", "angle": "deg"})
    assert units.axis_label(series.LENGTH, 1) == "velocity [mm/s]"
    assert units.axis_label(series.ANGLE, 2) == "angular acceleration [deg/s²]"
    assert Units().axis_label(series.LENGTH, 0) == "position"  # no unit given, none invented
    (curve,) = series.curves(trajectory, ["crank.phi"], units)
    # theta = t**2 + pi/2 (the textbook driver), shown in degrees
    assert np.allclose(curve.values[0][:, 0], np.degrees(trajectory.t**2 + np.pi / 2))
    assert np.allclose(curve.values[1][:, 0], np.degrees(2 * trajectory.t))


def test_units_key_is_validated(tmp_path: Path) -> None:
    text = TEXTBOOK.read_text()
    good = tmp_path / "good.yaml"
    good.write_text(text + "units: {length: m, angle: deg}\n")
    assert symkin.load(good).units.angle == "deg"
    # Units label pictures only: the generated code (and its spec hash) does not change.
    assert symkin.load(good).spec_hash() == symkin.load(TEXTBOOK).spec_hash()
    for bad in ("{length: m, angle: grad}", "{length: '<script>'}", "{speed: m}", "m"):
        (tmp_path / "bad.yaml").write_text(text + f"units: {bad}\n")
        with pytest.raises(MechanismError, match="units"):
            symkin.load(tmp_path / "bad.yaml")


# ----- the figure ----------------------------------------------------------------------------

@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".svg", b"<?xml"),
                                           (".pdf", b"%PDF")])
def test_plot_formats_by_suffix(crank_slider, tmp_path: Path, suffix: str, magic: bytes) -> None:
    trajectory, _ = crank_slider
    path = plots.plot(trajectory, tmp_path / f"p{suffix}", ["crank.phi", "rod.P"],
                      Units(length="m"), "crank_slider")
    assert path.read_bytes().startswith(magic)


def test_plot_refuses_other_suffixes(crank_slider, tmp_path: Path) -> None:
    with pytest.raises(UsageError, match=r"\.png, \.svg, \.pdf"):
        plots.plot(crank_slider[0], tmp_path / "p.jpg")
    assert list(tmp_path.iterdir()) == []


def test_six_bar_plot_has_three_rows_and_two_columns(six_bar, tmp_path: Path) -> None:
    from PIL import Image

    path = plots.plot(six_bar[0], tmp_path / "six.png", units=Units(length="m"),
                      title="watt_six_bar")
    width, height = Image.open(path).size
    assert (width, height) == (1180, 880)  # two columns of panels, three rows


# ----- the animation -------------------------------------------------------------------------

def test_outlines_hold_ground_pivots_and_slide_axes(six_bar, crank_slider) -> None:
    assert six_bar[1]["ground"].tolist() == [[0, 0], [4, 0], [9, 0]]
    # the textbook's prismatic pair: slider on ground, sB = [0, c] = [0, 4], v = [0, 1]
    assert crank_slider[1]["slide:ground"].tolist() == [[0, 4], [1, 0]]


def test_slide_axis_is_placed_in_the_global_frame(crank_slider) -> None:
    trajectory, outlines = crank_slider
    ((at, direction),) = animation.slide_axes(trajectory, outlines)
    assert np.allclose(at, [0, 4]) and np.allclose(direction, [1, 0])
    # the slider's pin (rod.P) stays on that axis all the time
    r, _, _ = trajectory.point("rod", "P")
    assert np.abs(r[:, 1] - 4).max() < 1e-12


def test_animation_size_and_frame_rate(crank_slider, tmp_path: Path) -> None:
    from PIL import Image

    trajectory, outlines = crank_slider
    seen = []
    path = animation.animate(trajectory, tmp_path / "a.gif", outlines, fps=10, size=(640, 480),
                             progress=lambda done, total: seen.append((done, total)))
    image = Image.open(path)
    assert image.size == (640, 480)
    assert image.n_frames == trajectory.t.size == 31
    assert image.info["duration"] == 100  # ms per frame at 10 fps
    assert seen[-1] == (31, 31) and len(seen) == 31


@pytest.mark.parametrize("text", ["640", "0x480", "640x", "axb", "9000x100"])
def test_bad_sizes_are_refused(text: str) -> None:
    with pytest.raises(UsageError, match="WIDTHxHEIGHT"):
        animation.parse_size(text)


# ----- the HTML report -----------------------------------------------------------------------

def test_report_is_self_contained(crank_slider, tmp_path: Path) -> None:
    trajectory, outlines = crank_slider
    path = html.report(trajectory, tmp_path / "r.html", outlines, ["crank.phi", "rod.P"],
                       Units(length="m"), "crank_slider")
    text = path.read_text(encoding="utf-8")
    assert not re.search(r"<script[^>]+src=", text)  # plotly.js is inside, nothing fetched
    assert text.count("<script") >= 2 and "crank_slider" in text
    # names reach the page as JSON, with "/" and "<" escaped (no markup from data)
    assert "velocity vectors (m\\u002fs)" in text
    assert "acceleration vectors (m\\u002fs" in text


def test_report_without_plotly_says_how_to_install(crank_slider, tmp_path: Path,
                                                   monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "plotly.graph_objects", None)
    with pytest.raises(UsageError, match=r"symkin\[html\]"):
        html.report(crank_slider[0], tmp_path / "r.html", crank_slider[1])


def _chromium() -> str:
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None:
        if "chromium" in os.environ.get("SYMKIN_REQUIRE_TOOLS", "").split():
            pytest.fail("chromium is required (SYMKIN_REQUIRE_TOOLS) but not found")
        pytest.skip("chromium is not installed (Debian: apt install chromium)")
    return found


def _browse(page: Path, *options: str) -> subprocess.CompletedProcess[str]:
    """Open a page in headless Chromium; console messages go to stderr as CONSOLE lines."""
    command = [_chromium(), "--headless", "--disable-gpu", "--no-sandbox",
               "--enable-logging=stderr", "--v=0", "--virtual-time-budget=8000",
               "--window-size=1400,900", *options, page.as_uri()]
    return subprocess.run(command, capture_output=True, text=True, timeout=180, check=False)


def _console_errors(stderr: str) -> list[str]:
    """Console messages of the page at warning or error level (not the browser's own logs)."""
    return [line for line in stderr.splitlines() if "CONSOLE" in line
            and not re.search(r"INFO:CONSOLE|:INFO:.*CONSOLE", line)]


def _console_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if "CONSOLE" in line]


def test_console_errors_are_seen(tmp_path: Path) -> None:
    """The check below can fail: a page that logs an error is caught."""
    page = tmp_path / "bad.html"
    page.write_text("<html><body><script>console.error('planted');undefinedCall();</script>"
                    "</body></html>")
    result = _browse(page, "--dump-dom")
    assert any("planted" in line for line in _console_lines(result.stderr)), result.stderr


def test_report_in_headless_chromium(six_bar, tmp_path: Path) -> None:
    from PIL import Image

    trajectory, outlines = six_bar
    page = html.report(trajectory, tmp_path / "six.html", outlines, units=Units(length="m"),
                       title="watt_six_bar")
    shot = tmp_path / "six.png"
    loaded = _browse(page, "--dump-dom", f"--screenshot={shot}")  # one browser for both
    assert loaded.returncode == 0 and shot.exists(), loaded.stderr
    assert _console_lines(loaded.stderr) == [], loaded.stderr
    dom = loaded.stdout
    # plotly drew the figure: its SVG layers, the slider and play buttons are in the DOM
    assert 'class="main-svg"' in dom and "slider-container" in dom and "updatemenu" in dom
    pixels = np.asarray(Image.open(shot).convert("RGB"), dtype=int)
    mechanism = pixels[80:650, 60:560]  # the left part of the page: the mechanism's view
    for colour in series.palette(5):  # the five moving bodies, each in its own colour
        rgb = np.array([int(colour[k:k + 2], 16) for k in (1, 3, 5)])
        close = np.abs(mechanism - rgb).sum(axis=2) < 40
        assert close.sum() > 50, f"no {colour} body drawn in the mechanism's view"


def test_run_without_plotly_stops_before_solving(tmp_path: Path) -> None:
    """--html without plotly: exit 2 at once with the install hint, nothing written."""
    blocker = tmp_path / "blocker"
    blocker.mkdir()
    (blocker / "sitecustomize.py").write_text("import sys\nsys.modules['plotly'] = None\n")
    env = {**os.environ, "PYTHONPATH": f"{blocker}{os.pathsep}{ROOT}"}
    result = subprocess.run([sys.executable, "-m", "symkin", "run", str(TEXTBOOK), "-o", "a.csv",
                             "--html", "r.html"], cwd=tmp_path, env=env, capture_output=True,
                            text=True, timeout=300, check=False)
    assert result.returncode == 2 and "pip install 'symkin[html]'" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "a.csv").exists() and not (tmp_path / "r.html").exists()
