"""The rows of drivers that read ``input`` signals (the input-drivers section): each input
function put in its slot of the Taylor polynomial in tau, the rows brought back to tau = t, and the
inputs' values at the file's start for generation-time samples. Kept apart from derivation so
that the derivation reads as the pipeline it is."""

from __future__ import annotations

import math
from typing import Any

import sympy as sp

from symkin.symbolic.planar import TAU, input_slot
from symkin.symbolic.symbols import Symbols


def at_tau(expr: sp.Expr, symbols: Symbols) -> sp.Expr:
    """An expression derived from inputs' Taylor polynomials, taken at tau = t."""
    return expr.xreplace({TAU: symbols.t}) if symbols.inputs else expr


def with_inputs(constraint: Any, symbols: Symbols, index: int) -> Any:
    """The driver with each ``input`` function replaced by its slot (planar.input_slot)."""
    update: dict[str, Any] = {}
    for item in symbols.inputs:
        if item.driver != index:
            continue
        slot = input_slot(item.u, item.du, item.ddu, symbols.t)
        if item.component is None:
            update[item.key] = slot
        else:
            value = list(update.get(item.key, getattr(constraint, item.key)))
            value[item.component] = slot
            update[item.key] = value
    return constraint.model_copy(update=update) if update else constraint


def input_values(phi: list[sp.Expr], symbols: Symbols,
                  at_start: dict[sp.Symbol, float]) -> tuple[float, ...]:
    """Each input's value at the file's q0 and t0 (``at_start``, rates zero): its row, linear
    in u, solved for u; 0 where that has no finite value. Only generation-time samples use
    it."""
    if not symbols.inputs:
        return ()
    at_q0: dict[sp.Symbol, Any] = dict(at_start)
    for item in symbols.inputs:
        at_q0.update({item.u: 0, item.du: 0, item.ddu: 0})
    values = []
    for item in symbols.inputs:
        row = next(row for row in phi if item.u in row.free_symbols)
        try:
            value = float(-row.subs(at_q0) / sp.diff(row, item.u).subs(at_q0))
        except (TypeError, ValueError, ZeroDivisionError):
            value = 0.0
        values.append(value if math.isfinite(value) else 0.0)
    return tuple(values)
