"""Stage 7 for spatial mechanisms: the 3D report (plotly) and the projected GIF (matplotlib).

A spatial run carries no outlines (those are planar local vectors), so the picture is read
from the trajectory alone: each moving body is a line through its named points in file order,
every named point is marked (the examples name a point at each joint), and the dotted path of
every moving point stays in the view. The HTML report is a rotatable plotly scene with one
frame per shown time and a slider; the GIF is an isometric projection of the same lines.
With masses or forces, each joint's reaction force (body i on body j) is an arrow at its point
on body i, the largest of the run VECTOR_SHARE of the scene long, as in the planar pictures,
and the HTML report has the planar report's column of efforts and reactions beside its scene;
a run its forces move (runtime.dynamics) has the planar report's energy column too.

Names in the figure come from a validated file and reach the browser as JSON data only.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin import outfiles
from symkin.errors import SymkinError, UsageError
from symkin.present import page, series
from symkin.present.placement import REACTION, VECTOR_SHARE, Outlines, joint_points
from symkin.present.series import DEFAULT_UNITS, Units
from symkin.runtime.outputs.results import Trajectory

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]

MAX_FRAMES = 200
DEFAULT_SIZE = (900, 600)  # pixels
DPI = 100
BODY_WIDTH = 8  # a body's line in the report, in pixels
ARROW_WIDTH = 12
"""A reaction arrow's line: wider than a body's (and dashed), so that one along its body's
line shows over it."""
# Isometric view with z up: the x axis drawn down to the right, y down to the left.
ISO_ANGLE = np.pi / 6


def body_lines(trajectory: Trajectory) -> dict[str, Array]:
    """Per body with named points, the global positions of its points, shape (T, n, 3)."""
    r, _, _ = trajectory.point_arrays()
    lines: dict[str, list[int]] = {}
    for k, (body, _) in enumerate(trajectory.points):
        lines.setdefault(body, []).append(k)
    return {body: r[:, columns, :] for body, columns in lines.items()}


def frame_indices(trajectory: Trajectory) -> Array:
    """The time indices drawn: at most MAX_FRAMES, evenly spaced, first and last included."""
    return np.unique(np.linspace(0, trajectory.t.size - 1, MAX_FRAMES).astype(int))


def isometric(points: Array) -> Array:
    """(..., 3) points as (..., 2) picture coordinates of the isometric projection."""
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    across = (x - y) * np.cos(ISO_ANGLE)
    up = z - (x + y) * np.sin(ISO_ANGLE)
    return np.stack([across, up], axis=-1)


def _drawable(trajectory: Trajectory) -> dict[str, Array]:
    if trajectory.t.size == 0:
        raise UsageError("nothing to draw: no time point was solved")
    lines = body_lines(trajectory)
    if not lines:
        raise UsageError("nothing to draw: the mechanism names no point on a moving body "
                         "(add points to its bodies to see them in the 3D view)")
    return lines


def reactions(trajectory: Trajectory, outlines: Outlines | None
              ) -> tuple[list[str], Array, Array]:
    """The joints drawn with an arrow, their points on body i (T, J, 3) and their reaction
    forces [Fx, Fy, Fz] (T, J, 3, unscaled); none without forces. An unsolved row's force
    is zero and its point NaN (a ground point too), so that no arrow is drawn there."""
    forces = trajectory.forces
    where = joint_points(trajectory, outlines or {}) if forces is not None else {}
    shown = [k for k, name in enumerate(forces.joint_names) if name in where] if forces else []
    if forces is None or not shown:
        return [], np.zeros((trajectory.t.size, 0, 3)), np.zeros((trajectory.t.size, 0, 3))
    names = [forces.joint_names[k] for k in shown]
    points = np.stack([where[name] for name in names], axis=1)
    force = forces.reaction[:, shown, :3]
    points = np.where(np.isfinite(force).all(axis=-1, keepdims=True), points, np.nan)
    return names, points, np.nan_to_num(force)


def force_scale(forces: Array, span: float) -> float:
    """Scene length per unit of force: the largest force of the run VECTOR_SHARE of span."""
    largest = float(np.linalg.norm(forces, axis=-1).max(initial=0.0))
    return VECTOR_SHARE * span / largest if largest > 0 else 0.0


def _bounds(lines: dict[str, Array]) -> tuple[Array, Array]:
    """Low and high corners of everything drawn (NaN rows of a partial run ignored)."""
    every = np.concatenate([a.reshape(-1, 3) for a in lines.values()] + [np.zeros((1, 3))])
    every = every[np.all(np.isfinite(every), axis=1)]
    return every.min(axis=0), every.max(axis=0)


# --- the HTML report --------------------------------------------------------------------------


def graph_objects() -> Any:
    """plotly's figure module, or a UsageError saying how to install it (both reports)."""
    try:
        import plotly.graph_objects as go
    except ImportError:
        raise UsageError("--html needs the plotly package, which draws the report: "
                         "pip install 'symkin[html]' (or pip install plotly)") from None
    return go


def report(trajectory: Trajectory, path: str | Path, units: Units = DEFAULT_UNITS,
           title: str = "symkin", outlines: Outlines | None = None) -> Path:
    """Write the self-contained 3D report: bodies moving under a time slider (play / pause).

    Args:
        trajectory: the solved spatial run (a partial one works too).
        path: the .html file to write.
        units: labels from the file's ``units`` key.
        title: the page's title, e.g. the mechanism's name.
        outlines: the joints' points (:func:`symkin.symbolic.drawing.spatial_outlines`),
            where the reaction arrows are drawn; none drawn without.
    """
    path = Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise UsageError(f"cannot write a report to {path.name}: use a file ending in .html")
    go = graph_objects()
    lines = _drawable(trajectory)
    frames = frame_indices(trajectory)
    figure = _figure(go, trajectory)
    for body, points in lines.items():
        for k, (_, name) in enumerate(p for p in trajectory.points if p[0] == body):
            track = points[:, k, :]
            if _moves(track):
                figure.add_trace(go.Scatter3d(
                    x=track[:, 0], y=track[:, 1], z=track[:, 2], mode="lines",
                    name=f"path {body}.{name}", legendgroup="paths", showlegend=False,
                    line={"dash": "dot", "width": 2, "color": "#777"}, hoverinfo="skip"))
    moving = []
    for body, colour in zip(lines, series.palette(len(lines))):
        names = [f"{body}.{p}" for b, p in trajectory.points if b == body]
        figure.add_trace(go.Scatter3d(
            mode="lines+markers", name=body, text=names, hoverinfo="text+x+y+z",
            line={"width": BODY_WIDTH, "color": colour},
            marker={"size": 5, "color": "black", "symbol": "circle"}))
        moving.append(len(figure.data) - 1)
    names, points, forces = reactions(trajectory, outlines)
    scale = force_scale(forces, _span(lines))
    force_unit = units.loads()[0]
    for name in names:
        # Wider than a body's line and dashed, with a large head: an arrow that runs along
        # its body's line (a rod pulled or pushed along itself) still shows over it.
        figure.add_trace(go.Scatter3d(
            mode="lines+markers", name="joint reactions (i on j)",
            legendgroup="reactions", showlegend=name == names[0],
            hovertemplate=(f"{name} reaction: F = (%{{customdata[0]:.4g}}, "
                           f"%{{customdata[1]:.4g}}, %{{customdata[2]:.4g}}) {force_unit}"
                           "<extra></extra>"),
            line={"width": ARROW_WIDTH, "color": REACTION, "dash": "dash"},
            marker={"size": [0, 9], "color": REACTION, "symbol": "diamond",
                    "line": {"width": 1, "color": "black"}}))
        moving.append(len(figure.data) - 1)
    cursors = _columns(go, figure, trajectory, units)
    built = [go.Frame(name=f"{float(trajectory.t[k]):.6g}", traces=moving + list(cursors),
                      data=[*(_at(go, shape[k]) for shape in lines.values()),
                            *_arrows(go, points[k], forces[k], scale),
                            *(go.Scatter(x=[trajectory.t[k]] * 2, y=list(extent))
                              for extent in cursors.values())])
             for k in frames]
    figure.frames = built
    for index, trace in zip(built[0].traces, built[0].data):
        figure.data[index].x, figure.data[index].y = trace.x, trace.y
        if index in moving:
            figure.data[index].z = trace.z
    _layout(figure, trajectory, frames, lines, units, title)
    return page.write(figure, path)


def _side_columns(trajectory: Trajectory) -> tuple[str, ...]:
    """The columns of panels beside the scene: ``forces`` (with masses or forces,
    :mod:`symkin.present.html_forces`), then ``energy`` (a run its forces move,
    :mod:`symkin.present.html_energy`)."""
    from symkin.present import html_energy

    return tuple(name for name, shown in (("forces", trajectory.forces is not None),
                                          ("energy", html_energy.energies(trajectory)
                                           is not None)) if shown)


def _figure(go: Any, trajectory: Trajectory) -> Any:
    """The empty figure: the scene alone, or the scene beside its side columns (three panels
    each, sharing the time axis)."""
    side = _side_columns(trajectory)
    if not side:
        return go.Figure()
    from plotly.subplots import make_subplots

    panels: list[dict[str, Any]] = [{} for _ in side]
    specs = [[{"type": "scene", "rowspan": 3}, *panels], [None, *panels], [None, *panels]]
    widths = [0.62, 0.38] if len(side) == 1 else [0.5, 0.25, 0.25]
    return make_subplots(rows=3, cols=1 + len(side), specs=specs, shared_xaxes=True,
                         column_widths=widths, horizontal_spacing=0.08,
                         vertical_spacing=0.06)


def _columns(go: Any, figure: Any, trajectory: Trajectory, units: Units
             ) -> dict[int, tuple[float, float]]:
    """The side columns' curves (columns 2 on); returns each time cursor's trace index and
    the y range it spans (none without side columns)."""
    from symkin.present import html_energy, html_forces

    cursors = []
    for column, name in enumerate(_side_columns(trajectory), start=2):
        if name == "forces":
            cursors += html_forces.plot(go, figure, trajectory, column=column)
            html_forces.label(figure, column, units, spatial=True)
        else:
            cursors += html_energy.plot(go, figure, trajectory, column)
            html_energy.label(figure, column, units)
    return {index: html_forces.panel_range(figure, index) for index, _, _ in cursors}


def _span(lines: dict[str, Array]) -> float:
    low, high = _bounds(lines)
    return max(float(np.max(high - low)), 1e-9)


def _arrows(go: Any, points: Array, forces: Array, scale: float) -> list[Any]:
    """Each joint's arrow at one time: from its point along its force (J, 3), scaled; the
    unscaled force rides along as customdata."""
    found = []
    for point, force in zip(points, forces):
        ends = np.stack([point, point + scale * force])
        found.append(go.Scatter3d(x=ends[:, 0], y=ends[:, 1], z=ends[:, 2],
                                  customdata=[force, force]))
    return found


def _moves(track: Array) -> bool:
    """Whether a point's (T, 3) positions change (NaN rows of a partial run ignored)."""
    solved = track[np.all(np.isfinite(track), axis=1)]
    if solved.shape[0] < 2:
        return False
    return bool(np.ptp(solved, axis=0).max() > 1e-12 * max(1.0, float(np.abs(solved).max())))


def _at(go: Any, points: Array) -> Any:
    ring = closed(points)
    return go.Scatter3d(x=ring[:, 0], y=ring[:, 1], z=ring[:, 2])


def closed(points: Array) -> Array:
    """A body's (n, d) points as drawn: a closed polygon when it has more than two, so that a
    plate (a Stewart platform's six attachments) reads as one body."""
    return np.vstack([points, points[:1]]) if len(points) > 2 else points


def _layout(figure: Any, trajectory: Trajectory, frames: Array, lines: dict[str, Array],
            units: Units, title: str) -> None:
    low, high = _bounds(lines)
    # One cube around the mechanism, so that lengths look the same along every axis.
    centre, half = (low + high) / 2, 0.55 * max(float(np.max(high - low)), 1e-9)
    unit = f" [{units.length}]" if units.length else ""
    axes = {f"{axis}axis": {"range": [centre[k] - half, centre[k] + half],
                            "title": {"text": f"{axis}{unit}"}}
            for k, axis in enumerate("xyz")}
    figure.update_layout(
        title={"text": f"{title}: {trajectory.t.size} time points, t = "
                       f"{trajectory.t[0]:.4g} to {trajectory.t[-1]:.4g} "
                       "(drag to turn the view)"},
        height=760, template="plotly_white",
        scene={**axes, "aspectmode": "cube",
               "camera": {"up": {"x": 0, "y": 0, "z": 1},
                          "eye": {"x": 1.5, "y": -1.5, "z": 1.0}}},
        legend={"x": 1.0, "y": 1.0, "xanchor": "left", "yanchor": "top"},
        margin={"t": 60, "b": 110},
        **page.time_controls(trajectory, frames, units, redraw=True, y=0.0))


# --- the GIF ---------------------------------------------------------------------------------


def animate(trajectory: Trajectory, path: str | Path, fps: int = 20,
            size: tuple[int, int] = DEFAULT_SIZE, progress: Progress | None = None,
            outlines: Outlines | None = None) -> Path:
    """Write a GIF of the spatial mechanism moving, in isometric projection (z up).

    Args:
        trajectory: the solved spatial run.
        path: the .gif to write.
        fps: frames per second; at most MAX_FRAMES frames are drawn, evenly spaced.
        size: width and height in pixels.
        progress: called as progress(frames done, frames) while frames are drawn.
        outlines: the joints' points, where the reaction arrows are drawn (see
            :func:`report`).
    """
    if trajectory.t.size == 0:
        raise SymkinError("nothing to animate: no time point was solved")
    if not 1 <= fps <= 100:
        raise UsageError(f"--fps {fps}: give 1 to 100 frames per second")
    from PIL import Image

    from symkin.present.plots import _pyplot

    spatial_lines = _drawable(trajectory)
    lines = {body: isometric(points) for body, points in spatial_lines.items()}
    _, points, forces = reactions(trajectory, outlines)
    # the arrows scaled in space, then projected (the projection is linear)
    tails, heads = isometric(points), isometric(force_scale(forces, _span(spatial_lines)) * forces)
    plt = _pyplot()
    figure, ax = plt.subplots(figsize=(size[0] / DPI, size[1] / DPI), dpi=DPI,
                              layout="constrained")
    try:
        drawn = _projected_scene(ax, trajectory, lines)
        arrows = _projected_arrows(ax, tails, heads)
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small")
        frames = frame_indices(trajectory)
        images = []
        for done, k in enumerate(frames, start=1):
            for body, line in drawn.items():
                line.set_data(*closed(lines[body][k]).T)
            if arrows is not None:
                arrows.set_offsets(tails[k])
                arrows.set_UVC(heads[k, :, 0], heads[k, :, 1])
            ax.set_title(f"t = {trajectory.t[k]:.4g} (isometric view, z up)")
            figure.canvas.draw()
            rgb = Image.fromarray(np.asarray(figure.canvas.buffer_rgba())).convert("RGB")
            images.append(rgb.quantize(method=Image.Quantize.FASTOCTREE,
                                       dither=Image.Dither.NONE))
            if progress is not None:
                progress(done, frames.size)
    finally:
        plt.close(figure)
    path = Path(path)
    with outfiles.replacing(path) as temporary:
        images[0].save(temporary, save_all=True, append_images=images[1:],
                       duration=round(1000 / fps), loop=0)
    return path


def _projected_scene(ax: Any, trajectory: Trajectory, lines: dict[str, Array]) -> dict[str, Any]:
    """Axes, projected coordinate axes, point paths; returns the line of each body."""
    every = np.concatenate([a.reshape(-1, 2) for a in lines.values()] + [np.zeros((1, 2))])
    every = every[np.all(np.isfinite(every), axis=1)]
    low, high = every.min(axis=0), every.max(axis=0)
    span = max(float(np.max(high - low)), 1e-9)
    margin = 0.12 * span
    ax.set_xlim(low[0] - margin, high[0] + margin)
    ax.set_ylim(low[1] - margin, high[1] + margin)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xticks([])
    ax.set_yticks([])
    # The global axes at the origin, a fifth of the picture long, so the view can be read.
    for k, label in enumerate("xyz"):
        tip = isometric(np.eye(3)[k] * 0.2 * span)
        ax.annotate("", xy=tuple(tip), xytext=(0.0, 0.0),
                    arrowprops={"arrowstyle": "->", "color": "0.5"})
        ax.text(*(1.12 * tip), label, color="0.4", ha="center", va="center")
    for points in lines.values():
        for k in range(points.shape[1]):
            ax.plot(points[:, k, 0], points[:, k, 1], ":", linewidth=0.8, color="0.5")
    return {body: ax.plot([], [], "o-", linewidth=3, markersize=5, color=colour,
                          markerfacecolor="black", label=body)[0]
            for body, colour in zip(lines, series.palette(len(lines)))}


def _projected_arrows(ax: Any, tails: Array, heads: Array) -> Any:
    """The reaction arrows' artist at the first frame (tails and projected forces, each
    (T, J, 2)), and their legend entry; None without forces."""
    if tails.shape[1] == 0:
        return None
    ax.plot([], [], "-", color=REACTION, linewidth=2, label="joint reactions (i on j)")
    return ax.quiver(tails[0, :, 0], tails[0, :, 1], heads[0, :, 0], heads[0, :, 1],
                     angles="xy", scale_units="xy", scale=1.0, color=REACTION,
                     width=0.004, zorder=4)
