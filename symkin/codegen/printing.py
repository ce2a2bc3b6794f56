"""Printing helpers more than one backend's printer shares: code generation's, below the
backends, so that no backend imports another's printer (the import-linter contract "Backends
do not import each other" covers their printers too)."""

from __future__ import annotations

from typing import Any

import sympy as sp


class PairwiseMinMax:
    """``Min``/``Max`` of any number of arguments as nested calls of a two-argument function
    of the language (``MIN_FUNCTION``, ``MAX_FUNCTION``), in the arguments' order:
    ``Min(a, b, c)`` -> ``f(a, f(b, c))``. The functions chosen give the other argument where
    one is NaN (IEEE 754's minNum and maxNum): the generated code of every backend treats NaN
    alike.

    A mix-in for a SymPy code printer (it calls the printer's ``_print``).
    """

    MIN_FUNCTION: str
    MAX_FUNCTION: str

    def _print_Min(self, expr: sp.Min) -> str:
        return self._nested(self.MIN_FUNCTION, expr.args)

    def _print_Max(self, expr: sp.Max) -> str:
        return self._nested(self.MAX_FUNCTION, expr.args)

    def _nested(self, function: str, args: tuple[sp.Expr, ...]) -> str:
        printer: Any = self
        text = str(printer._print(args[-1]))
        for arg in reversed(args[:-1]):
            text = f"{function}({printer._print(arg)}, {text})"
        return text


def heaviside_at_zero(expr: sp.Heaviside) -> float:
    """The value a step takes at 0: its second argument, else 1/2 (the value the parser gives
    every Heaviside)."""
    return float(expr.args[1]) if len(expr.args) > 1 else 0.5
