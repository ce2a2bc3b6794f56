"""What a figure shows: the chosen quantities of a run, their units, and their colours.

Shared by the static plots (:mod:`symkin.present.plots`) and the HTML report
(:mod:`symkin.present.html`), so both select, label and colour a quantity the same way.

A quantity is a coordinate (``crank.phi``, ``slider.x``) or a named point (``coupler.P``, its x
and y drawn as one colour, solid and dashed). Lengths and angles never share an axis: each has
its own column, labelled with the units of the file's optional ``units`` key.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.errors import UsageError
from symkin.limits import listed
from symkin.runtime.outputs.results import Trajectory

Array = NDArray[np.float64]
LENGTH, ANGLE = "length", "angle"
ORDERS = ("position", "velocity", "acceleration")

# Distinct colours: Tableau 10, then its light partners (Tableau 20 order), then a sampled
# colour wheel for the rare panel that shows more than twenty quantities.
_TABLEAU = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
            "#7f7f7f", "#bcbd22", "#17becf")
_LIGHT = ("#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2",
          "#c7c7c7", "#dbdb8d", "#9edae5")


def palette(count: int) -> list[str]:
    """``count`` colours, none repeated."""
    if count <= len(_TABLEAU):
        return list(_TABLEAU[:count])
    if count <= 2 * len(_TABLEAU):
        return list(_TABLEAU) + list(_LIGHT[:count - len(_TABLEAU)])
    return [_hsv_hex(k / count) for k in range(count)]


def _hsv_hex(hue: float) -> str:
    import colorsys

    r, g, b = colorsys.hsv_to_rgb(hue, 0.75, 0.8)
    return f"#{round(r * 255):02x}{round(g * 255):02x}{round(b * 255):02x}"


# ----- units ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class Units:
    """Labels for lengths and time, and the unit angles are shown in (rad or deg)."""

    length: str | None = None
    angle: str = "rad"
    time: str = "s"

    @classmethod
    def of(cls, raw: Any) -> Units:
        """The units of a file's ``units`` mapping (validated with the file; None: defaults)."""
        if not isinstance(raw, Mapping):
            return cls()
        length = raw.get("length")
        return cls(length=str(length) if length is not None else None,
                   angle="deg" if raw.get("angle") == "deg" else "rad",
                   time=str(raw.get("time", "s")))

    def scale(self, kind: str) -> float:
        """Factor from symkin's numbers (radians for angles) to the units shown."""
        return 180.0 / math.pi if kind == ANGLE and self.angle == "deg" else 1.0

    def unit(self, kind: str, order: int) -> str | None:
        """``m``, ``m/s``, ``m/s²`` or ``rad/s`` …; None when lengths have no unit given."""
        base = self.angle if kind == ANGLE else self.length
        if base is None:
            return None
        return base + ("", f"/{self.time}", f"/{self.time}²")[order]

    def axis_label(self, kind: str, order: int) -> str:
        words = ORDERS[order] if kind == LENGTH else \
            ("angle", "angular velocity", "angular acceleration")[order]
        unit = self.unit(kind, order)
        return f"{words} [{unit}]" if unit else words

    def time_label(self) -> str:
        return f"t [{self.time}]"

    def loads(self) -> tuple[str, str]:
        """The units of a force and of a moment. A file in metres and seconds has its masses
        in kilograms (the file gives no mass unit: SI is the only consistent reading): N and
        N m; other lengths or times give the derived unit with "mass" for the mass's; a
        file without a length unit: N (SI), N m (SI), the numbers being SI only if the file's
        are."""
        if self.length is None:
            return "N (SI)", "N m (SI)"
        if self.length == "m" and self.time == "s":
            return "N", "N m"
        return (f"mass·{self.length}/{self.time}²",
                f"mass·{self.length}²/{self.time}²")

    def load_labels(self, spatial: bool = False) -> tuple[str, str, str]:
        """The three force panels' axis titles: effort, joint force, joint moment."""
        force, moment = self.loads()
        return (f"effort [{force} or {moment}]", f"joint force |F| [{force}]",
                f"joint moment {'|M|' if spatial else 'M'} [{moment}]")


DEFAULT_UNITS = Units()


# ----- selection -----------------------------------------------------------------------------

def names(coordinates: Sequence[str], points: Sequence[tuple[str, str]]) -> list[str]:
    """Every name ``--select`` accepts: the coordinates, then the named points."""
    return list(coordinates) + [f"{b}.{p}" for b, p in points if f"{b}.{p}" not in coordinates]


def parse_selection(text: str) -> list[str]:
    """``"crank.phi, coupler.P"`` -> ["crank.phi", "coupler.P"] (empty items dropped)."""
    return [item.strip() for item in text.split(",") if item.strip()]


def check_selection(selected: Sequence[str], coordinates: Sequence[str],
                    points: Sequence[tuple[str, str]]) -> list[str]:
    """The selection, or UsageError naming the unknown names and listing the valid ones.

    A point named like a coordinate (a point ``x`` on body ``crank``) is shadowed by the
    coordinate ``crank.x``.
    """
    valid = names(coordinates, points)
    unknown = [name for name in selected if name not in valid]
    if unknown:
        # The message lists ten: first the names of the bodies the unknown ones name.
        bodies = {name.rsplit(".", 1)[0] for name in unknown}
        near = sorted(valid, key=lambda name: name.rsplit(".", 1)[0] not in bodies)
        raise UsageError(f"--select: no coordinate or named point {listed(unknown)}; "
                         f"choose from: {listed(near)}")
    if not selected:
        raise UsageError(f"--select: give at least one name; choose from: {listed(valid)}")
    return list(dict.fromkeys(selected))


def default_selection(trajectory: Trajectory) -> list[str]:
    """What a plot shows when nothing is selected: every body's angle that changes, and every
    named point that moves, once (a point that coincides with an earlier one all the time,
    such as the two halves of a revolute joint, is shown once). The body origins' x and y are
    added only when there is no named point to show."""
    chosen = [name for k, name in enumerate(trajectory.coordinates)
              if name.endswith(".phi") and _moves(trajectory.q[:, k])]
    seen: list[Array] = []
    for body, point in trajectory.points:
        r, _, _ = trajectory.point(body, point)
        if not _moves(r) or any(_same(r, other) for other in seen):
            continue
        seen.append(r)
        chosen.append(f"{body}.{point}")
    if not seen:
        chosen += [name for k, name in enumerate(trajectory.coordinates)
                   if not name.endswith(".phi") and _moves(trajectory.q[:, k])]
    return chosen or list(trajectory.coordinates)


def _scale(values: Array) -> float:
    finite = values[np.isfinite(values)]
    return float(np.max(np.abs(finite))) if finite.size else 0.0


def _moves(values: Array) -> bool:
    """True when a quantity changes over the run (a pivot on the ground does not)."""
    if values.shape[0] < 2:
        return True
    table = values.reshape(values.shape[0], -1)
    spread = float(np.max(np.nanmax(table, axis=0) - np.nanmin(table, axis=0)))
    return spread > 1e-9 * max(1.0, _scale(values))


def _same(a: Array, b: Array) -> bool:
    return bool(np.max(np.abs(a - b)) <= 1e-9 * max(1.0, _scale(a)))


# ----- curves --------------------------------------------------------------------------------

@dataclass(frozen=True)
class Curve:
    """One selected quantity.

    Attributes:
        name: as selected, ``crank.phi`` or ``coupler.P``.
        kind: LENGTH or ANGLE (which column, which unit).
        components: ("",) for a coordinate, ("x", "y") for a point (spatial: x, y, z).
        values: position, velocity, acceleration, each (T, len(components)), in the units shown.
        colour: its colour, unique within its column.
    """

    name: str
    kind: str
    components: tuple[str, ...]
    values: tuple[Array, Array, Array]
    colour: str


def curves(trajectory: Trajectory, selected: Sequence[str], units: Units) -> list[Curve]:
    """The selected quantities as curves, coloured per column (lengths, angles)."""
    raw = [_quantity(trajectory, name) for name in selected]
    colours = {kind: iter(palette(sum(1 for _, k, _, _ in raw if k == kind)))
               for kind in (LENGTH, ANGLE)}
    return [Curve(name, kind, parts,
                  (values[0] * units.scale(kind), values[1] * units.scale(kind),
                   values[2] * units.scale(kind)), next(colours[kind]))
            for name, kind, parts, values in raw]


def _quantity(trajectory: Trajectory, name: str
              ) -> tuple[str, str, tuple[str, ...], tuple[Array, Array, Array]]:
    if name in trajectory.coordinates:
        k = trajectory.coordinates.index(name)
        kind = ANGLE if name.endswith(".phi") else LENGTH
        return name, kind, ("",), (trajectory.q[:, k:k + 1], trajectory.dq[:, k:k + 1],
                                   trajectory.d2q[:, k:k + 1])
    body, point = name.rsplit(".", 1)
    return name, LENGTH, tuple("xyz"[:trajectory.point_size]), trajectory.point(body, point)


def kinds(selected: Sequence[Curve]) -> list[str]:
    """The columns a figure needs, lengths first."""
    return [kind for kind in (LENGTH, ANGLE) if any(c.kind == kind for c in selected)]
