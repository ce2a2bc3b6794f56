"""The C99 backend: its printer, its template folder and how it names files and literals."""

from __future__ import annotations

import math
from typing import Any

import sympy as sp
from sympy.codegen.ast import float32, float64
from sympy.codegen.ast import real as real_type
from sympy.printing.c import C99CodePrinter
from sympy.printing.precedence import PRECEDENCE

from symkin.codegen.backends.config import Backend
from symkin.codegen.symbols import symbol_text


class CPrinter(C99CodePrinter):
    """C99 printer for generated kernels: array arguments, literal constants, no ``pow(x, 2)``.

    ``M_PI`` is not part of C99 (it is POSIX), so pi and e are printed as literals; in float mode
    the base class already prints ``sinf``/``0.5F``, so nothing is promoted to double.
    """

    def __init__(self, real: str = "double") -> None:
        alias = float32 if real == "float" else float64
        super().__init__({"type_aliases": {real_type: alias}, "strict": True})
        self._suffix = "F" if real == "float" else ""

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        return symbol_text(expr.name)

    def _print_Pi(self, expr: Any) -> str:
        return repr(math.pi) + self._suffix

    def _print_Exp1(self, expr: Any) -> str:
        return repr(math.e) + self._suffix

    def _print_Pow(self, expr: sp.Pow) -> str:
        # A square is the most common power in kinematics; a product is exact and cheaper.
        if expr.exp == 2:
            base = self.parenthesize(expr.base, PRECEDENCE["Mul"])
            return f"({base}*{base})"
        return str(super()._print_Pow(expr))


def literal(real: str) -> Any:
    """A C literal of the real type: full precision for double, ``F`` suffix for float."""
    suffix = "F" if real == "float" else ""

    def text(value: float) -> str:
        printed = repr(float(value))
        return printed + suffix if any(ch in printed for ch in ".en") else printed + ".0" + suffix
    return text


PURPOSES = {
    "kernel": "kinematic kernel of the mechanism {name}: Phi, Phi_q, Phi_t, Gamma, points",
    "solver": "position, velocity and acceleration analysis of {name} (Example 2.6)",
    "linalg": "the solver's linear algebra on the dense LU",
    "sparse_lu": "sparse LU of Phi_q with its pivot order fixed at generation time",
    "dense_lu": "dense LU with partial pivoting (also the sparse LU's fall-back)",
}

BACKEND = Backend(name="c", template_folder="c", printer=CPrinter, literal=literal,
                  module_template="kernel", purposes=PURPOSES)
