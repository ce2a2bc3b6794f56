"""The reaction arrows of a spatial run (issue 27, item 2): the 3D report and the isometric GIF.

The run is bench/spatial_slider_crank_forces.yaml (the spatial slider-crank with masses,
gravity, a torque, a damper and a spring) solved by the CLI. The arrows are checked against
the run's own NPZ and the file's geometry: each starts at its joint's point on body i (a
ground point of the file, or a named point the NPZ holds) and is the NPZ reaction force
times one scale, the largest of the run VECTOR_SHARE of the scene's cube.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from cli_support import symkin_main
from codegen_support import compiled, derived
from motion_support import kernel

from symkin.present import view3d
from tests.present.test_view3d import RSSR, _figure, _numbers

ROOT = Path(__file__).resolve().parents[2]
FORCES = ROOT / "bench" / "spatial_slider_crank_forces.yaml"
H, R, K, L = 0.1, 0.08, 0.12, 0.4  # the file's parameters h, r, k, L
B0 = np.sqrt(L**2 - (H + R) ** 2 - K**2)  # where the slider's B starts, on the x axis
ARROWS = "joint reactions (i on j)"
MAGENTA = np.array([0xC2, 0x00, 0x8F])  # animation.REACTION


STEP = ("--dt", "0.05")  # 21 time points: each a frame of the page and of the GIF
POINTS = 21


@pytest.fixture(scope="module")
def forces_cache(tmp_path_factory) -> dict[str, str]:
    """A kernel cache of this module's own: the first run in it derives, the next reuses."""
    return {"SYMKIN_CACHE_DIR": str(tmp_path_factory.mktemp("forces_cache"))}


@pytest.fixture(scope="module")
def forces_run(tmp_path_factory, forces_cache) -> tuple[Path, Path, Path]:
    """The loaded spatial slider-crank solved by the CLI (NumPy backend) in an empty kernel
    cache, so deriving (the cold run of test_a_warm_run_draws_the_same_arrows): npz, html,
    gif."""
    folder = tmp_path_factory.mktemp("spatial_forces")
    result = symkin_main("run", str(FORCES), "--backend", "numpy", *STEP, "-o", "f.npz",
                         "--html", "f.html", "--animate", "f.gif", cwd=folder, env=forces_cache)
    assert result.returncode == 0, result.stderr
    assert "cached kernel" not in result.stdout, result.stdout
    return folder / "f.npz", folder / "f.html", folder / "f.gif"


@pytest.fixture(scope="module")
def solved(forces_run) -> tuple[Any, Any]:
    """The file's System and its NumPy trajectory at the CLI run's time points (the API):
    derived and generated once per run (tests/dynamics/test_spatial_forces.py solves the same
    file)."""
    import symkin

    system = derived(FORCES)
    return system, symkin.solve(kernel(FORCES, "numpy"), t=np.load(forces_run[0])["t"])


def _tails_and_heads(frame: dict, first: int, count: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """The arrows of one frame, the figure's ``count`` traces from ``first`` on: tails and
    heads, each (J, 3)."""
    own = frame["traces"].index(first)  # a frame lists the traces it updates, in its order
    ends = np.array([np.stack([_numbers(trace[axis]) for axis in "xyz"], axis=1)
                     for trace in frame["data"][own:own + count]])
    return ends[:, 0], ends[:, 1]


def test_report_arrows_are_the_npz_reactions_at_the_joints_points(forces_run) -> None:
    npz, page, _ = forces_run
    saved = np.load(npz)
    names = [str(n) for n in saved["points"]]
    joints = [str(n) for n in saved["joint_names"]]
    assert joints == ["crank_bearing", "pin", "cross", "guide"]
    data, frames, layout = _figure(page)
    arrows = [k for k, trace in enumerate(data) if trace.get("name") == ARROWS]
    assert len(arrows) == 4 and sum(data[k]["showlegend"] for k in arrows) == 1
    first = arrows[0]
    assert len(frames) == saved["t"].size == POINTS
    # the file's geometry: the bearing and the guide on the ground, the pin on the crank (its
    # point A), the cross on the slider (its point B)
    ground = np.array([[0.0, H, K], [B0, 0.0, 0.0]])
    span = (np.diff(layout["scene"]["xaxis"]["range"])[0]) / 1.1  # the cube is 1.1 spans
    largest = np.linalg.norm(saved["reaction"][..., :3], axis=-1).max()
    scale = 0.15 * span / largest
    for k, frame in enumerate(frames):
        tails, heads = _tails_and_heads(frame, first)
        np.testing.assert_allclose(tails[[0, 3]], ground, atol=1e-12)
        np.testing.assert_allclose(tails[1], saved["r"][k, names.index("crank.A")], atol=1e-12)
        np.testing.assert_allclose(tails[2], saved["r"][k, names.index("slider.B")],
                                   atol=1e-12)
        force = saved["reaction"][k, :, :3]
        np.testing.assert_allclose(heads - tails, scale * force, rtol=1e-9,
                                   atol=1e-12 * span)
        own = frame["traces"].index(first)
        for j, trace in enumerate(frame["data"][own:own + 4]):
            np.testing.assert_allclose(np.reshape(_numbers(trace["customdata"]), (2, 3)),
                                       [force[j], force[j]], rtol=1e-12)
    # every time point is a frame, so the run's largest force is among them: VECTOR_SHARE long
    lengths = [np.linalg.norm(heads - tails, axis=1)
               for tails, heads in (_tails_and_heads(f, first) for f in frames)]
    assert np.max(lengths) == pytest.approx(0.15 * span, rel=1e-9)
    # the crank pin on its circle about the bearing's axis x, turned by the driver 2πt:
    # the arrows' tails are where the mechanism is, not only where the code put them
    t = saved["t"]
    pin = np.array([_tails_and_heads(f, first)[0][1] for f in frames])
    circle = np.stack([0 * t, H + R * np.cos(2 * np.pi * t), K + R * np.sin(2 * np.pi * t)], 1)
    assert np.abs(pin - circle).max() < 1e-9


def test_no_arrows_without_forces_or_without_the_joints_points(forces_run,
                                                               tmp_path: Path) -> None:
    import symkin

    rssr = symkin.solve(compiled(RSSR, "numpy"))
    assert rssr.forces is None
    data, frames, _ = _figure(view3d.report(rssr, tmp_path / "rssr.html", outlines={}))
    assert not [trace for trace in data if trace.get("name") == ARROWS]
    assert len(frames[0]["data"]) == len(view3d.body_lines(rssr))


def _frame(gif: Path, k: int) -> np.ndarray:
    from PIL import Image

    image = Image.open(gif)
    image.seek(k)
    return np.asarray(image.convert("RGB"), dtype=int)


def _magenta(pixels: np.ndarray) -> int:
    """Arrow-coloured pixels in the mechanism's axes (the legend, right of x = 700, has a
    magenta line of its own)."""
    return int((np.abs(pixels[:, :700] - MAGENTA).sum(axis=2) < 40).sum())


def test_gif_draws_the_arrows_and_only_with_them(forces_run, solved, tmp_path: Path) -> None:
    from symkin.symbolic import drawing

    _, _, gif = forces_run
    system, trajectory = solved
    bare = view3d.animate(trajectory, tmp_path / "bare.gif")
    drawn = view3d.animate(trajectory, tmp_path / "drawn.gif",
                           outlines=drawing.spatial_outlines(system))
    for k in (0, 5, 12):
        with_arrows, without = _frame(drawn, k), _frame(bare, k)
        assert _magenta(with_arrows) > 50 and _magenta(without) == 0
        assert (np.abs(with_arrows - without).sum(axis=2) > 0).sum() > 50
        np.testing.assert_array_equal(_frame(gif, k), with_arrows)  # the CLI draws them too


def test_report_force_column_is_the_npz_magnitudes(forces_run) -> None:
    """Beside the scene: each driver's effort, each joint's |F| and |M| (the norms of the
    NPZ's [Fx, Fy, Fz] and [Mx, My, Mz]) against t, and a time cursor per panel."""
    npz, page, _ = forces_run
    saved = np.load(npz)
    data, frames, layout = _figure(page)
    curves = {(trace["yaxis"], trace["name"]): _numbers(trace["y"]) for trace in data
              if trace["type"] == "scatter" and trace.get("name")}
    np.testing.assert_allclose(curves[("y", "driver0")], saved["effort"][:, 0], rtol=1e-12)
    force = np.sqrt((saved["reaction"][..., :3] ** 2).sum(axis=-1))
    moment = np.sqrt((saved["reaction"][..., 3:] ** 2).sum(axis=-1))
    for j, name in enumerate(str(n) for n in saved["joint_names"]):
        np.testing.assert_allclose(curves[("y2", name)], force[:, j], rtol=1e-12)
        if moment[:, j].max() > 1e-9 * force.max():  # the spherical pin carries none
            np.testing.assert_allclose(curves[("y3", name)], moment[:, j], rtol=1e-12)
    assert ("y3", "pin") not in curves
    assert layout["yaxis3"]["title"]["text"] == "joint moment |M| [N m (SI)]"  # no units given
    cursors = [k for k, trace in enumerate(data) if trace["type"] == "scatter"
               and not trace.get("name")]
    assert len(cursors) == 3 and set(cursors) <= set(frames[0]["traces"])
    own = frames[8]["traces"].index(cursors[0])
    assert _numbers(frames[8]["data"][own]["x"]) == pytest.approx([saved["t"][8]] * 2)


def test_a_warm_run_draws_the_same_arrows(forces_run, forces_cache, tmp_path: Path) -> None:
    """The joints' points travel in the index with the kernel (3-component rows): the run
    that reuses the cached kernel draws the arrows the deriving run (forces_run) drew."""
    _, page, _ = forces_run
    result = symkin_main("run", str(FORCES), "--backend", "numpy", *STEP, "--html", "warm.html",
                         cwd=tmp_path, env=forces_cache)
    assert result.returncode == 0, result.stderr
    assert "cached kernel" in result.stdout, result.stdout
    (cold, cold_frames, _), (warm, warm_frames, _) = _figure(page), _figure(tmp_path / "warm.html")
    assert [t.get("name") for t in warm] == [t.get("name") for t in cold]
    assert len(warm_frames) == len(cold_frames) == POINTS
    first = next(k for k, trace in enumerate(cold) if trace.get("name") == ARROWS)
    for a, b in zip(cold_frames, warm_frames):
        np.testing.assert_array_equal(_tails_and_heads(a, first), _tails_and_heads(b, first))


def test_a_partial_run_with_forces_draws_without_warnings(solved, tmp_path: Path) -> None:
    """Rows a run did not solve (NaN positions and loads) draw no arrow and warn nothing."""
    import dataclasses
    import warnings

    from symkin.symbolic import drawing

    system, trajectory = solved
    q, reaction = trajectory.q.copy(), trajectory.forces.reaction.copy()
    q[10:], reaction[10:] = np.nan, np.nan
    partial = dataclasses.replace(trajectory, q=q, forces=dataclasses.replace(
        trajectory.forces, reaction=reaction))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        outlines = drawing.spatial_outlines(system)
        page = view3d.report(partial, tmp_path / "p.html", outlines=outlines)
        view3d.animate(partial, tmp_path / "p.gif", outlines=outlines)
    data, frames, _ = _figure(page)
    first = next(k for k, trace in enumerate(data) if trace.get("name") == ARROWS)
    tails, heads = _tails_and_heads(frames[4], first)
    assert np.isfinite(tails).all() and (np.linalg.norm(heads - tails, axis=1) > 0).all()
    assert _magenta(_frame(tmp_path / "p.gif", 4)) > 50
    assert _magenta(_frame(tmp_path / "p.gif", 16)) == 0  # nothing solved, nothing drawn


def test_report_with_forces_in_headless_chromium(forces_run, tmp_path: Path) -> None:
    """The page with its arrows and forces column loads without a console message and shows
    the arrows' magenta in the scene (software WebGL)."""
    from PIL import Image

    from tests.present.test_present import _browse, _console_lines

    _, page, _ = forces_run
    webgl = ("--enable-unsafe-swiftshader", "--use-angle=swiftshader")
    shot = tmp_path / "forces.png"
    taken = _browse(page, *webgl, f"--screenshot={shot}")
    assert taken.returncode == 0 and shot.exists(), taken.stderr
    benign = ("willReadFrequently", "GL Driver Message (OpenGL, Performance")
    assert [line for line in _console_lines(taken.stderr)
            if not any(remark in line for remark in benign)] == [], taken.stderr
    scene = np.asarray(Image.open(shot).convert("RGB"), dtype=int)[60:650, :700]
    assert (np.abs(scene - MAGENTA).sum(axis=2) < 60).sum() > 20


def test_report_arrows_show_over_a_body_line_and_say_their_unit(forces_run) -> None:
    """An arrow along its body's line (a rod pushed along itself) was hidden under it: the
    arrows are wider than the bodies' lines and dashed; the force axes and the arrows' hover
    say the unit (the file gives none: N (SI))."""
    _, page, _ = forces_run
    data, _, layout = _figure(page)
    arrows = [trace for trace in data if trace.get("name") == ARROWS]
    bodies = [trace for trace in data if trace.get("type") == "scatter3d"
              and trace.get("name") in ("crank", "rod", "slider")]
    assert arrows and bodies
    widest_body = max(trace["line"]["width"] for trace in bodies)
    for trace in arrows:
        assert trace["line"]["width"] > widest_body and trace["line"]["dash"] == "dash"
        assert "N (SI)" in trace["hovertemplate"]
    titles = [axis["title"]["text"] for name, axis in layout.items()
              if name.startswith("yaxis") and isinstance(axis, dict) and "title" in axis]
    assert "effort [N (SI) or N m (SI)]" in titles and "joint force |F| [N (SI)]" in titles
    assert "joint moment |M| [N m (SI)]" in titles


@pytest.mark.parametrize("units, force, moment", [
    ({"length": "m"}, "[N]", "[N m]"), (None, "[N (SI)]", "[N m (SI)]"),
    ({"length": "mm", "time": "ms"}, "[mass·mm/ms²]", "[mass·mm²/ms²]")])
def test_force_figure_axes_give_the_units(units, force, moment, monkeypatch, tmp_path) -> None:
    from symkin.present import force_plots
    from symkin.present.series import Units
    from symkin.runtime.loads.forces import Forces
    from symkin.runtime.outputs.results import Trajectory

    saved = []
    monkeypatch.setattr(force_plots, "_save", lambda figure, plt, path: saved.append(figure))
    t = np.linspace(0, 1, 5)
    trajectory = Trajectory(t, np.zeros((5, 3)), np.zeros((5, 3)), np.zeros((5, 3)),
                            ("a.x", "a.y", "a.phi"))
    trajectory.__dict__["forces"] = Forces(np.zeros((5, 3)), np.ones((5, 1)),
                                           np.ones((5, 1, 3)), ("motor",), ("pin",))
    force_plots.plot_forces(trajectory, tmp_path / "f.png", units=Units.of(units))
    labels = [ax.get_ylabel() for ax in saved[0].axes]
    assert labels[0].endswith(f"{force[:-1]} or {moment[1:]}")
    assert labels[1].endswith(force) and labels[2].endswith(moment)
