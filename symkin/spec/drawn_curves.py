"""Curves of the drawn layout: a curve [x(s), y(s)] or a polar profile rho(s) drawn in global
coordinates and carried by a body, turned into the text of the curve in that body's frame,
c'(s) = A(angle)^T (c(s) - origin). Each component is first parsed alone by the whitelist
parser (so that wrapping it in parentheses cannot change its meaning), as every drawn piece;
only text is built here, never evaluated but through the parser and the bounded evaluator.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import sympy as sp

from symkin.errors import ExpressionError, MechanismError
from symkin.spec import constants, expressions

Path_ = tuple[str | int, ...]
S = sp.Symbol("s", real=True)


def _parsed(raw: Any, symbols: Mapping[str, sp.Symbol], path: Path_) -> list[sp.Expr]:
    if not isinstance(raw, (list, tuple)) or len(raw) != 2:
        raise MechanismError("expected a curve [x(s), y(s)]", path)
    parsed = []
    for k, item in enumerate(raw):
        try:
            parsed.append(expressions.parse(item, {**symbols, "s": S}))
        except ExpressionError as error:
            raise MechanismError(str(error), path + (k,), "Use numbers, parameter names, s, "
                                 "pi, E and the listed functions.") from None
    return parsed


def in_frame(raw: Any, origin: tuple[Any, Any], angle: Any, turned: bool,
             symbols: Mapping[str, sp.Symbol], values: Mapping[sp.Symbol, float],
             path: Path_) -> tuple[list[str], Callable[[float], tuple[float, float]]]:
    """The curve's components in the frame at ``origin`` turned by ``angle`` (text; ``turned``
    False when the angle is a plain zero), and the drawn curve's point at a value of s."""
    parsed = _parsed(raw, symbols, path)
    dx, dy = (f"({item}) - ({o})" for item, o in zip(raw, origin))
    texts = [dx, dy]
    if turned:
        texts = [f"cos({angle})*({dx}) + sin({angle})*({dy})",
                 f"-sin({angle})*({dx}) + cos({angle})*({dy})"]

    def at(value: float) -> tuple[float, float]:
        x, y = (constants.value(expr.subs(S, value), values) for expr in parsed)
        return x, y
    return texts, at


def polar_in_frame(rho: Any, angle: Any, turned: bool, symbols: Mapping[str, sp.Symbol],
                   path: Path_) -> Any:
    """A polar profile about the frame's origin, s the angle from the global x axis as
    drawn: as written when the frame is not turned, else [rho cos(s - angle), ...]."""
    _parsed([rho, 0], symbols, path)
    if not turned:
        return {"polar": rho}
    return [f"({rho})*cos(s - ({angle}))", f"({rho})*sin(s - ({angle}))"]
