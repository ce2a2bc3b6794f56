"""How a symbol of the derivation appears in generated code: an array element or a temporary.

The printers of every backend map symbols through :func:`symbol_text`; a name from the
mechanism file can never reach generated code, because only internal names are mapped.
"""

from __future__ import annotations

import re

import sympy as sp

from symkin.errors import BuildError, ExpressionError
from symkin.spec import constants
from symkin.spec.substitution import Substitution
from symkin.symbolic.derivation import System

_INTERNAL = re.compile(r"_(q|dq|ddq|lam|p|shared)(\d+)\Z")
_TEMPORARY = re.compile(r"w\d+\Z")


def symbol_text(name: str) -> str:
    """The code for a symbol: ``_q3`` -> ``q[3]``, ``_t`` -> ``t``, temporaries as they are.

    ``_shared2`` -> ``shared[2]``: a value the fused routine computed once (a sine or cosine of
    coordinates) and passes on to Phi_t and Gamma at the same q (codegen.lower).

    Anything else would be a name from the mechanism file reaching the code, so it is refused.
    """
    if name == "_t":
        return "t"
    match = _INTERNAL.match(name)
    if match:
        return f"{match.group(1)}[{match.group(2)}]"
    if _TEMPORARY.match(name):
        return name
    raise BuildError(f"internal error: the symbol {name!r} is not an argument of the generated "
                     "function")


def internal_symbols(system: System) -> dict[sp.Symbol, sp.Symbol]:
    """User symbols -> internal symbols whose names the printers turn into array accesses."""
    mapping = {system.t: sp.Symbol("_t", real=True)}
    # The inputs' u, du, ddu follow the parameters in p[] (System.code_parameters).
    arrays = [("q", system.q), ("dq", system.dq), ("p", system.code_parameters)]
    if system.dynamics is not None:  # accelerations and multipliers (inverse dynamics)
        arrays += [("ddq", system.dynamics.ddq), ("lam", system.dynamics.lam)]
    for prefix, symbols in arrays:
        mapping.update({s: sp.Symbol(f"_{prefix}{k}", real=True) for k, s in enumerate(symbols)})
    return mapping


def prepare(expr: sp.Expr, internal: dict[sp.Symbol, sp.Symbol]) -> sp.Expr:
    """Internal symbols, no DiracDelta, and every constant part a plain number (one
    expression; :class:`Preparer` for many)."""
    return Preparer(internal)(expr)


class Preparer:
    """Prepares expressions for printing: internal symbols, no DiracDelta, and every constant
    part a plain number.

    Constants are folded to correctly rounded doubles (:func:`constants.fold`'s rule: each
    largest constant part that is not a plain number becomes its value), so no printer ever
    meets ``sqrt(2)`` (C99 would print the POSIX macro ``M_SQRT2``) or an integer wider than a
    C integer constant.

    One pass rebuilds each distinct subtree once, remembered across every expression it is
    given: a piecewise cam profile's derivatives recur in many rows of Phi_q and Gamma, and
    rebuilding a Piecewise re-evaluates its conditions, which dominated the lowering when each
    row was substituted and then folded on its own (two full rebuilds per row).
    """

    def __init__(self, internal: dict[sp.Symbol, sp.Symbol]) -> None:
        self._rebuild = Substitution(internal, fold=True)

    def __call__(self, expr: sp.Expr) -> sp.Expr:
        """Raises:
            BuildError: a constant part has no finite real value.
        """
        expr = sp.sympify(expr)
        # d/dx Heaviside is DiracDelta, which is zero wherever it can be evaluated in floats.
        if expr.has(sp.DiracDelta):
            expr = expr.replace(lambda e: isinstance(e, sp.DiracDelta),
                                lambda e: sp.Integer(0))
        try:
            return self._rebuild(expr)
        except ExpressionError as error:
            raise BuildError(f"cannot generate code for {constants.describe(expr)}: "
                             f"{error.message}") from None
