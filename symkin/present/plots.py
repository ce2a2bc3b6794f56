"""Stage 7 — results, pictures: the selected quantities against time, in one figure.

Rows are position, velocity and acceleration; columns are lengths and angles (never on one
axis), labelled with the file's units. matplotlib runs with the Agg backend (no display
needed) and writes PNG, SVG or PDF by the file's suffix. The animation is in
:mod:`symkin.present.animation`, the interactive report in :mod:`symkin.present.html`.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin import outfiles
from symkin.errors import UsageError
from symkin.present import series
from symkin.present.series import DEFAULT_UNITS, Units
from symkin.runtime.outputs.results import Trajectory

FORMATS = (".png", ".svg", ".pdf")
_STYLES: dict[str, Any] = {"": "-", "x": "-", "y": "--", "z": ":"}


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot(trajectory: Trajectory, path: str | Path, select: Sequence[str] | None = None,
         units: Units = DEFAULT_UNITS, title: str | None = None) -> Path:
    """Write one figure: position, velocity and acceleration panels (rows) of the selected
    quantities, lengths and angles in separate columns, one legend per column above it.

    Args:
        trajectory: the solved run (a partial one works too).
        path: the file to write; .png, .svg or .pdf (the suffix decides).
        select: coordinate names and named points (``crank.phi``, ``coupler.P``); default
            :func:`series.default_selection`.
        units: labels (and degrees for angles) from the file's ``units`` key.
        title: the figure's title, e.g. the mechanism's name.

    Raises:
        UsageError: an unknown name in ``select`` (the message lists the valid ones), or a
            suffix other than .png, .svg, .pdf.
    """
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise UsageError(f"cannot write a plot to {path.name}: use a file ending in "
                         f"{', '.join(FORMATS)}")
    chosen = series.check_selection(select, trajectory.coordinates, trajectory.points) \
        if select is not None else series.default_selection(trajectory)
    drawn = series.curves(trajectory, chosen, units)
    columns = series.kinds(drawn)
    plt = _pyplot()
    figure, axes = plt.subplots(3, len(columns), figsize=(5.6 * len(columns) + 0.6, 8.8),
                                sharex=True, squeeze=False, layout="constrained")
    for column, kind in enumerate(columns):
        mine = [curve for curve in drawn if curve.kind == kind]
        for order in range(3):
            ax = axes[order, column]
            for curve in mine:
                _draw(ax, trajectory.t, curve, order)
            ax.set_ylabel(units.axis_label(kind, order))
            ax.grid(True, linewidth=0.4, alpha=0.5)
        axes[2, column].set_xlabel(units.time_label())
        _legend(axes[0, column], mine)
    if title:
        figure.suptitle(title)
    return _save(figure, plt, path)


def _draw(ax: Any, t: NDArray[np.float64], curve: series.Curve, order: int) -> None:
    values = curve.values[order]
    for k, part in enumerate(curve.components):
        ax.plot(t, values[:, k], _STYLES[part], color=curve.colour, linewidth=1.4)


def _legend(ax: Any, curves: Sequence[series.Curve]) -> None:
    """One entry per quantity (its colour) and, when points are shown, what solid and dashed
    mean; placed above the column's top panel, outside the data."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=c.colour, linewidth=2) for c in curves]
    labels = [c.name for c in curves]
    parts = max((c.components for c in curves if len(c.components) > 1), key=len, default=())
    if parts:
        handles += [Line2D([], [], color="black", linestyle=_STYLES[part]) for part in parts]
        labels += [f"{part} (points)" for part in parts]
    ax.legend(handles, labels, loc="lower left", bbox_to_anchor=(0.0, 1.02, 1.0, 0.1),
              mode="expand", ncol=min(3, len(labels)), fontsize="small", frameon=False,
              borderaxespad=0.0)


def _save(figure: Any, plt: Any, path: Path) -> Path:
    try:
        with outfiles.replacing(path) as temporary:
            figure.savefig(temporary, dpi=100)
    finally:
        plt.close(figure)
    return path
