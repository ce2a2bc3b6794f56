"""Drawn quantities (text and nominal value) and their arithmetic, shared by drawn and drawn3d."""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import sympy as sp

from symkin.errors import ExpressionError, MechanismError
from symkin.spec import constants, expressions

Path_ = tuple[str | int, ...]


@dataclass(frozen=True)
class Q:
    """One drawn quantity: its text (a number or an expression) and its nominal value."""

    text: Any
    value: float


class _Context:
    """The parameters' nominal values, to check and evaluate each piece of the drawing."""

    def __init__(self, parameters: Any) -> None:
        if not isinstance(parameters, Mapping):
            raise MechanismError("expected a mapping of parameter names to values",
                                 ("parameters",), "Write parameters: {a: 1.0, b: 5.0}.")
        # A name that is not text is named by the validation of the local form.
        named = {name: raw for name, raw in parameters.items() if isinstance(name, str)}
        self.symbols = {name: sp.Symbol(name, real=True) for name in named}
        self.values: dict[sp.Symbol, float] = {}
        # parameters with no value, each with why: blamed at their own line when the
        # drawing uses them (a point is not where the mistake is)
        self.unusable: dict[str, MechanismError] = {}
        for name, raw in named.items():
            if isinstance(raw, float) and not math.isfinite(raw):
                # said here: every drawn point that uses it would be blamed instead
                raise MechanismError(f"{raw} is not a finite number", ("parameters", name),
                                     "Give the parameter a finite value.")
            try:
                self.values[self.symbols[name]] = constants.value(expressions.parse(raw, {}))
            except ExpressionError as error:
                self.unusable[name] = MechanismError(
                    str(error), ("parameters", name),
                    "A parameter's value is a number or an expression of numbers, pi and E; "
                    "it cannot use t or other parameters." if error.text else
                    "Check the arguments of sqrt, log, asin, acos and the magnitudes.")
            except (TypeError, ValueError):
                continue  # not text: validation of the local form names it

    def quantity(self, raw: Any, path: Path_) -> Q:
        if isinstance(raw, str):
            return self._expression(raw, path)
        if isinstance(raw, bool) or not isinstance(raw, numbers.Real):
            raise MechanismError("expected a number or an expression", path)
        if not math.isfinite(raw):
            raise MechanismError(f"{raw} is not a finite number", path, "Give a finite value.")
        try:
            expressions.number(float(raw))  # the local form's rules (e.g. no subnormal)
        except ExpressionError as error:
            raise MechanismError(str(error), path) from None
        # numpy scalars become Python numbers: the text goes on into the local form
        return Q(int(raw) if isinstance(raw, numbers.Integral) else float(raw), float(raw))

    def _expression(self, raw: str, path: Path_) -> Q:
        try:
            expr = expressions.parse(raw, self.symbols)
        except ExpressionError as error:
            raise MechanismError(str(error), path, "Use numbers, parameter names, pi, E and "
                                 "the listed functions.") from None
        used = sorted(str(symbol) for symbol in expr.free_symbols)
        for name in used:
            if name in self.unusable:
                raise self.unusable[name]
        try:
            value = constants.value(expr, self.values)
        except ExpressionError as error:
            raise MechanismError(
                f"{raw!r} is not a finite real number at the nominal parameter values: "
                f"{error.message}", path,
                "A link too short (or too long) to close the drawing at these values? "
                + (f"Check the parameters it uses: {', '.join(used)}." if used else
                   "Check the numbers.")) from None
        return Q(raw, value)

    def tidy(self, q: Q) -> Any:
        """The text of a derived quantity in its simplest form: the parser's own expression
        printed back (cos(pi/2)*(a) -> 0), kept only if it parses back to the same thing."""
        if not isinstance(q.text, str):
            return q.text
        expr = expressions.parse(q.text, self.symbols)
        if expr.is_Number:
            return _clean(float(expr)) if expr.is_Float else int(expr) if expr.is_Integer \
                else q.text
        text = sp.sstr(expr)
        try:
            same = expressions.parse(text, self.symbols) == expr
        except ExpressionError:
            same = False
        return text if same else q.text

    def vector(self, raw: Any, path: Path_) -> tuple[Q, Q]:
        if not isinstance(raw, (list, tuple)) or len(raw) != 2:
            raise MechanismError("expected a vector [x, y]", path)
        return self.quantity(raw[0], path + (0,)), self.quantity(raw[1], path + (1,))


# ----- arithmetic on drawn quantities (numbers stay numbers) ---------------------------------

def _clean(value: float) -> float | int:
    """A float without the last-bit noise of a subtraction (0.3 - 0.1 -> 0.2)."""
    cleaned = float(f"{value:.15g}")
    return int(cleaned) if cleaned.is_integer() and abs(cleaned) < 2**53 else cleaned


def _numeric(q: Q) -> bool:
    return not isinstance(q.text, str)


def _sub(a: Q, b: Q) -> Q:
    if a.text == b.text:
        return Q(0, 0.0)
    if _numeric(a) and _numeric(b):
        return Q(_clean(a.value - b.value), a.value - b.value)
    if _numeric(b) and b.value == 0:
        return a
    return Q(f"({a.text}) - ({b.text})", a.value - b.value)


def _neg(a: Q) -> Q:
    return Q(_clean(-a.value), -a.value) if _numeric(a) else Q(f"-({a.text})", -a.value)


def _to_frame(dx: Q, dy: Q, angle: Q) -> tuple[Q, Q]:
    """A^T(angle) [dx, dy]: a global difference vector in a frame turned by ``angle``."""
    if _numeric(angle) and angle.value == 0:
        return dx, dy
    c, s = math.cos(angle.value), math.sin(angle.value)
    x, y = c * dx.value + s * dy.value, -s * dx.value + c * dy.value
    if _numeric(angle) and _numeric(dx) and _numeric(dy):
        return Q(_clean(x), x), Q(_clean(y), y)
    a = angle.text
    return (Q(f"cos({a})*({dx.text}) + sin({a})*({dy.text})", x),
            Q(f"-sin({a})*({dx.text}) + cos({a})*({dy.text})", y))
