"""Efforts and reactions in the pictures of a run: the HTML report's force column holds the
NPZ's numbers (efforts, |F| of each joint, the moments a joint carries), the indeterminate
ones named min-norm; the GIF's frames carry the reaction arrows (pixels of their colour,
absent from the same run drawn without forces), C backend through the CLI."""

from __future__ import annotations

import base64
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from codegen_support import compiled, derived
from motion_support import derived_from, kernel_from
from PIL import Image

import symkin
from symkin import cli
from symkin.present import animation, html
from symkin.symbolic.drawing import outlines

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
pytest.importorskip("plotly")


def _traces(page: Path) -> list[dict]:
    """The figure's traces as the page hands them to plotly.js (JSON; arrays typed)."""
    text = page.read_text(encoding="utf-8")
    start = text.index("[", text.index('"symkin-report"', text.index("Plotly.newPlot(")))
    traces, _ = json.JSONDecoder().raw_decode(text[start:])
    return traces


def _values(array) -> np.ndarray:
    """A trace's y: a list, or plotly's typed array {"dtype", "bdata"} (base64)."""
    if isinstance(array, dict):
        return np.frombuffer(base64.b64decode(array["bdata"]), dtype=array["dtype"])
    return np.asarray(array, dtype=float)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pictures")
    paths = {suffix: folder / f"run.{suffix}" for suffix in ("npz", "html", "gif")}
    # --dt 0.1: 11 time points (the file's 51 draw and check nothing more), each a frame
    assert cli.main(["run", str(EXAMPLES / "parallelogram_extra_bar_loads.yaml"), "--backend",
                     "c", "--dt", "0.1", "-o", str(paths["npz"]), "--html", str(paths["html"]),
                     "--animate", str(paths["gif"])]) == 0
    return paths


def test_html_force_curves_are_the_npz_values(run) -> None:
    traces = {trace["name"]: trace for trace in _traces(run["html"]) if "name" in trace}
    with np.load(run["npz"]) as data:
        effort, reaction = data["effort"], data["reaction"]
        drivers, joints = list(data["driver_names"]), list(data["joint_names"])
        fixed = data["reaction_determinate"]
    for k, name in enumerate(drivers):
        np.testing.assert_array_equal(_values(traces[name]["y"]), effort[:, k])
    for k, name in enumerate(joints):
        label = name if fixed[k, :2].all() else f"{name} (min-norm)"
        np.testing.assert_allclose(_values(traces[label]["y"]),
                                   np.hypot(reaction[:, k, 0], reaction[:, k, 1]), rtol=1e-15)
        assert traces[label]["line"].get("dash", "solid") == (
            "solid" if fixed[k, :2].all() else "dot")
    assert "P (min-norm)" not in traces and "O0 (min-norm)" in traces


def test_html_moment_panel_holds_the_moments_a_joint_carries(tmp_path: Path) -> None:
    """The loaded crank-slider with its slide's point A off the slider's frame: the
    prismatic pair carries a moment, its revolutes none, so the moment panel holds the
    slide's M alone, in the last column's third panel."""
    data = yaml.safe_load((EXAMPLES / "crank_slider_load.yaml").read_text())
    next(j for j in data["joints"] if j["type"] == "prismatic")["sA"] = [0.3, 0.2]
    system = derived_from(data)
    traj = symkin.solve(kernel_from(data, "numpy"))
    page = html.report(traj, tmp_path / "r.html", outlines(system))
    traces = _traces(page)
    last = max(int(t["yaxis"][1:]) for t in traces if t.get("yaxis", "y") != "y")
    moments = [t for t in traces if t.get("yaxis") == f"y{last}" and t.get("name")]
    assert [t["name"] for t in moments] == ["slide"]
    slide = traj.forces.joint_names.index("slide")
    np.testing.assert_array_equal(_values(moments[0]["y"]), traj.reaction[:, slide, 2])


def _reaction_pixels(frame: Image.Image) -> int:
    rgb = np.asarray(frame.convert("RGB"), dtype=int)
    colour = np.array([int(animation.REACTION[k:k + 2], 16) for k in (1, 3, 5)])
    return int((np.abs(rgb - colour).sum(axis=2) < 40).sum())


def test_gif_frames_carry_the_reaction_arrows(run, tmp_path: Path) -> None:
    system = derived(EXAMPLES / "parallelogram_extra_bar_loads.yaml")
    with np.load(run["npz"]) as saved:  # the CLI run's time points
        t = saved["t"]
    traj = symkin.solve(compiled(EXAMPLES / "parallelogram_extra_bar_loads.yaml", "numpy"), t=t)
    shapes = outlines(system)
    bare = animation.animate(dataclasses.replace(traj, forces=None), tmp_path / "bare.gif",
                             shapes)
    with Image.open(run["gif"]) as arrows, Image.open(bare) as plain:
        assert arrows.n_frames == plain.n_frames == traj.t.size
        assert traj.t.size == 11
        for k in (0, 2, 5, 10):
            arrows.seek(k)
            plain.seek(k)
            assert _reaction_pixels(plain) == 0
            assert _reaction_pixels(arrows) > 150, f"frame {k}"
