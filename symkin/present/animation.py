"""Stage 7 — the mechanism moving: a GIF with every body, ground pivot and slide axis.

Bodies are drawn as polygons through the local vectors of their joints and points
(``outlines``, from :func:`symkin.symbolic.drawing.outlines`), so what moves on screen is what
the constraints hold together. Ground pivots are drawn as hatched triangles, slide axes as
dash-dotted lines through the whole picture; the legend stands to the right of the mechanism.
With masses or forces, each joint's reaction (body i on body j) is an arrow at its point on
body i, the largest of the run VECTOR_SHARE of the picture long, as in the HTML report.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin import outfiles
from symkin.errors import SymkinError, UsageError
from symkin.present import series
from symkin.present.placement import (
    GROUND,
    REACTION,
    VECTOR_SHARE,
    Outlines,
    global_vectors,
    joint_points,
)
from symkin.runtime.outputs.results import Trajectory

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]

MAX_FRAMES = 200
DEFAULT_SIZE = (900, 600)  # pixels
DPI = 100


def body_shapes(trajectory: Trajectory, outlines: Outlines) -> dict[str, Array]:
    """Global positions of each body's outline vertices, each shape (T, K, 2) (2.14)."""
    shapes = {}
    for body in trajectory.bodies:
        local = np.asarray(outlines.get(body, np.zeros((1, 2))), dtype=float).reshape(-1, 2)
        shapes[body] = global_vectors(trajectory, body, local)
    return shapes


def slide_axes(trajectory: Trajectory, outlines: Outlines) -> list[tuple[Array, Array]]:
    """Every slide axis as (point, unit direction), each (T, 2), in the global frame."""
    axes = []
    for key, rows in outlines.items():
        if not key.startswith("slide:"):
            continue
        body = key.split(":", 1)[1]
        rows = np.asarray(rows, dtype=float).reshape(-1, 2)
        if body != GROUND and body not in trajectory.bodies:
            continue
        for point, direction in zip(rows[0::2], rows[1::2]):
            norm = float(np.hypot(*direction))
            if norm == 0:
                continue
            at = global_vectors(trajectory, body, point[None])[:, 0]
            turned = global_vectors(trajectory, body, np.array([point + direction / norm]))[:, 0]
            axes.append((at, turned - at))
    return axes


def rods(trajectory: Trajectory, outlines: Outlines) -> list[tuple[Array, Array]]:
    """Every rod with no body of its own (a distance constraint) as its two ends, each (T, 2),
    in the global frame: the keys ``rod:<body i>:<body j>`` hold rows end on i, end on j."""
    found = []
    for key, rows in outlines.items():
        if not key.startswith("rod:"):
            continue
        first, second = key.split(":")[1:3]
        if not all(body == GROUND or body in trajectory.bodies for body in (first, second)):
            continue
        rows = np.asarray(rows, dtype=float).reshape(-1, 2)
        for a, b in zip(rows[0::2], rows[1::2]):
            found.append((global_vectors(trajectory, first, a[None])[:, 0],
                          global_vectors(trajectory, second, b[None])[:, 0]))
    return found


def marks(trajectory: Trajectory, outlines: Outlines) -> list[tuple[str, Array]]:
    """The higher pairs' marks (``curve:<body>:<label>:<k>``: pitch circles, rack lines,
    curves, cam profiles) as (label, polyline (T, K, 2)) in the global frame."""
    found = []
    for key, rows in outlines.items():
        if not key.startswith("curve:"):
            continue
        body, label = key.split(":")[1:3]
        if body != GROUND and body not in trajectory.bodies:
            continue
        local = np.asarray(rows, dtype=float).reshape(-1, 2)
        found.append((label, global_vectors(trajectory, body, local)))
    return found


def contacts(trajectory: Trajectory, outlines: Outlines) -> list[tuple[str, Array]]:
    """The contact points to mark, as (label, (T, 2) global): each gear pair's pitch point
    (outlines ``pitch:<i>:<j>:<k>``: r_i from i's frame origin along the line to j's, away
    from it for a ring, r_j < 0), then each pair's reported ``NAME.contact_x`` and
    ``NAME.contact_y`` (a cam's contact, a point on its curve)."""
    found = []
    for key, rows in outlines.items():
        if not key.startswith("pitch:"):
            continue
        i, j = key.split(":")[1:3]
        if not all(body == GROUND or body in trajectory.bodies for body in (i, j)):
            continue
        ri, rj = np.asarray(rows, dtype=float).reshape(-1, 2)[0]
        centre_i, centre_j = (global_vectors(trajectory, body, np.zeros((1, 2)))[:, 0]
                              for body in (i, j))
        line = centre_j - centre_i
        with np.errstate(all="ignore"):
            towards = line / np.hypot(*line.T)[:, None] * math.copysign(1.0, rj)
        found.append(("pitch point", centre_i + ri * towards))
    reported = dict(trajectory.outputs)
    for name, x in reported.items():
        if name.endswith(".contact_x") and name[:-1] + "y" in reported:
            found.append((f"contact {name[:-len('.contact_x')]}",
                          np.column_stack([x, reported[name[:-1] + "y"]])))
    return found


def parse_size(text: str) -> tuple[int, int]:
    """``"900x600"`` -> (900, 600), pixels; UsageError for anything else."""
    width, _, height = text.lower().partition("x")
    try:
        size = (int(width), int(height))
    except ValueError:
        size = (0, 0)
    if not (100 <= size[0] <= 4000 and 100 <= size[1] <= 4000):
        raise UsageError(f"--size {text}: give WIDTHxHEIGHT in pixels, each 100 to 4000, "
                         "e.g. 900x600")
    return size


def animate(trajectory: Trajectory, path: str | Path, outlines: Outlines, fps: int = 20,
            size: tuple[int, int] = DEFAULT_SIZE, progress: Progress | None = None) -> Path:
    """Write a GIF of the mechanism moving, with the traces of its moving named points.

    Args:
        trajectory: the solved run.
        path: the .gif to write.
        outlines: per body, the local vectors to draw it through; ``ground`` pivots and
            ``slide:<body>`` axes, ``rod:<i>:<j>`` rods (see
            :func:`symkin.symbolic.drawing.outlines`).
        fps: frames per second; at most MAX_FRAMES frames are drawn, evenly spaced.
        size: width and height in pixels.
        progress: called as progress(frames done, frames) while frames are drawn.
    """
    if trajectory.spatial:  # no planar outlines: an isometric view of the points
        from symkin.present import view3d

        return view3d.animate(trajectory, path, fps, size, progress, outlines)
    if trajectory.t.size == 0:
        raise SymkinError("nothing to animate: no time point was solved")
    if not 1 <= fps <= 100:
        raise UsageError(f"--fps {fps}: give 1 to 100 frames per second")
    from PIL import Image

    from symkin.present.plots import _pyplot

    plt = _pyplot()
    scene = _Scene(plt, trajectory, outlines, size)
    frames = np.unique(np.linspace(0, trajectory.t.size - 1, MAX_FRAMES).astype(int))
    images = []
    try:
        for done, k in enumerate(frames, start=1):
            rgb = Image.fromarray(scene.render(int(k))).convert("RGB")
            # A fast octree palette per frame: median cut took ten times longer.
            images.append(rgb.quantize(method=Image.Quantize.FASTOCTREE,
                                       dither=Image.Dither.NONE))
            if progress is not None:
                progress(done, frames.size)
    finally:
        plt.close(scene.figure)
    path = Path(path)
    with outfiles.replacing(path) as temporary:
        images[0].save(temporary, save_all=True, append_images=images[1:],
                       duration=round(1000 / fps), loop=0)
    return path


class _Scene:
    """The figure of an animation and the artists that move."""

    def __init__(self, plt: Any, trajectory: Trajectory, outlines: Outlines,
                 size: tuple[int, int]) -> None:
        self.trajectory = trajectory
        self.figure, ax = plt.subplots(figsize=(size[0] / DPI, size[1] / DPI), dpi=DPI,
                                       layout="constrained")
        self.ax = ax
        self.shapes = body_shapes(trajectory, outlines)
        self.slides = slide_axes(trajectory, outlines)
        self.rods = rods(trajectory, outlines)
        self.marks = marks(trajectory, outlines)
        self.contacts = contacts(trajectory, outlines)
        x0, x1, y0, y1 = _limits([*self.shapes.values(), _ground(outlines)[None],
                                  *(polyline for _, polyline in self.marks)])
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal", adjustable="box")
        ax.grid(True, linewidth=0.3, alpha=0.4)
        span = max(x1 - x0, y1 - y0)
        self.reach = 2 * span
        self.slide_lines = [ax.plot([], [], "-.", color="0.45", linewidth=0.9,
                                    label="slide axis" if k == 0 else None)[0]
                            for k in range(len(self.slides))]
        self.rod_lines = [ax.plot([], [], "o--", color="0.25", linewidth=1.5, markersize=3,
                                  label="rod" if k == 0 else None)[0]
                          for k in range(len(self.rods))]
        first = {label: k for k, (label, _) in reversed(list(enumerate(self.marks)))}
        self.mark_lines = [ax.plot([], [], "-", color="0.35", linewidth=0.9,
                                   label=label if first[label] == k else None)[0]
                           for k, (label, _) in enumerate(self.marks)]
        seen: set[str] = set()
        self.contact_dots = []
        for label, _ in self.contacts:
            self.contact_dots.append(ax.plot([], [], "x", color="crimson", markersize=7,
                                             markeredgewidth=1.6, label=None if label in seen
                                             else label)[0])
            seen.add(label)
        _pivots(ax, _ground(outlines), span)
        self.reactions, self.arrows = _reaction_arrows(ax, trajectory, outlines, span)
        colours = series.palette(len(self.shapes))
        self.lines = {body: ax.plot([], [], "o-", linewidth=3, markersize=4, color=colour,
                                    alpha=0.85, label=body)[0]
                      for body, colour in zip(self.shapes, colours)}
        self.traces = [(trajectory.point(b, p)[0], ax.plot([], [], ":", linewidth=1,
                                                             color="0.3")[0])
                       for b, p in trajectory.points if _moving_point(trajectory, b, p)]
        self.title = ax.set_title(" ")
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small",
                  borderaxespad=0.0)
        # Lay the figure out and draw what does not move once; each frame then restores that
        # background and draws only the moving artists (an order of magnitude faster than
        # drawing the whole figure per frame).
        self.moving = [*self.lines.values(), *(line for _, line in self.traces),
                       *self.slide_lines, *self.rod_lines, *self.mark_lines,
                       *self.contact_dots, self.title,
                       *([self.arrows] if self.arrows is not None else [])]
        for artist in self.moving:
            artist.set_animated(True)
        canvas = self.figure.canvas
        canvas.draw()
        self.figure.set_layout_engine("none")
        self.background = canvas.copy_from_bbox(self.figure.bbox)

    def render(self, k: int) -> NDArray[np.uint8]:
        """The picture at time index k as an RGBA array (height, width, 4)."""
        self.show(k)
        canvas = self.figure.canvas
        canvas.restore_region(self.background)
        for artist in self.moving:
            self.figure.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba()).copy()

    def show(self, k: int) -> None:
        for body, line in self.lines.items():
            line.set_data(*_closed(self.shapes[body][k]).T)
        for trace, line in self.traces:
            line.set_data(trace[:k + 1, 0], trace[:k + 1, 1])
        for (at, direction), line in zip(self.slides, self.slide_lines):
            ends = at[k] + np.outer([-self.reach, self.reach], direction[k])
            line.set_data(ends[:, 0], ends[:, 1])
        for (a, b), line in zip(self.rods, self.rod_lines):
            line.set_data([a[k, 0], b[k, 0]], [a[k, 1], b[k, 1]])
        for (_, polyline), line in zip(self.marks, self.mark_lines):
            line.set_data(polyline[k, :, 0], polyline[k, :, 1])
        if self.arrows is not None:
            points, vectors = self.reactions
            self.arrows.set_offsets(points[k])
            self.arrows.set_UVC(vectors[k, :, 0], vectors[k, :, 1])
        for (_, point), dot in zip(self.contacts, self.contact_dots):
            dot.set_data(point[k, :1], point[k, 1:])
        self.title.set_text(f"t = {self.trajectory.t[k]:.4g}")


def _reaction_arrows(ax: Any, trajectory: Trajectory, outlines: Outlines, span: float
                     ) -> tuple[tuple[Array, Array], Any]:
    """The joints' points (T, J, 2) and their reactions scaled to picture lengths (T, J, 2)
    (NaN rows drawn as nothing), and the arrows' artist; (empty, None) without forces."""
    forces = trajectory.forces
    where = joint_points(trajectory, outlines) if forces is not None else {}
    shown = [k for k, name in enumerate(forces.joint_names) if name in where] if forces else []
    if forces is None or not shown:
        return (np.zeros((0, 0, 2)), np.zeros((0, 0, 2))), None
    points = np.stack([where[forces.joint_names[k]] for k in shown], axis=1)
    vectors = np.nan_to_num(forces.reaction[:, shown, :2])
    largest = float(np.hypot(vectors[..., 0], vectors[..., 1]).max(initial=0.0))
    vectors = vectors * (VECTOR_SHARE * span / largest if largest > 0 else 0.0)
    arrows = ax.quiver(points[0, :, 0], points[0, :, 1], vectors[0, :, 0], vectors[0, :, 1],
                       angles="xy", scale_units="xy", scale=1.0, color=REACTION,
                       width=0.004, zorder=4)
    ax.plot([], [], "-", color=REACTION, linewidth=2, label="joint reactions (i on j)")
    return (points, vectors), arrows


def _moving_point(trajectory: Trajectory, body: str, point: str) -> bool:
    r, _, _ = trajectory.point(body, point)
    return bool(np.ptp(r, axis=0).max() > 1e-12 * max(1.0, float(np.abs(r).max())))


def _ground(outlines: Outlines) -> Array:
    return np.asarray(outlines.get(GROUND, np.zeros((0, 2))), dtype=float).reshape(-1, 2)


def _pivots(ax: Any, points: Array, span: float) -> None:
    """A hatched triangle under every ground pivot (the usual sign for a fixed support)."""
    from matplotlib.patches import Polygon

    size = 0.04 * span
    for k, (x, y) in enumerate(points):
        triangle = np.array([[x, y], [x - size, y - 1.6 * size], [x + size, y - 1.6 * size]])
        ax.add_patch(Polygon(triangle, closed=True, facecolor="none", edgecolor="black",
                             hatch="////", linewidth=1.0, zorder=1,
                             label="ground pivot" if k == 0 else None))


def _limits(shapes: list[Array]) -> tuple[float, float, float, float]:
    every = np.concatenate([s.reshape(-1, 2) for s in shapes] + [np.zeros((1, 2))])
    low, high = every.min(axis=0), every.max(axis=0)
    margin = 0.1 * max(float(np.max(high - low)), 1e-9)
    return low[0] - margin, high[0] + margin, low[1] - 2 * margin, high[1] + margin


def _closed(vertices: Array) -> Array:
    """A polygon through the vertices, closed when it has more than two."""
    return np.vstack([vertices, vertices[:1]]) if len(vertices) > 2 else vertices
