"""Stage 7 — results, pictures: coordinates and point paths against time, and an animation.

matplotlib runs with the Agg backend (no display needed); the animation is a GIF written by
PillowWriter. Bodies are drawn as polygons through the local vectors of their joints and points
(``outlines``), so what moves on screen is what the constraints hold together.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.errors import SymkinError
from symkin.runtime.results import Trajectory, rotation

MAX_FRAMES = 200


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot(trajectory: Trajectory, path: str | Path,
         coordinates: Sequence[str] | None = None) -> Path:
    """Write a PNG: the chosen coordinates (default all) and every named point's x, y against t.

    Args:
        trajectory: the solved run (a partial one works too).
        path: the .png to write.
        coordinates: coordinate names to show, e.g. ("crank.phi", "slider.x").
    """
    chosen = list(coordinates or trajectory.coordinates)
    unknown = [name for name in chosen if name not in trajectory.coordinates]
    if unknown:
        raise SymkinError(f"cannot plot {', '.join(unknown)}: the coordinates are "
                          f"{', '.join(trajectory.coordinates)}")
    plt = _pyplot()
    panels = 2 if trajectory.points else 1
    figure, axes = plt.subplots(panels, 1, figsize=(8, 3.2 * panels), sharex=True,
                                squeeze=False)
    top = axes[0, 0]
    for name in chosen:
        top.plot(trajectory.t, trajectory.q[:, trajectory.coordinates.index(name)], label=name)
    top.set_ylabel("q")
    top.legend(fontsize="small", ncol=3)
    if trajectory.points:
        bottom = axes[1, 0]
        for body, point in trajectory.points:
            r, _, _ = trajectory.point(body, point)
            bottom.plot(trajectory.t, r[:, 0], label=f"{body}.{point} x")
            bottom.plot(trajectory.t, r[:, 1], "--", label=f"{body}.{point} y")
        bottom.set_ylabel("point position")
        bottom.legend(fontsize="small", ncol=2)
    axes[-1, 0].set_xlabel("t")
    figure.tight_layout()
    return _save(figure, plt, Path(path))


def _save(figure: Any, plt: Any, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return path


def body_shapes(trajectory: Trajectory, outlines: Mapping[str, NDArray[np.float64]]
                ) -> dict[str, NDArray[np.float64]]:
    """Global positions of each body's outline vertices, each shape (T, K, 2) (2.14)."""
    shapes = {}
    for body in trajectory.bodies:
        local = np.asarray(outlines.get(body, np.zeros((1, 2))), dtype=float).reshape(-1, 2)
        q, _, _ = trajectory.body(body)
        R = rotation(q[:, 2])  # (T, 2, 2)
        shapes[body] = q[:, None, :2] + np.einsum("tij,kj->tki", R, local)
    return shapes


def _limits(shapes: Mapping[str, NDArray[np.float64]]) -> tuple[float, float, float, float]:
    every = np.concatenate([s.reshape(-1, 2) for s in shapes.values()] + [np.zeros((1, 2))])
    low, high = every.min(axis=0), every.max(axis=0)
    margin = 0.1 * max(float(np.max(high - low)), 1e-9)
    return low[0] - margin, high[0] + margin, low[1] - margin, high[1] + margin


def animate(trajectory: Trajectory, path: str | Path,
            outlines: Mapping[str, NDArray[np.float64]], fps: int = 20) -> Path:
    """Write a GIF of the mechanism moving, with the traces of the named points.

    Args:
        trajectory: the solved run.
        path: the .gif to write.
        outlines: per body, the local vectors to draw it through (its joints and points).
        fps: frames per second; at most MAX_FRAMES frames are drawn, evenly spaced.
    """
    if trajectory.t.size == 0:
        raise SymkinError("nothing to animate: no time point was solved")
    plt = _pyplot()
    from matplotlib.animation import PillowWriter

    shapes = body_shapes(trajectory, outlines)
    traces = [trajectory.point(body, point)[0] for body, point in trajectory.points]
    frames = np.unique(np.linspace(0, trajectory.t.size - 1, MAX_FRAMES).astype(int))
    figure, ax = plt.subplots(figsize=(6, 5))
    x0, x1, y0, y1 = _limits(shapes)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.plot([0], [0], "k^", markersize=10)  # the ground origin
    lines = {body: ax.plot([], [], "o-", linewidth=3, label=body)[0] for body in shapes}
    trace_lines = [ax.plot([], [], ":", linewidth=1)[0] for _ in traces]
    title = ax.set_title("")
    ax.legend(loc="upper right", fontsize="small")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    writer = PillowWriter(fps=fps)
    with writer.saving(figure, str(path), dpi=80):
        for k in frames:
            for body, line in lines.items():
                line.set_data(*_closed(shapes[body][k]).T)
            for line, trace in zip(trace_lines, traces):
                line.set_data(trace[:k + 1, 0], trace[:k + 1, 1])
            title.set_text(f"t = {trajectory.t[k]:.4g}")
            writer.grab_frame()
    plt.close(figure)
    return path


def _closed(vertices: NDArray[np.float64]) -> NDArray[np.float64]:
    """A polygon through the vertices, closed when it has more than two."""
    return np.vstack([vertices, vertices[:1]]) if len(vertices) > 2 else vertices
