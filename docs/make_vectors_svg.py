"""Draw docs/vectors.svg: the vectors of a pair and of a slide driver, as README.md uses them.

Body i (a slider) moves along a guide fixed in body j. Each body has its frame (origin r, angle
phi); point A is fixed in i (local vector sA), point B in j (sB); v, fixed in j, is the normal
of the slide, u (for a `slide` driver) its direction; phi0 is phi_i - phi_j in the assembled
pose. Run from the repository root: ``python docs/make_vectors_svg.py`` (needs matplotlib; the
output is the same bytes on every run).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Arc, Polygon  # noqa: E402

OUT = Path(__file__).resolve().parent / "vectors.svg"
I_COLOUR, J_COLOUR, PAIR = "#1f77b4", "#2ca02c", "#d62728"


def turn(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def arrow(ax, start, end, colour, label, offset=(0.0, 0.0), width=1.6, at=0.5) -> None:
    ax.annotate("", xy=end, xytext=start,
                arrowprops={"arrowstyle": "-|>", "color": colour, "lw": width,
                            "shrinkA": 0, "shrinkB": 0, "mutation_scale": 14})
    middle = (1 - at) * np.asarray(start) + at * np.asarray(end) + np.asarray(offset)
    ax.text(*middle, label, color=colour, fontsize=13, ha="center", va="center")


def frame(ax, origin, angle, colour, name) -> None:
    """A body's frame: two short axes and the origin's name."""
    R = turn(angle)
    for k, axis in enumerate(("ξ", "η")):
        tip = origin + 0.9 * R[:, k]
        arrow(ax, origin, tip, colour, "", width=1.1)
        ax.text(*(origin + 1.05 * R[:, k]), f"{axis}$_{name}$", color=colour, fontsize=11,
                ha="center", va="center")
    ax.plot(*origin, "o", color=colour, markersize=4)


def main() -> None:
    plt.rcParams.update({"svg.hashsalt": "symkin", "font.family": "DejaVu Sans"})
    figure, ax = plt.subplots(figsize=(8.4, 5.6))
    ax.set_aspect("equal")
    ax.axis("off")

    # The global frame, and the origins of the body frames as vectors r from it.
    origin = np.array([-0.9, -0.9])
    arrow(ax, origin, origin + (1.0, 0), "black", "", width=1.0)
    arrow(ax, origin, origin + (0, 1.0), "black", "", width=1.0)
    ax.text(*(origin + (1.1, -0.08)), "x", fontsize=12)
    ax.text(*(origin + (-0.08, 1.12)), "y", fontsize=12)

    # Body j: a guide turned by phi_j; its slide axis is the line eta_j = 1.2, B on it.
    phi_j = np.radians(10)
    Rj = turn(phi_j)
    rj = np.array([0.6, 0.4])
    on_axis = lambda xi: rj + Rj @ np.array([xi, 1.2])  # noqa: E731
    B = on_axis(2.2)
    guide = [rj + Rj @ np.array(p) for p in ([-0.4, -0.3], [7.6, -0.3], [7.6, 0.95],
                                               [-0.4, 0.95])]
    ax.add_patch(Polygon(guide, closed=True, facecolor=J_COLOUR, alpha=0.18,
                         edgecolor=J_COLOUR))
    ax.plot(*np.array([on_axis(-0.6), on_axis(8.0)]).T, "-.", color="0.45", linewidth=1)
    ax.text(*(on_axis(7.3) + Rj @ np.array([0, 0.15])), "slide axis", color="0.35",
            fontsize=10, rotation=np.degrees(phi_j), ha="center")
    frame(ax, rj, phi_j, J_COLOUR, "j")
    arrow(ax, origin, rj, "0.6", "$\\mathbf{r}_j$", offset=(0.25, -0.15), width=1.0)
    ax.text(*(rj + Rj @ np.array([6.4, -0.1])), "body j", color=J_COLOUR, fontsize=12,
            rotation=np.degrees(phi_j))

    # Body i: a plate whose point A slides on the axis; frame turned by phi_i = phi_j + phi0.
    phi0 = np.radians(25)
    phi_i = phi_j + phi0
    Ri = turn(phi_i)
    A = on_axis(5.6)
    sA = np.array([-0.5, -1.4])
    ri = A - Ri @ sA
    plate = [ri + Ri @ np.array(p) for p in ([-1.1, -1.7], [1.1, -1.7], [1.4, 0.7],
                                               [-0.9, 0.9])]
    ax.add_patch(Polygon(plate, closed=True, facecolor=I_COLOUR, alpha=0.15,
                         edgecolor=I_COLOUR))
    frame(ax, ri, phi_i, I_COLOUR, "i")
    arrow(ax, origin, ri, "0.6", "$\\mathbf{r}_i$", offset=(-0.1, 0.3), width=1.0, at=0.72)
    ax.text(*(ri + Ri @ np.array([0.4, 0.95])), "body i", color=I_COLOUR, fontsize=12)

    # The pair: sA in i, sB and v (the slide's normal) in j, u along the slide for a
    # `slide` driver, d = r_B - r_A stays perpendicular to v.
    arrow(ax, ri, A, I_COLOUR, "$\\mathbf{s}_A^{(i)}$", offset=(-0.35, 0.05), width=2)
    arrow(ax, rj, B, J_COLOUR, "$\\mathbf{s}_B^{(j)}$", offset=(0.3, -0.25), width=2)
    for point, name, shift in ((A, "A", (0.12, -0.4)), (B, "B", (-0.35, -0.4))):
        ax.plot(*point, "o", color=PAIR, markersize=6, zorder=5)
        ax.text(*(point + np.array(shift)), name, color=PAIR, fontsize=13)
    arrow(ax, B, B + Rj @ np.array([0.0, 1.3]), PAIR, "$\\mathbf{v}^{(j)}$",
          offset=(-0.4, 0.2), width=2)
    arrow(ax, B, B + Rj @ np.array([1.2, 0.0]), "#9467bd", "$\\mathbf{u}^{(j)}$",
          offset=(0.0, 0.3), width=2)
    below = Rj @ np.array([0.0, -0.55])
    arrow(ax, A + below, B + below, "0.25", "$\\mathbf{d} = \\mathbf{r}_B - \\mathbf{r}_A$",
          offset=tuple(Rj @ np.array([0.0, -0.25])), width=1)

    # phi0: from the direction of body j's xi axis to body i's xi axis.
    ax.plot(*np.array([ri, ri + 1.5 * Rj[:, 0]]).T, ":", color=J_COLOUR, linewidth=1.2)
    ax.add_patch(Arc(ri, 2.4, 2.4, theta1=np.degrees(phi_j), theta2=np.degrees(phi_i),
                     color="black", linewidth=1))
    ax.text(*(ri + 1.45 * turn(phi_j + phi0 / 2)[:, 0]), "$\\varphi_0$", fontsize=13,
            ha="left", va="center")

    ax.set_xlim(-1.2, 9.0)
    ax.set_ylim(-1.2, 5.6)
    figure.tight_layout(pad=0.2)
    figure.savefig(OUT, metadata={"Date": None, "Creator": None})
    plt.close(figure)
    print(OUT)


if __name__ == "__main__":
    main()
