"""The Octave backend's printer: SymPy expressions as MATLAB/Octave text that runs unchanged
in both (element-wise operators, 1-based array elements, no Octave-only syntax)."""

from __future__ import annotations

import re

import sympy as sp
from sympy.printing.octave import OctaveCodePrinter
from sympy.printing.precedence import PRECEDENCE

from symkin.codegen.symbol_printing import symbol_text
from symkin.octave_process import number as literal

_ELEMENT = re.compile(r"(\w+)\[(\d+)\]\Z")


class MatlabPrinter(OctaveCodePrinter):
    """SymPy's Octave printer held to the subset MATLAB shares: the arguments' elements are
    ``q(k+1)``, a step function is a comparison (MATLAB's ``heaviside`` needs a toolbox)."""

    def __init__(self) -> None:
        super().__init__({"strict": True, "inline": True})

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        text = symbol_text(expr.name)
        element = _ELEMENT.match(text)
        # symbol_text writes 0-based C/Python elements; MATLAB counts from 1.
        return f"{element.group(1)}({int(element.group(2)) + 1})" if element else text

    def _print_Float(self, expr: sp.Float) -> str:
        return literal(float(expr))

    def _print_Heaviside(self, expr: sp.Heaviside) -> str:
        at_zero = float(expr.args[1]) if len(expr.args) > 1 else 0.5
        argument = self._print(expr.args[0])
        return f"((({argument}) > 0) + {literal(at_zero)}*(({argument}) == 0))"

    def _print_Min(self, expr: sp.Min) -> str:
        return self._nested("min", expr.args)

    def _print_Max(self, expr: sp.Max) -> str:
        return self._nested("max", expr.args)

    def _nested(self, function: str, args: tuple[sp.Expr, ...]) -> str:
        # min/max of two, as C's fmin/fmax: a NaN argument gives the other one.
        text = str(self._print(args[-1]))
        for arg in reversed(args[:-1]):
            text = f"{function}({self._print(arg)}, {text})"
        return text

    def _print_Pow(self, expr: sp.Pow) -> str:
        if expr.exp == 2:
            base = self.parenthesize(expr.base, PRECEDENCE["Mul"])
            return f"({base}.*{base})"
        return str(super()._print_Pow(expr))
