"""What both HTML pages (the planar report and the 3D view) share: the time slider with its
play and pause buttons under the figure, and how the page is written."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin import outfiles
from symkin.present.series import Units
from symkin.runtime.outputs.results import Trajectory


def time_controls(trajectory: Trajectory, frames: NDArray[np.float64], units: Units, *,
                  redraw: bool, y: float) -> dict[str, Any]:
    """Layout keys ``sliders`` and ``updatemenus``: one slider step per frame (named by its
    time, as the frames are) and play/pause at height ``y``. ``redraw``: a 3D scene needs it
    (it cannot be updated in place the way a 2D plot can)."""
    step = {"mode": "immediate", "frame": {"duration": 0, "redraw": redraw},
            "transition": {"duration": 0}}
    steps = [{"method": "animate", "label": f"{float(trajectory.t[k]):.4g}",
              "args": [[f"{float(trajectory.t[k]):.6g}"], step]} for k in frames]
    play = {"frame": {"duration": 50, "redraw": redraw}, "fromcurrent": True,
            "transition": {"duration": 0}}
    # The slider's own tick labels (one per frame) would crowd: the current time is shown
    # above it instead.
    return {
        "sliders": [{"active": 0, "steps": steps, "y": y, "x": 0.08, "len": 0.9,
                     "font": {"color": "rgba(0,0,0,0)"}, "ticklen": 0, "minorticklen": 0,
                     "currentvalue": {"prefix": f"{units.time_label()} = ",
                                      "font": {"color": "#222"}},
                     "pad": {"t": 40}}],
        "updatemenus": [{"type": "buttons", "direction": "left", "x": 0.0, "y": y,
                         "xanchor": "left", "yanchor": "top", "pad": {"t": 40, "r": 10},
                         "buttons": [
                             {"label": "▶", "method": "animate", "args": [None, play]},
                             {"label": "❚❚", "method": "animate",
                              "args": [[None], {"mode": "immediate",
                                                "frame": {"duration": 0, "redraw": False}}]}]}],
    }


def write(figure: Any, path: Path) -> Path:
    """The figure as one self-contained HTML file (plotly.js inside: it opens offline)."""
    with outfiles.replacing(path) as temporary:
        figure.write_html(temporary, include_plotlyjs=True, full_html=True, auto_play=False,
                          config={"displaylogo": False, "responsive": True},
                          div_id="symkin-report")
    return path
