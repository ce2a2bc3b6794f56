"""Stage 7 — the interactive report: one self-contained HTML file a designer opens first.

The mechanism moves under a time slider (play / pause), with the paths of its points and the
velocity and acceleration vectors of the selected points; beside it, the selected quantities
against time, with a cursor at the slider's time. Drawing is done by plotly.js, whose minified
source ships inside the plotly Python package and is written into the file, so the report works
offline and needs nothing but a browser. plotly is an optional dependency (``symkin[html]``).

Every name in the figure comes from a validated file (identifiers) and is passed to the browser
as JSON data, never as markup.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.errors import UsageError
from symkin.present import html_energy, html_forces, page, series
from symkin.present.animation import (
    MAX_FRAMES,
    body_shapes,
    contacts,
    marks,
    rods,
    slide_axes,
)
from symkin.present.placement import Outlines, joint_points
from symkin.present.series import DEFAULT_UNITS, LENGTH, Units
from symkin.runtime.outputs.results import Trajectory

Array = NDArray[np.float64]
VECTOR_SHARE = 0.15  # the longest vector of the run drawn this long, relative to the picture
VELOCITY, ACCELERATION = "#d62728", "#1f77b4"
REACTION = "#2ca02c"  # joint reactions (inverse dynamics): body i on body j


def available() -> bool:
    """Whether the report can be drawn (plotly is installed), without importing it."""
    import importlib.util

    try:
        return importlib.util.find_spec("plotly") is not None
    except ValueError:  # a module entry without a spec (blocked or half-imported)
        return False


def _plotly() -> Any:
    from symkin.present.view3d import graph_objects

    return graph_objects()


def report(trajectory: Trajectory, path: str | Path, outlines: Outlines,
           select: Sequence[str] | None = None, units: Units = DEFAULT_UNITS,
           title: str = "symkin") -> Path:
    """Write the interactive report.

    Args:
        trajectory: the solved run (a partial one works too).
        path: the .html file to write.
        outlines: what :func:`symkin.symbolic.drawing.outlines` gives (bodies, ground
            pivots, slide axes, rods).
        select: the quantities to plot (coordinates and named points); default
            :func:`series.default_selection`. Vectors are drawn at the selected points.
        units: labels from the file's ``units`` key.
        title: the page's title, e.g. the mechanism's name.
    """
    if trajectory.spatial:  # no planar outlines: the 3D view draws from the points alone
        from symkin.present import view3d

        return view3d.report(trajectory, path, units, title, outlines)
    path = Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise UsageError(f"cannot write a report to {path.name}: use a file ending in .html")
    if trajectory.t.size == 0:
        raise UsageError("nothing to report: no time point was solved")
    go = _plotly()
    from plotly.subplots import make_subplots

    chosen = series.check_selection(select, trajectory.coordinates, trajectory.points) \
        if select is not None else series.default_selection(trajectory)
    curves = series.curves(trajectory, chosen, units)
    columns = series.kinds(curves)
    # with masses or forces, one more column: efforts and reactions (present.html_forces)
    forces = [] if trajectory.forces is None else [2 + len(columns)]
    # a run its forces integrated (runtime.dynamics): the energies (present.html_energy)
    energy = ([] if html_energy.energies(trajectory) is None
              else [2 + len(columns) + len(forces)])
    panel: list[dict[str, Any] | None] = [{} for _ in [*columns, *forces, *energy]]
    specs: list[list[dict[str, Any] | None]] = [[{"rowspan": 3}, *panel]]
    specs += [[None, *panel] for _ in range(2)]
    figure = make_subplots(
        rows=3, cols=1 + len(panel), specs=specs, shared_xaxes=True,
        column_widths=[0.5] + [0.5 / len(panel)] * len(panel),
        horizontal_spacing=0.07, vertical_spacing=0.06)
    frames = np.unique(np.linspace(0, trajectory.t.size - 1, MAX_FRAMES).astype(int))
    scene = _Scene(trajectory, outlines, [c.name for c in curves if c.kind == LENGTH
                                          and len(c.components) == 2], units)
    moving = scene.static(go, figure)
    cursors = _plots(go, figure, trajectory, curves, columns, units)
    for column in forces:
        cursors += html_forces.plot(go, figure, trajectory, column)
        html_forces.label(figure, column, units)
    for column in energy:
        cursors += html_energy.plot(go, figure, trajectory, column)
        html_energy.label(figure, column, units)
    _animate(go, figure, trajectory, frames, scene, moving, cursors)
    _layout(figure, trajectory, frames, scene, columns, units, title)
    return page.write(figure, path)


class _Scene:
    """The mechanism's view: bodies, pivots, slide axes, paths and vectors."""

    def __init__(self, trajectory: Trajectory, outlines: Outlines, points: Sequence[str],
                 units: Units) -> None:
        self.trajectory = trajectory
        self.shapes = body_shapes(trajectory, outlines)
        self.slides = slide_axes(trajectory, outlines)
        self.rods = rods(trajectory, outlines)
        self.marks = marks(trajectory, outlines)
        self.contacts = contacts(trajectory, outlines)
        self.ground = np.asarray(outlines.get("ground", np.zeros((0, 2))), float).reshape(-1, 2)
        self.points = list(points)
        every = np.concatenate([s.reshape(-1, 2) for s in self.shapes.values()]
                               + [p.reshape(-1, 2) for _, p in self.marks]
                               + [self.ground, np.zeros((1, 2))])
        self.low, self.high = every.min(axis=0), every.max(axis=0)
        self.span = max(float(np.max(self.high - self.low)), 1e-9)
        self.kinematics = {name: trajectory.point(*name.rsplit(".", 1)) for name in points}
        self.scales = {order: self._scale(order) for order in (1, 2)}
        self.units = units
        # inverse dynamics: each joint's reaction (on body j) drawn at its point on body i
        self.reactions = self._reactions(trajectory, outlines)

    def _reactions(self, trajectory: Trajectory, outlines: Outlines
                   ) -> list[tuple[str, Array, Array]]:
        forces = trajectory.forces
        if forces is None:
            return []
        where = joint_points(trajectory, outlines)
        found = [(name, where[name], forces.reaction[:, k, :2])
                 for k, name in enumerate(forces.joint_names) if name in where]
        largest = max([float(np.nanmax(np.hypot(*f.T), initial=0.0)) for _, _, f in found]
                      + [0.0])
        self.force_scale = VECTOR_SHARE * self.span / largest if largest > 0 else 0.0
        return found

    def _scale(self, order: int) -> float:
        """Picture length per unit of velocity (order 1) or acceleration (order 2)."""
        largest = max([float(np.nanmax(np.hypot(*k[order].T))) for k in
                       self.kinematics.values()] + [0.0])
        return VECTOR_SHARE * self.span / largest if largest > 0 else 0.0

    def static(self, go: Any, figure: Any) -> list[int]:
        """Add the traces; returns the indices of those that move (in frame order)."""
        for name, (r, _, _) in self.kinematics.items():
            figure.add_trace(go.Scatter(x=r[:, 0], y=r[:, 1], mode="lines", name=f"path {name}",
                                        line={"dash": "dot", "width": 1, "color": "#555"},
                                        legendgroup="paths", showlegend=False,
                                        hoverinfo="skip"), row=1, col=1)
        if self.ground.size:
            figure.add_trace(go.Scatter(
                x=self.ground[:, 0], y=self.ground[:, 1], mode="markers", name="ground pivot",
                marker={"symbol": "triangle-up-open", "size": 16, "color": "black",
                        "line": {"width": 2}}), row=1, col=1)
        moving = []
        colours = series.palette(len(self.shapes))
        for (body, _), colour in zip(self.shapes.items(), colours):
            moving.append(self._add(figure, go.Scatter(
                mode="lines+markers", name=body, line={"width": 4, "color": colour},
                marker={"size": 6}, fill="toself", fillcolor=_translucent(colour))))
        for k in range(len(self.slides)):
            moving.append(self._add(figure, go.Scatter(
                mode="lines", name="slide axis", showlegend=k == 0, legendgroup="slide",
                line={"dash": "dashdot", "width": 1, "color": "#777"}, hoverinfo="skip")))
        for k in range(len(self.rods)):
            moving.append(self._add(figure, go.Scatter(
                mode="lines+markers", name="rod", showlegend=k == 0, legendgroup="rods",
                line={"dash": "dash", "width": 2, "color": "#444"}, marker={"size": 4})))
        shown: set[str] = set()
        for label, _ in self.marks:
            moving.append(self._add(figure, go.Scatter(
                mode="lines", name=label, showlegend=label not in shown, legendgroup=label,
                line={"width": 1, "color": "#555"}, hoverinfo="skip")))
            shown.add(label)
        for label, _ in self.contacts:
            moving.append(self._add(figure, go.Scatter(
                mode="markers", name=label, showlegend=label not in shown, legendgroup=label,
                marker={"symbol": "x", "size": 10, "color": "crimson"})))
            shown.add(label)
        for order, colour, word in ((1, VELOCITY, "velocity"), (2, ACCELERATION,
                                                                "acceleration")):
            unit = self.units.unit(LENGTH, order)
            label = f"{word} vectors" + (f" ({unit})" if unit else "")
            for k, name in enumerate(self.points):
                moving.append(self._add(figure, go.Scatter(
                    mode="lines+markers", name=label, legendgroup=word, showlegend=k == 0,
                    line={"width": 2, "color": colour},
                    marker={"symbol": "arrow", "angleref": "previous", "size": [0, 11],
                            "color": colour},
                    hovertemplate=f"{name} {word}<extra></extra>")))
        for k, (name, _, _) in enumerate(self.reactions):
            moving.append(self._add(figure, go.Scatter(
                mode="lines+markers", name="joint reactions (i on j)", legendgroup="reactions",
                showlegend=k == 0, line={"width": 2, "color": REACTION},
                marker={"symbol": "arrow", "angleref": "previous", "size": [0, 11],
                        "color": REACTION},
                hovertemplate=f"{name} reaction<extra></extra>")))
        return moving

    @staticmethod
    def _add(figure: Any, trace: Any) -> int:
        figure.add_trace(trace, row=1, col=1)
        return len(figure.data) - 1

    def at(self, go: Any, k: int) -> list[Any]:
        """The moving traces at time index k, in the order :meth:`static` added them."""
        data = [go.Scatter(x=_closed(s[k])[:, 0], y=_closed(s[k])[:, 1])
                for s in self.shapes.values()]
        for at, direction in self.slides:
            ends = at[k] + np.outer([-2 * self.span, 2 * self.span], direction[k])
            data.append(go.Scatter(x=ends[:, 0], y=ends[:, 1]))
        for a, b in self.rods:
            data.append(go.Scatter(x=[a[k, 0], b[k, 0]], y=[a[k, 1], b[k, 1]]))
        for _, polyline in self.marks:
            data.append(go.Scatter(x=polyline[k, :, 0], y=polyline[k, :, 1]))
        for _, point in self.contacts:
            data.append(go.Scatter(x=point[k, :1], y=point[k, 1:]))
        for order in (1, 2):
            for name in self.points:
                r, tip = self.kinematics[name][0][k], self.kinematics[name][order][k]
                end = r + self.scales[order] * tip
                data.append(go.Scatter(x=[r[0], end[0]], y=[r[1], end[1]],
                                       customdata=[tip, tip]))
        for _, point, force in self.reactions:
            r, end = point[k], point[k] + self.force_scale * force[k]
            data.append(go.Scatter(x=[r[0], end[0]], y=[r[1], end[1]],
                                   customdata=[force[k], force[k]]))
        return data


def _plots(go: Any, figure: Any, trajectory: Trajectory, curves: Sequence[series.Curve],
           columns: Sequence[str], units: Units) -> list[tuple[int, int, int]]:
    """The quantities against time; returns each panel's (trace index, row, col) of its cursor."""
    cursors = []
    for column, kind in enumerate(columns, start=2):
        for order in range(3):
            for curve in curves:
                if curve.kind != kind:
                    continue
                for k, part in enumerate(curve.components):
                    figure.add_trace(go.Scatter(
                        x=trajectory.t, y=curve.values[order][:, k], mode="lines",
                        name=curve.name if k == 0 else f"{curve.name} {part}",
                        legendgroup=curve.name, showlegend=order == 0 and k == 0,
                        line={"color": curve.colour, "dash": "dash" if part == "y" else "solid",
                              "width": 1.5}), row=order + 1, col=column)
            figure.add_trace(go.Scatter(x=[], y=[], mode="lines", showlegend=False,
                                        hoverinfo="skip", line={"color": "black", "width": 1}),
                             row=order + 1, col=column)
            cursors.append((len(figure.data) - 1, order, column))
    return cursors


def _animate(go: Any, figure: Any, trajectory: Trajectory, frames: Array, scene: _Scene,
             moving: list[int], cursors: list[tuple[int, int, int]]) -> None:
    """One plotly frame per shown time: the moving traces and the time cursors."""
    bounds = {index: html_forces.panel_range(figure, index) for index, _, _ in cursors}
    built = []
    for k in frames:
        t = float(trajectory.t[k])
        data = scene.at(go, int(k)) + [go.Scatter(x=[t, t], y=list(bounds[index]))
                                       for index, _, _ in cursors]
        built.append(go.Frame(data=data, name=f"{t:.6g}",
                              traces=moving + [index for index, _, _ in cursors]))
    figure.frames = built
    first = built[0]
    for index, trace in zip(first.traces, first.data):
        figure.data[index].x, figure.data[index].y = trace.x, trace.y


def _layout(figure: Any, trajectory: Trajectory, frames: Array, scene: _Scene,
            columns: Sequence[str], units: Units, title: str) -> None:
    margin = 0.1 * scene.span
    figure.update_xaxes(range=[scene.low[0] - margin, scene.high[0] + margin],
                        title_text=f"x [{units.length}]" if units.length else "x", row=1, col=1)
    figure.update_yaxes(range=[scene.low[1] - 2 * margin, scene.high[1] + margin],
                        scaleanchor="x", scaleratio=1,
                        title_text=f"y [{units.length}]" if units.length else "y", row=1, col=1)
    for column, kind in enumerate(columns, start=2):
        for order in range(3):
            figure.update_yaxes(title_text=units.axis_label(kind, order), row=order + 1,
                                col=column)
        figure.update_xaxes(title_text=units.time_label(), row=3, col=column)
    figure.update_layout(
        title={"text": f"{title}: {trajectory.t.size} time points, t = "
                       f"{trajectory.t[0]:.4g} to {trajectory.t[-1]:.4g}"
                       + (" (points: x solid, y dashed)" if scene.points else "")},
        height=760, template="plotly_white", hovermode="closest",
        legend={"x": 1.02, "y": 1.0, "xanchor": "left", "yanchor": "top",
                "font": {"size": 11}, "groupclick": "togglegroup"},
        margin={"t": 60, "b": 110, "r": 40},
        **page.time_controls(trajectory, frames, units, redraw=False, y=-0.02))


def _translucent(colour: str) -> str:
    """``#rrggbb`` as a light fill: rgba with alpha 0.25."""
    red, green, blue = (int(colour[k:k + 2], 16) for k in (1, 3, 5))
    return f"rgba({red},{green},{blue},0.25)"


def _closed(vertices: Array) -> Array:
    return np.vstack([vertices, vertices[:1]]) if len(vertices) > 2 else vertices
