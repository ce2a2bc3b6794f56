"""The Octave backend's printer: SymPy expressions as MATLAB/Octave text that runs unchanged
in both (element-wise operators, 1-based array elements, no Octave-only syntax)."""

from __future__ import annotations

import re

import sympy as sp
from sympy.printing.octave import OctaveCodePrinter
from sympy.printing.precedence import PRECEDENCE

from symkin.codegen.printing import PairwiseMinMax, heaviside_at_zero
from symkin.codegen.symbol_printing import symbol_text
from symkin.octave_process import number as literal

_ELEMENT = re.compile(r"(\w+)\[(\d+)\]\Z")


class MatlabPrinter(PairwiseMinMax, OctaveCodePrinter):
    """SymPy's Octave printer held to the subset MATLAB shares: the arguments' elements are
    ``q(k+1)``, a step function is a comparison (MATLAB's ``heaviside`` needs a toolbox)."""

    # min/max of two, as C's fmin/fmax: a NaN argument gives the other one.
    MIN_FUNCTION = "min"
    MAX_FUNCTION = "max"

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
        argument = self._print(expr.args[0])
        return (f"((({argument}) > 0) + {literal(heaviside_at_zero(expr))}"
                f"*(({argument}) == 0))")

    def _print_Pow(self, expr: sp.Pow) -> str:
        if expr.exp == 2:
            base = self.parenthesize(expr.base, PRECEDENCE["Mul"])
            return f"({base}.*{base})"
        return str(super()._print_Pow(expr))
