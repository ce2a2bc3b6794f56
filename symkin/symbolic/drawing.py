"""What a drawing of a planar mechanism needs from its derivation: per body, the local
vectors of its joint and driver attachments and named points, as plain NumPy arrays.

The runtime's plots and the warm-run index take these arrays, never SymPy objects.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

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
    return {body: np.array(v or [(0.0, 0.0)], dtype=float) for body, v in found.items()}
