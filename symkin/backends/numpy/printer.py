"""The NumPy backend's printer: SymPy expressions as NumPy text (double precision only)."""

from __future__ import annotations

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE

from symkin.codegen.printing import PairwiseMinMax, heaviside_at_zero
from symkin.codegen.symbol_printing import symbol_text


class PythonPrinter(PairwiseMinMax, NumPyPrinter):
    """NumPy printer for the generated module: array arguments, ``numpy.`` functions."""

    # fmin/fmax, as in C: the generated code of both backends treats NaN alike.
    MIN_FUNCTION = "numpy.fmin"
    MAX_FUNCTION = "numpy.fmax"

    def __init__(self) -> None:
        super().__init__({"strict": True})

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        return symbol_text(expr.name)

    def _print_Float(self, expr: sp.Float) -> str:
        return repr(float(expr))

    def _print_Heaviside(self, expr: sp.Heaviside) -> str:
        return f"numpy.heaviside({self._print(expr.args[0])}, {heaviside_at_zero(expr)!r})"

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        if expr.exp == 2:
            base = self.parenthesize(expr.base, PRECEDENCE["Mul"])
            return f"({base}*{base})"
        return str(super()._print_Pow(expr, rational))

