"""The envelope plot of a sweep: each named point's x and y over t, min/max shaded, and the
mean ± 3 sigma."""

from __future__ import annotations

from pathlib import Path

from symkin import outfiles
from symkin.sweeps.result import SweepResult
from symkin.sweeps.tolerance import envelope


def plot_envelopes(result: SweepResult, path: str | Path) -> Path:
    """Write a PNG: one row per named point, x and y against t."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    points = result.points_named
    figure, axes = plt.subplots(max(len(points), 1), 2, figsize=(10, 2.6 * max(len(points), 1)),
                                squeeze=False)
    for row, (body, name) in enumerate(points):
        band = envelope(result, body, name)
        for column, label in enumerate("xy"):
            axis = axes[row][column]
            axis.fill_between(result.t, band.low[:, column], band.high[:, column], alpha=0.3,
                              label="min/max")
            axis.plot(result.t, band.mean[:, column], "k-", lw=1, label="mean")
            for sign in (1, -1):
                axis.plot(result.t, band.mean[:, column] + sign * 3 * band.std[:, column], "r--",
                          lw=0.8, label="mean ± 3σ" if sign == 1 else None)
            axis.set_title(f"{body}.{name}.{label}")
            axis.set_xlabel("t")
    axes[0][0].legend(loc="best", fontsize="small")
    figure.tight_layout()
    try:
        with outfiles.replacing(path) as temporary:
            figure.savefig(temporary, dpi=100)
    finally:
        plt.close(figure)
    return path
