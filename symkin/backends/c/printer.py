"""The C99 backend's printer and literals: SymPy expressions as C99 text of the real type."""

from __future__ import annotations

import math
from collections.abc import Callable

import sympy as sp
from sympy.codegen.ast import float32, float64
from sympy.codegen.ast import real as real_type
from sympy.printing.c import C99CodePrinter
from sympy.printing.precedence import PRECEDENCE

from symkin.codegen.printing import heaviside_at_zero
from symkin.codegen.symbol_printing import symbol_text
from symkin.errors import BuildError


class CPrinter(C99CodePrinter):
    """C99 printer for generated kernels: array arguments, literal numbers, no ``pow(x, 2)``.

    Constant parts reach it already folded to plain numbers (codegen.symbol_printing.prepare),
    so the POSIX macros SymPy would print for pi, sqrt(2) or log(2) (``M_PI``, ``M_SQRT2``,
    ``M_LN2``, not in C99) never appear. Floats print as the shortest literal that
    round-trips; integers wider than an ``int`` print as real literals (a C integer constant
    would be truncated). In float mode the base class prints ``sinf``/``0.5F``, so nothing is
    promoted to double.
    """

    def __init__(self, real: str = "double") -> None:
        alias = float32 if real == "float" else float64
        super().__init__({"type_aliases": {real_type: alias}, "strict": True})
        self._literal = literal(real)
        self._suffix = "F" if real == "float" else ""

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        return symbol_text(expr.name)

    def _print_Float(self, expr: sp.Float) -> str:
        return self._literal(float(expr))

    # pi and E, should an unfolded one reach the printer: literals, never M_PI or M_E.
    def _print_Pi(self, expr: sp.Expr) -> str:
        return self._literal(float(expr))

    _print_Exp1 = _print_Pi

    def _print_Integer(self, expr: sp.Integer) -> str:
        if abs(int(expr)) > _INT_MAX:
            return self._literal(float(expr))
        return str(int(expr))

    def _print_Heaviside(self, expr: sp.Heaviside) -> str:
        # The step with H(0) = 1/2, the value the parser gives every Heaviside; a NaN argument
        # stays NaN (as numpy.heaviside gives), so a non-real argument is seen, not hidden.
        x = self._print(expr.args[0])
        at_zero = self._literal(heaviside_at_zero(expr))
        one, zero = self._literal(1.0), self._literal(0.0)
        return (f"(({x}) > 0 ? {one} : (({x}) < 0 ? {zero} : "
                f"(({x}) == 0 ? {at_zero} : ({x}))))")

    def _print_Pow(self, expr: sp.Pow) -> str:
        # A square is the most common power in kinematics; a product is exact and cheaper.
        if expr.exp == 2:
            base = self.parenthesize(expr.base, PRECEDENCE["Mul"])
            return f"({base}*{base})"
        if expr.exp == sp.Rational(1, 3):
            # SymPy's x**(1/3) is the principal root, not real for x < 0: pow gives NaN there
            # (cbrt would give a real number NumPy and SymPy do not).
            function = "powf" if self._suffix else "pow"
            return f"{function}({self._print(expr.base)}, {self._print(expr.exp)})"
        return str(super()._print_Pow(expr))


_INT_MAX = 2**31 - 1
# The normal range of IEEE single precision: a literal outside it does not fit a float.
_FLOAT_RANGE = (1.1754943508222875e-38, 3.4028234663852886e38)


def literal(real: str) -> Callable[[float], str]:
    """A C literal of the real type: shortest round-trip text; ``F`` suffix for float.

    Raises:
        BuildError: the value is not finite, or (float) outside the range of a float.
    """
    suffix = "F" if real == "float" else ""

    def text(value: float) -> str:
        value = float(value)
        if not math.isfinite(value):
            raise BuildError(f"the value {value} is not finite and has no C literal")
        if suffix and value != 0 and not _FLOAT_RANGE[0] <= abs(value) <= _FLOAT_RANGE[1]:
            raise BuildError(f"the value {value!r} is outside the range of a float "
                             f"({_FLOAT_RANGE[0]:.3g} to {_FLOAT_RANGE[1]:.3g} in magnitude); "
                             f"generate with real='double', or change the units")
        printed = repr(value)
        return printed + suffix if any(ch in printed for ch in ".en") else printed + ".0" + suffix
    return text

