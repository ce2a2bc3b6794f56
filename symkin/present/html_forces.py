"""Stage 7 — the HTML report's efforts and reactions against time (a file with masses or
forces): one more column of three panels beside the kinematics', as ``run_forces.png`` has
them: each driver's effort, each joint's force magnitude |F| = sqrt(Fx² + Fy²), and the
moments of the joints that carry one (a spatial run: |F| of [Fx, Fy, Fz] and the moment's
magnitude |M| of [Mx, My, Mz]). Where rows were removed as redundant, a curve that is
not unique (the minimum-norm solution's) is dotted and its name says ``min-norm``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.present import series
from symkin.present.series import Units
from symkin.runtime.outputs.results import Trajectory

Array = NDArray[np.float64]
MOMENT_FLOOR = 1e-9
"""A joint's moment is plotted when it exceeds this much of the largest force (not a
revolute's zero)."""


@dataclass(frozen=True)
class ForceCurve:
    """One curve of the column: its panel (0 effort, 1 |F|, 2 M), name and values (T,)."""

    panel: int
    name: str
    values: Array
    determinate: bool


def force_curves(trajectory: Trajectory) -> list[ForceCurve]:
    """The curves of the efforts and reactions, in panel order; none without forces."""
    forces = trajectory.forces
    if forces is None:
        return []
    known = forces.determinate
    fixed = np.ones(len(forces.columns()), dtype=bool) if known is None else known
    efforts = len(forces.driver_names)
    found = [ForceCurve(0, name, forces.effort[:, k], bool(fixed[k]))
             for k, name in enumerate(forces.driver_names)]
    width = len(forces.parts)
    force, moments = _magnitudes(forces.reaction)
    floor = MOMENT_FLOOR * max(float(np.nanmax(force, initial=0.0)), 1.0)
    for k, name in enumerate(forces.joint_names):
        parts = fixed[efforts + width * k:efforts + width * (k + 1)]
        split = 3 if width == 6 else 2  # the force components, then the moment
        found.append(ForceCurve(1, name, force[:, k], bool(parts[:split].all())))
        moment = moments[:, k]
        if float(np.nanmax(np.abs(moment), initial=0.0)) > floor:
            found.append(ForceCurve(2, name, moment, bool(parts[split:].all())))
    return found


def _magnitudes(reaction: Array) -> tuple[Array, Array]:
    """(T, J) |F| and the moment: M itself in a planar run (T, J, 3), |M| in a spatial one
    (T, J, 6)."""
    if reaction.shape[-1] == 6:
        return (np.linalg.norm(reaction[..., :3], axis=-1),
                np.linalg.norm(reaction[..., 3:], axis=-1))
    return np.hypot(reaction[..., 0], reaction[..., 1]), reaction[..., 2]


def plot(go: Any, figure: Any, trajectory: Trajectory, column: int
         ) -> list[tuple[int, int, int]]:
    """Add the column's curves and a time cursor per panel; returns each cursor's (trace
    index, row, col), as the kinematic panels' are."""
    found = force_curves(trajectory)
    colours = dict(zip(dict.fromkeys(c.name for c in found), series.palette(len(found))))
    shown: set[str] = set()
    for curve in found:
        label = curve.name if curve.determinate else f"{curve.name} (min-norm)"
        figure.add_trace(go.Scatter(
            x=trajectory.t, y=curve.values, mode="lines", name=label,
            legendgroup=f"forces {curve.name}", showlegend=label not in shown,
            line={"color": colours[curve.name], "width": 1.5,
                  "dash": "solid" if curve.determinate else "dot"}),
            row=curve.panel + 1, col=column)
        shown.add(label)
    return cursor_traces(go, figure, column)


def cursor_traces(go: Any, figure: Any, column: int) -> list[tuple[int, int, int]]:
    """An empty line in each of the column's three panels, which the time slider moves:
    (trace index, panel, column) of each."""
    cursors: list[tuple[int, int, int]] = []
    for panel in range(3):
        figure.add_trace(go.Scatter(x=[], y=[], mode="lines", showlegend=False,
                                    hoverinfo="skip", line={"color": "black", "width": 1}),
                         row=panel + 1, col=column)
        cursors.append((len(figure.data) - 1, panel, column))
    return cursors


def label(figure: Any, column: int, units: Units, spatial: bool = False) -> None:
    """The column's axis titles with the force and moment units (a spatial run's moments are
    magnitudes |M|)."""
    for panel, title in enumerate(units.load_labels(spatial)):
        figure.update_yaxes(title_text=title, row=panel + 1, col=column)
    figure.update_xaxes(title_text=units.time_label(), row=3, col=column)


def panel_range(figure: Any, cursor: int) -> tuple[float, float]:
    """The y range of a panel's curves (the traces just before its cursor on that axis)."""
    axis = figure.data[cursor].yaxis
    values = [np.asarray(trace.y, dtype=float) for trace in figure.data[:cursor]
              if getattr(trace, "yaxis", None) == axis and trace.y is not None and len(trace.y)]
    if not values:
        return (0.0, 1.0)
    joined = np.concatenate(values)
    joined = joined[np.isfinite(joined)]
    return (float(joined.min()), float(joined.max())) if joined.size else (0.0, 1.0)
