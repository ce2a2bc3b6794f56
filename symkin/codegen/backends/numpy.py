"""The NumPy backend: its printer and its template folder (one Python module per mechanism)."""

from __future__ import annotations

from typing import Any

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE

from symkin.codegen.backends.config import Backend
from symkin.codegen.symbols import symbol_text


class PythonPrinter(NumPyPrinter):
    """NumPy printer for the generated module: array arguments, ``numpy.`` functions."""

    def __init__(self) -> None:
        super().__init__({"strict": True})

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        return symbol_text(expr.name)

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        if expr.exp == 2:
            base = self.parenthesize(expr.base, PRECEDENCE["Mul"])
            return f"({base}*{base})"
        return str(super()._print_Pow(expr, rational))


def _printer(real: str) -> PythonPrinter:
    # NumPy computes in double; lower() refuses real="float" for this backend.
    del real
    return PythonPrinter()


def _literal(real: str) -> Any:
    del real
    return repr


BACKEND = Backend(name="numpy", template_folder="numpy", printer=_printer, literal=_literal,
                  module_template="kernel",
                  purposes={"kernel": "kinematic kernel of the mechanism {name}"})
