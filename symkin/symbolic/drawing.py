"""What a drawing of a planar mechanism needs from its derivation: per body, the local
vectors of its joint and driver attachments and named points, as plain NumPy arrays; the
points attached to the ground (pivots, under the key ``ground``); the slide axes (under
``slide:<body>``: rows point, direction, point, ... in the frame of the body that carries the
slide); the rods with no body of their own (under ``rod:<body i>:<body j>``: rows point on
i, point on j, ...); and the higher pairs' marks (under ``curve:<body>:<label>:<k>``: a
polyline in the body's frame — pitch circles with a turning radius, rack lines, curves, cam
profiles).

Everything is read from the System's resolved vectors (:attr:`System.placed`); what each pair
type adds to the drawing its module says (:class:`symkin.pairs.kit.PairType`). The runtime's
plots and the warm-run index take these arrays, never SymPy objects.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np
import sympy as sp
from numpy.typing import NDArray

from symkin import pairs
from symkin.pairs.fields import GROUND
from symkin.spec import constants
from symkin.symbolic.derivation import Placed, System

Vector = tuple[float, float]


def outlines(system: System) -> dict[str, NDArray[np.float64]]:
    """Per body, the local vectors of its joint and driver attachments and its named points,
    at the nominal parameter values: what ``animate`` draws each body through; and the ground's
    pivots, the slide axes and the rods.

    Args:
        system: the derived System.
    """
    values = dict(zip(system.p, system.p_values))

    def at(vector: sp.ImmutableMatrix) -> Vector:
        x, y = (float(v.subs(values)) for v in vector)
        return x, y

    mech = system.mechanism
    found: dict[str, list[Vector]] = {body: [] for body in mech.bodies}
    # The points on the i side of every joint and driver, then those on the j side.
    points = [p for p in system.placed if p.kind == "point"]
    ordered = sorted(points, key=lambda p: p.side != "i")
    attachments = [(p.body, p.vector) for p in ordered]
    attachments += [(body, vector) for body, _, vector in system.points]
    for body, vector in attachments:
        if body in found and at(vector) not in found[body]:
            found[body].append(at(vector))
    drawn = {body: np.array(v or [(0.0, 0.0)], dtype=float) for body, v in found.items()}
    pivots: set[Vector] = set()
    slides: dict[str, list[Vector]] = {}
    rods: dict[str, list[Vector]] = {}
    for (section, index), placed in _by_constraint(system.placed).items():
        kind = pairs.of(getattr(mech, section)[index])
        on_ground = [p for p in placed if p.kind == "point" and p.body == GROUND]
        if kind.pivot and on_ground:
            pivots.add(at(on_ground[0].vector))
        if kind.slide:
            normal = next(p for p in placed if p.key == kind.slide)
            point = next(p for p in placed if p.kind == "point" and p.body == normal.body)
            (vx, vy) = at(normal.vector)
            slides.setdefault(normal.body, []).extend([at(point.vector), (vy, -vx)])
        if kind.rod:
            first, second = (p for p in placed if p.kind == "point")
            rods.setdefault(f"rod:{first.body}:{second.body}", []).extend(
                [at(first.vector), at(second.vector)])
    drawn.update(_marks(system, values))
    drawn.update(_pitches(system, values))
    if pivots:
        drawn[GROUND] = np.array(sorted(pivots), dtype=float)
    drawn.update({f"slide:{body}": np.array(rows, dtype=float) for body, rows in slides.items()})
    drawn.update({key: np.array(rows, dtype=float) for key, rows in rods.items()})
    drawn.update(_joint_points(system, at))
    return drawn


def spatial_outlines(system: System) -> dict[str, NDArray[np.float64]]:
    """What the 3D view needs besides the trajectory's named points: with inverse dynamics,
    each joint's point on body i (``joint:<name>:<body i>``, one row x, y, z in the frame of
    body i, global for the ground), where its reaction arrow is drawn; else nothing."""
    values = dict(zip(system.p, system.p_values))

    def at(vector: sp.ImmutableMatrix) -> tuple[float, ...]:
        return tuple(float(v.subs(values)) for v in vector)

    return _joint_points(system, at)


def _joint_points(system: System, at: Any) -> dict[str, NDArray[np.float64]]:
    """With inverse dynamics, where each joint's reaction acts: ``joint:<name>:<body i>``
    holds the joint's point on body i (its local vector), the point its moment is about."""
    if system.dynamics is None:
        return {}
    found: dict[str, NDArray[np.float64]] = {}
    names = system.dynamics.joint_names
    for p in system.placed:
        if (p.section, p.side, p.kind) == ("joints", "i", "point"):
            key = f"joint:{names[p.index]}:{p.body}"
            found.setdefault(key, np.array([at(p.vector)], dtype=float))
    return found


MARK_SAMPLES = 121


def _marks(system: System, values: dict[sp.Symbol, float]) -> dict[str, NDArray[np.float64]]:
    """The pairs' own marks (pitch circles, rack lines, curves, cam profiles) sampled at the
    nominal parameters, under ``curve:<body>:<label>:<k>`` (rows: points in the body's frame;
    points where a curve has no real value are left out)."""
    from symkin.pairs.kit import S_MARK
    from symkin.symbolic.planar import Context
    from symkin.symbolic.symbols import make_symbols

    mech = system.mechanism
    ctx = Context(mech, make_symbols(mech))
    found: dict[str, NDArray[np.float64]] = {}
    for section in pairs.SECTIONS:
        for constraint in getattr(mech, section):
            marks = pairs.of(constraint).marks
            for body, label, curve, (start, stop) in marks(constraint, ctx) if marks else ():
                s = np.linspace(float(start.subs(values)), float(stop.subs(values)),
                                MARK_SAMPLES)
                with np.errstate(all="ignore"):
                    xy = np.column_stack([np.broadcast_to(np.asarray(constants.lambdify_floats(
                        S_MARK, item.subs(values))(s), dtype=float), s.shape)
                        for item in curve])
                xy = xy[np.isfinite(xy).all(axis=1)]
                if len(xy) > 1:
                    found[f"curve:{body}:{label}:{len(found)}"] = xy
    return found


def _pitches(system: System, values: dict[sp.Symbol, float]) -> dict[str, NDArray[np.float64]]:
    """Each meshing's pitch point as ``pitch:<body i>:<body j>:<k>``: one row (r_i, r_j), r_j
    negative for a ring gear j (see :attr:`symkin.pairs.kit.PairType.pitch`)."""
    from symkin.symbolic.planar import Context
    from symkin.symbolic.symbols import make_symbols

    mech = system.mechanism
    ctx = Context(mech, make_symbols(mech))
    found: dict[str, NDArray[np.float64]] = {}
    for constraint in mech.joints:
        pitch = pairs.of(constraint).pitch
        if pitch is not None:
            i, j, ri, rj = pitch(constraint, ctx)
            found[f"pitch:{i}:{j}:{len(found)}"] = np.array(
                [[float(ri.subs(values)), float(rj.subs(values))]], dtype=float)
    return found


def _by_constraint(placed: Iterable[Placed]) -> dict[tuple[str, int], list[Placed]]:
    grouped: dict[tuple[str, int], list[Placed]] = {}
    for p in placed:
        grouped.setdefault((p.section, p.index), []).append(p)
    return grouped
