"""Stage 7 — the HTML report's energy column (a mechanism its forces move,
runtime.dynamics): three panels against time, the kinetic and potential energy, the work of
the non-conservative forces and drivers since t0, and the balance T + V - W, which the exact
motion keeps constant (its drift is the integration's error, shown rather than hidden).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.present.html_forces import cursor_traces
from symkin.present.series import Units
from symkin.runtime.outputs.results import Trajectory

Array = NDArray[np.float64]
TITLES = ("energy", "work W", "T + V - W")
# (panel, NPZ name of the array, legend name)
CURVES = ((0, "kinetic_energy", "kinetic T"), (0, "potential_energy", "potential V"),
          (1, "work_nonconservative", "work W"))
COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728")


def energies(trajectory: Trajectory) -> dict[str, Array] | None:
    """The run's energy arrays by NPZ name, or None for a run without them."""
    found = {name: values for name, values in trajectory.outputs
             if name in {curve[1] for curve in CURVES}}
    return found if len(found) == len(CURVES) else None


def plot(go: Any, figure: Any, trajectory: Trajectory, column: int
         ) -> list[tuple[int, int, int]]:
    """Add the column's curves and a time cursor per panel; returns each cursor's (trace
    index, row, col), as the other panels' are."""
    found = energies(trajectory)
    if found is None:
        return []
    for (panel, name, label), colour in zip(CURVES, COLOURS):
        figure.add_trace(go.Scatter(x=trajectory.t, y=found[name], mode="lines", name=label,
                                    line={"color": colour, "width": 1.5}),
                         row=panel + 1, col=column)
    balance = (found["kinetic_energy"] + found["potential_energy"]
               - found["work_nonconservative"])
    figure.add_trace(go.Scatter(x=trajectory.t, y=balance, mode="lines", name="T + V - W",
                                line={"color": COLOURS[3], "width": 1.5}), row=3, col=column)
    return cursor_traces(go, figure, column)


def label(figure: Any, column: int, units: Units) -> None:
    """The column's axis titles."""
    for panel, title in enumerate(TITLES):
        figure.update_yaxes(title_text=title, row=panel + 1, col=column)
    figure.update_xaxes(title_text=units.time_label(), row=3, col=column)
