"""The ranges a file gives the pairs' own coordinates (``NAME.s`` of a curve or a cam profile
written for s in [a, b], e.g. piecewise), at the nominal parameter values: plain data for the
manifest, so the driver stops a motion whose contact runs past the end of its curve."""

from __future__ import annotations

from symkin import pairs
from symkin.spec import constants
from symkin.symbolic.derivation import System
from symkin.symbolic.planar import Context
from symkin.symbolic.symbols import make_symbols

Range = tuple[str, float, float, str]
"""(coordinate name, a, b, the pair that owns it: ``joints[2] c1 point_on_curve``)."""


def coordinate_ranges(system: System) -> tuple[Range, ...]:
    """Every range the file gives, joints then drivers in file order."""
    mech = system.mechanism
    if mech.is_spatial:
        return ()
    ctx = Context(mech, make_symbols(mech))
    values = dict(zip(system.p, system.p_values))
    found = []
    for section in pairs.SECTIONS:
        for index, constraint in enumerate(getattr(mech, section)):
            kind = pairs.of(constraint)
            raw = kind.range_of(constraint)
            if raw is None:
                continue
            low, high = (constants.value(ctx.expr(item), values) for item in raw)
            (name, _), = kind.extra_coordinates(constraint)
            found.append((name, low, high, f"{section}[{index}] {constraint.name} {kind.name}"))
    return tuple(found)
