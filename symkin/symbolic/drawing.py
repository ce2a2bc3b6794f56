"""What a drawing of a planar mechanism needs from its derivation: per body, the local
vectors of its joint and driver attachments and named points, as plain NumPy arrays; the
points attached to the ground (pivots, under the key ``ground``); and the slide axes of the
prismatic and pin-in-slot pairs (under ``slide:<body j>``: rows point, direction, point, ...
in the frame of body j, which carries the slide).

The runtime's plots and the warm-run index take these arrays, never SymPy objects.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.spec.schema import GROUND, PinSlot, Prismatic, Revolute
from symkin.symbolic import planar as constraints
from symkin.symbolic import symbols as symbols_module
from symkin.symbolic.derivation import System


def outlines(system: System) -> dict[str, NDArray[np.float64]]:
    """Per body, the local vectors of its joint and driver attachments and its named points,
    at the nominal parameter values: what ``animate`` draws each body through.

    Args:
        system: the derived System.
    """
    mech = system.mechanism
    ctx = constraints.Context(mech, symbols_module.make_symbols(mech))
    values = dict(zip(system.p, system.p_values))
    found: dict[str, list[tuple[float, float]]] = {body: [] for body in mech.bodies}
    attachments = [(getattr(c, "i", None), getattr(c, "sA", None)) for c in
                   [*mech.joints, *mech.drivers]]
    attachments += [(getattr(c, "j", None), getattr(c, "sB", None)) for c in
                    [*mech.joints, *mech.drivers]]
    attachments += [(body, name) for body, spec in mech.bodies.items() for name in spec.points]
    for body, ref in attachments:
        if body in found and ref is not None:
            x, y = (float(v.subs(values)) for v in ctx.local(body, ref))
            vector = (x, y)
            if vector not in found[body]:
                found[body].append(vector)
    drawn = {body: np.array(v or [(0.0, 0.0)], dtype=float) for body, v in found.items()}
    # Revolute joints with the ground are its pivots; prismatic and pin-slot pairs carry
    # a slide axis (on body j, which may be the ground).
    pivots = {_at(ctx, GROUND, c.sB if c.j == GROUND else c.sA, values)
              for c in mech.joints if isinstance(c, Revolute) and GROUND in (c.i, c.j)}
    if pivots:
        drawn[GROUND] = np.array(sorted(pivots), dtype=float)
    for c in mech.joints:
        if isinstance(c, (Prismatic, PinSlot)):
            v = [float(ctx.expr(item).subs(values)) for item in c.v]
            rows = np.array([_at(ctx, c.j, c.sB, values), (v[1], -v[0])])  # axis: v turned -90°
            key = f"slide:{c.j}"
            drawn[key] = np.vstack([drawn[key], rows]) if key in drawn else rows
    return drawn


def _at(ctx: constraints.Context, body: str, ref: Any, values: dict[Any, Any]
        ) -> tuple[float, float]:
    x, y = (float(v.subs(values)) for v in ctx.local(body, ref))
    return x, y
