"""The NumPy backend's printer: SymPy expressions as NumPy text (double precision only)."""

from __future__ import annotations

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE

from symkin.codegen.symbol_printing import symbol_text


class PythonPrinter(NumPyPrinter):
    """NumPy printer for the generated module: array arguments, ``numpy.`` functions."""

    def __init__(self) -> None:
        super().__init__({"strict": True})

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        return symbol_text(expr.name)

    def _print_Float(self, expr: sp.Float) -> str:
        return repr(float(expr))

    def _print_Heaviside(self, expr: sp.Heaviside) -> str:
        at_zero = float(expr.args[1]) if len(expr.args) > 1 else 0.5
        return f"numpy.heaviside({self._print(expr.args[0])}, {at_zero!r})"

    def _print_Min(self, expr: sp.Min) -> str:
        return self._nested("numpy.fmin", expr.args)

    def _print_Max(self, expr: sp.Max) -> str:
        return self._nested("numpy.fmax", expr.args)

    def _nested(self, function: str, args: tuple[sp.Expr, ...]) -> str:
        # fmin/fmax, as in C: the generated code of both backends treats NaN alike.
        text = str(self._print(args[-1]))
        for arg in reversed(args[:-1]):
            text = f"{function}({self._print(arg)}, {text})"
        return text

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        if expr.exp == 2:
            base = self.parenthesize(expr.base, PRECEDENCE["Mul"])
            return f"({base}*{base})"
        return str(super()._print_Pow(expr, rational))

