"""Bounded numeric evaluation of expressions: a value, or a refusal that says why.

SymPy's own evaluation (``float(expr)``, ``evalf``) raises the working precision until it is
sure of the digits it returns, so ``sin(exp(100000000))`` takes many minutes. Here an
expression tree is evaluated with mpmath at a fixed ladder of precisions (120 bits, doubled up
to 1920): two successive precisions must agree to double precision, or the value is refused.
Arguments no double-precision code could evaluate meaningfully are refused before any work is
done: trigonometric arguments beyond 1e15, magnitudes beyond 1e300.

The same evaluator serves validation (a parameter, a point, the time grid at the nominal
parameter values) and code generation (constant parts of an expression become correctly
rounded literals, :func:`fold`), so what is accepted is what is generated.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, TypeAlias

import mpmath
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from symkin.errors import ExpressionError

START_BITS = 120
MAX_BITS = 1920
MAX_MAGNITUDE = 1e300
MAX_TRIG_ARGUMENT = 1e15
# Integers and rationals are printed exactly up to here; beyond, as correctly rounded reals
# (a C integer constant wider than long long is truncated, and no double holds more digits).
MAX_EXACT_INTEGER = 2**53

# An mpmath real (mpmath ships no type information).
_Number: TypeAlias = Any


QUOTE_LENGTH = 80
"""The longest quote of an expression in a message."""


def describe(expr: sp.Basic, length: int = QUOTE_LENGTH) -> str:
    """``expr`` as a message quotes it: each number of more than 12 characters in six
    significant digits (an exact integer of 300 digits is no help cut at 80), then the whole
    cut to ``length`` with an ellipsis."""
    numbers = {n: sp.Float(n, 6) for n in expr.atoms(sp.Number)
               if len(sp.sstr(n)) > 12 and mpmath.isfinite(mpmath.mpf(n.evalf(6)))}
    text = str(sp.sstr(expr.xreplace(numbers) if numbers else expr))
    return text if len(text) <= length else text[: length - 1] + "…"


class _Refused(Exception):
    """Inside the evaluator: the expression has no finite real value symkin will compute."""


def _check(x: _Number, what: str) -> _Number:
    if not mpmath.isfinite(x):
        raise _Refused(f"{what} is not finite")
    if abs(x) > MAX_MAGNITUDE:
        raise _Refused(f"{what} is larger than {MAX_MAGNITUDE:g} in magnitude")
    return x


def _trig(function: Callable[[_Number], _Number], name: str) -> Callable[[_Number], _Number]:
    def evaluate(x: _Number) -> _Number:
        if abs(x) > MAX_TRIG_ARGUMENT:
            raise _Refused(f"the argument of {name} is larger than {MAX_TRIG_ARGUMENT:g}: no "
                           f"double-precision code can evaluate it meaningfully")
        return function(x)
    return evaluate


def _domain(function: Callable[[_Number], _Number], name: str,
            inside: Callable[[_Number], bool], where: str) -> Callable[[_Number], _Number]:
    def evaluate(x: _Number) -> _Number:
        if not inside(x):
            raise _Refused(f"{name} of {mpmath.nstr(x, 6)} is not real ({where})")
        return function(x)
    return evaluate


def _exponential(function: Callable[[_Number], _Number], name: str
                 ) -> Callable[[_Number], _Number]:
    def evaluate(x: _Number) -> _Number:
        if abs(x) > 709:
            if name == "exp" and x < 0:
                return mpmath.mpf(0)
            raise _Refused(f"{name} of {mpmath.nstr(x, 6)} is larger than the largest double")
        return function(x)
    return evaluate


def _atan2(y: _Number, x: _Number) -> _Number:
    if x == 0 and y == 0:
        raise _Refused("atan2(0, 0) is undefined")
    return mpmath.atan2(y, x)


def _heaviside(x: _Number, at_zero: _Number | None = None) -> _Number:
    # SymPy's Heaviside(x) is 1/2 at 0, the value the parser also gives explicitly.
    if x == 0:
        return mpmath.mpf(0.5) if at_zero is None else at_zero
    return mpmath.mpf(1) if x > 0 else mpmath.mpf(0)


def _sign(x: _Number) -> _Number:
    return mpmath.mpf(mpmath.sign(x))


_FUNCTIONS: Mapping[type, Callable[..., _Number]] = {
    sp.sin: _trig(mpmath.sin, "sin"),
    sp.cos: _trig(mpmath.cos, "cos"),
    sp.tan: _trig(mpmath.tan, "tan"),
    sp.exp: _exponential(mpmath.exp, "exp"),
    sp.sinh: _exponential(mpmath.sinh, "sinh"),
    sp.cosh: _exponential(mpmath.cosh, "cosh"),
    sp.tanh: mpmath.tanh,
    sp.log: _domain(mpmath.log, "log", lambda x: x > 0, "log needs a positive argument"),
    sp.asin: _domain(mpmath.asin, "asin", lambda x: -1 <= x <= 1, "asin needs -1 <= x <= 1"),
    sp.acos: _domain(mpmath.acos, "acos", lambda x: -1 <= x <= 1, "acos needs -1 <= x <= 1"),
    sp.atan: mpmath.atan,
    sp.atan2: _atan2,
    sp.Abs: abs,
    sp.sign: _sign,
    sp.Heaviside: _heaviside,
    sp.Min: lambda *xs: min(xs),
    sp.Max: lambda *xs: max(xs),
}

_RELATIONS: Mapping[type, Callable[[_Number, _Number], bool]] = {
    sp.StrictLessThan: lambda a, b: bool(a < b),
    sp.LessThan: lambda a, b: bool(a <= b),
    sp.StrictGreaterThan: lambda a, b: bool(a > b),
    sp.GreaterThan: lambda a, b: bool(a >= b),
    sp.Equality: lambda a, b: bool(a == b),
    sp.Unequality: lambda a, b: bool(a != b),
}


class _Evaluator:
    """One evaluation of a tree at the current mpmath precision."""

    def __init__(self, values: Mapping[sp.Symbol, float]) -> None:
        self.values = values
        self.scale = mpmath.mpf(0)  # the largest magnitude met on the way

    def __call__(self, node: sp.Basic) -> _Number:
        result = _check(self._node(node), describe(node))
        self.scale = max(self.scale, abs(result))
        return result

    def _node(self, node: sp.Basic) -> _Number:
        if isinstance(node, sp.Rational):
            return mpmath.mpf(node.p) / node.q
        if isinstance(node, sp.Float):
            return mpmath.mpf(node._mpf_)
        if node is sp.pi:
            return +mpmath.pi
        if node is sp.E:
            return +mpmath.e
        if isinstance(node, sp.Symbol):
            if node not in self.values:
                raise _Refused(f"{node} has no value here")
            return mpmath.mpf(self.values[node])
        if isinstance(node, sp.Add):
            return mpmath.fsum(self(arg) for arg in node.args)
        if isinstance(node, sp.Mul):
            return mpmath.fprod(self(arg) for arg in node.args)
        if isinstance(node, sp.Pow):
            return self._power(node)
        if isinstance(node, sp.Piecewise):
            return self._piecewise(node)
        if isinstance(node, sp.DiracDelta):
            return mpmath.mpf(0)  # zero wherever it can be evaluated in floats
        function = _FUNCTIONS.get(type(node))
        if function is None:
            raise _Refused(f"symkin cannot evaluate {type(node).__name__}")
        return function(*(self(arg) for arg in node.args))

    def _power(self, node: sp.Pow) -> _Number:
        base = self(node.base)
        exponent = node.exp
        if isinstance(exponent, sp.Integer):
            if base == 0 and exponent < 0:
                raise _Refused(f"{describe(node)} divides by zero")
            return base ** int(exponent)
        power = self(exponent)
        if base < 0:
            raise _Refused(f"{describe(node)} is a fractional power of a negative number, "
                           f"which is not real")
        if base == 0 and power <= 0:
            raise _Refused(f"{describe(node)} divides by zero")
        if base > 0 and power * mpmath.log(base) > 709:
            raise _Refused(f"{describe(node)} is larger than the largest double")
        return base**power

    def _piecewise(self, node: sp.Piecewise) -> _Number:
        for value, condition in node.args:
            if self._holds(condition):
                return self(value)
        raise _Refused("no condition of a Piecewise holds")

    def _holds(self, condition: sp.Basic) -> bool:
        if condition is sp.true:
            return True
        if condition is sp.false:
            return False
        relation = _RELATIONS.get(type(condition))
        if relation is None:
            raise _Refused(f"symkin cannot evaluate the condition {condition}")
        return relation(self(condition.lhs), self(condition.rhs))


def value(expr: sp.Basic, values: Mapping[sp.Symbol, float] | None = None) -> float:
    """The value of ``expr`` as a double, with its symbols set to ``values``.

    Raises:
        ExpressionError: the value is not a finite real number, needs more than the bounded
            precision to be known to double precision, or is beyond what a double holds.
    """
    values = values or {}
    previous: tuple[float, bool] | None = None
    bits = START_BITS
    while bits <= MAX_BITS:
        evaluator = _Evaluator(values)
        try:
            with mpmath.workprec(bits):
                result = evaluator(expr)
        except _Refused as why:
            raise ExpressionError(str(why)) from None
        number = float(result)
        # Below the rounding noise of the largest intermediate: zero at this precision.
        noise = abs(result) <= evaluator.scale * mpmath.mpf(2) ** (8 - bits)
        if previous is not None:
            if _agree(previous[0], number):
                return number
            if previous[1] and noise:
                return 0.0
        previous = (number, noise)
        bits *= 2
    raise ExpressionError(f"its value is not known to double precision at {MAX_BITS} bits of "
                          f"working precision (it cancels too much)")


def _agree(a: float, b: float) -> bool:
    return a == b or abs(a - b) <= 4 * 2.0**-53 * max(abs(a), abs(b))


def is_plain_number(expr: sp.Basic) -> bool:
    """A number every backend prints exactly: a float, or a not too large integer/rational."""
    if isinstance(expr, sp.Float):
        return True
    if isinstance(expr, sp.Rational):
        return bool(abs(expr.p) <= MAX_EXACT_INTEGER and expr.q <= MAX_EXACT_INTEGER)
    return False


def fold(expr: sp.Expr) -> sp.Expr:
    """Replace each largest constant part of ``expr`` that is not a plain number by its value.

    ``sqrt(2)*t`` -> ``1.4142135623730951*t``; ``Min(c, 18446744073709551617)`` keeps c and
    folds the integer to the nearest double. The printers then only ever see plain numbers.

    Raises:
        ExpressionError: a constant part has no value (see :func:`value`).
    """
    replacements: dict[sp.Basic, sp.Basic] = {}
    symbolic: dict[sp.Basic, bool] = {}
    seen: set[sp.Basic] = set()

    def visit(node: sp.Basic) -> None:
        if node in seen:  # a shared subtree: its replacements are made
            return
        seen.add(node)
        if isinstance(node, sp.Expr) and not has_symbols(node, symbolic):
            if not is_plain_number(node):
                replacements[node] = sp.Float(value(node), 17)
            return
        for arg in node.args:
            visit(arg)

    visit(expr)
    return expr.xreplace(replacements) if replacements else expr


_UNION_OF_ARGS: dict[type, bool] = {}


def _union_of_args(kind: type) -> bool:
    """The class takes free_symbols from Basic (the union over its args). Looked up in the
    classes' own dictionaries: a function class's metaclass has a free_symbols of its own."""
    found = _UNION_OF_ARGS.get(kind)
    if found is None:
        owner = next(k for k in kind.__mro__ if "free_symbols" in k.__dict__)
        found = _UNION_OF_ARGS[kind] = owner is sp.Basic
    return found


def has_symbols(node: sp.Basic, known: dict[sp.Basic, bool]) -> bool:
    """``bool(node.free_symbols)``, remembered per subtree: SymPy recomputes free_symbols
    over the whole subtree at every call, so asking it at each node of a tree costs its size
    times its depth. A class with its own free_symbols (a symbol, a Derivative's bound
    variables) is asked itself."""
    found = known.get(node)
    if found is None:
        if _union_of_args(type(node)):
            found = any(has_symbols(arg, known) for arg in node.args)
        else:
            found = bool(node.free_symbols)
        known[node] = found
    return found


def numpy_modules() -> list[Any]:
    """lambdify's ``modules`` for NumPy: the module itself, whose names the printed function
    looks up where it uses them, and the one name the string "numpy" adds (I). The string would
    run ``from numpy import *``, which loads every lazy submodule of NumPy (f2py, testing, ...;
    0.1-0.15 s of a cold ``symkin generate``)."""
    import numpy

    return [{"I": 1j}, numpy]


class _AnalysisPrinter(NumPyPrinter):  # type: ignore[misc]  # SymPy is untyped
    """SymPy's NumPy printer with every sum and product written as its arguments joined, in
    parentheses, in the order SymPy keeps them: no sorting for display and no precedence
    rules to consult (most of the printer's time)."""

    def _print_Add(self, expr: sp.Expr, order: Any = None) -> str:
        return "(" + " + ".join([self._print(arg) for arg in expr.args]) + ")"

    def _print_Mul(self, expr: sp.Expr) -> str:
        return "(" + "*".join([self._print(arg) for arg in expr.args]) + ")"

    def _print_Piecewise(self, expr: sp.Expr) -> str:
        """Python's conditional expression, which evaluates the piece whose condition holds:
        NumPy's ``select`` evaluates every piece and costs microseconds even on scalars (a
        cam profile's Phi_q holds a thousand of them; its sample's Newton took seconds). The
        analyses call with scalars only (q[i], t, p[k]), for which both give the same value.
        A constant piece and the NaN past the last condition are made NumPy doubles, so that
        arithmetic on them keeps IEEE semantics (no ZeroDivisionError), as ``select``'s."""
        double = self._module_format("numpy.float64")
        text = f"{double}({self._print(sp.S.NaN)})"
        for piece, condition in reversed(expr.args):
            value = self._print(piece)
            if not piece.free_symbols:
                value = f"{double}({value})"
            text = (value if condition is sp.true
                    else f"(({value}) if ({self._condition(condition)}) else ({text}))")
        return text

    def _condition(self, condition: sp.Basic) -> str:
        """A piece's condition as NumPy's printer writes it for ``select`` (an ITE in it
        simplified first)."""
        if condition.has(sp.ITE):
            return str(self._print(sp.simplify_logic(condition)))
        return str(self._print(condition))


def lambdify_analysis(arguments: Any, expressions: Any, dummify: bool = False
                      ) -> Callable[..., Any]:
    """``sympy.lambdify`` to NumPy for an analysis made at generation time (an assembly, a
    rank, the samples of a pivot order), printed fast (:class:`_AnalysisPrinter`; SymPy's own
    printer where Python refuses the nesting), with no walk of the expressions for implemented
    functions (a derivation has none). A sum may round in the last bit otherwise than the
    generated code's; what these analyses decide (pivots, ranks, removed rows) does not hang
    on that."""
    modules = numpy_modules()
    # the settings lambdify gives its own NumPy printer, and the names of the dict module
    settings = {"fully_qualified_modules": False, "inline": True,
                "allow_unknown_functions": True, "order": "none",
                "user_functions": {name: name for name in modules[0]}}
    function: Callable[..., Any]
    try:
        function = sp.lambdify(arguments, expressions, modules=modules, use_imps=False,
                               printer=_AnalysisPrinter(settings), dummify=dummify)
    except (SyntaxError, RecursionError):  # parentheses nested deeper than Python takes
        function = sp.lambdify(arguments, expressions, modules=modules, use_imps=False,
                               printer=NumPyPrinter(settings), dummify=dummify)
    return function


def lambdify_floats(arguments: Any, expressions: Any, modules: Any = None,
                    dummify: bool = False, cse: bool = False) -> Callable[..., Any]:
    """``sympy.lambdify`` of ``expressions`` (an expression, a sequence or a matrix of them)
    with every constant part folded to a double first (:func:`fold`).

    Without the folding an exact number reaches NumPy as it is: a long decimal read as a
    rational, or ``sqrt`` of an integer wider than 64 bits, becomes a Python int that NumPy
    holds as an object and its ufuncs refuse ("no callable sqrt method"). Every numeric
    evaluation of derived expressions goes through here, so each sees the doubles the
    generated code sees.

    Raises:
        ExpressionError: a constant part has no value (see :func:`value`).
    """
    if isinstance(expressions, sp.MatrixBase):
        folded: Any = expressions.applyfunc(fold)
    elif isinstance(expressions, sp.Basic):
        folded = fold(expressions)
    else:
        folded = [fold(sp.sympify(e)) for e in expressions]
    if dummify:
        arguments, folded, dummify = _renamed(arguments, folded)
    if modules is None:  # NumPy (numpy_modules: the module itself, not the string)
        modules = numpy_modules()
    function: Callable[..., Any] = sp.lambdify(arguments, folded, modules=modules,
                                               dummify=dummify, cse=cse)
    return function


def _renamed(arguments: Any, folded: Any) -> tuple[Any, Any, bool]:
    """The argument symbols replaced by plain identifiers ``_a0``, ``_a1``, ... in one pass
    over the expressions, which is what ``dummify`` asks of lambdify: lambdify itself walks
    the whole expression once per argument (quadratic in a file's size). Where a name could
    collide with another symbol of the expressions, lambdify dummifies as before."""

    def leaves(item: Any) -> list[Any]:
        if isinstance(item, (list, tuple)):
            return [leaf for part in item for leaf in leaves(part)]
        return [item]

    symbols = leaves(arguments)
    if not all(isinstance(s, sp.Symbol) for s in symbols) or len(set(symbols)) < len(symbols):
        return arguments, folded, True
    names = {s: sp.Symbol(f"_a{k}") for k, s in enumerate(symbols)}
    whole = isinstance(folded, (sp.Basic, sp.MatrixBase))
    others = (folded.free_symbols if whole else
              set().union(set(), *(sp.sympify(e).free_symbols for e in folded)))
    if any(s.name.startswith("_a") for s in others if s not in names):
        return arguments, folded, True

    def rename(item: Any) -> Any:
        if isinstance(item, (list, tuple)):
            return type(item)(rename(part) for part in item)
        return names[item]

    renamed = (folded.xreplace(names) if whole
               else [sp.sympify(e).xreplace(names) for e in folded])
    return rename(arguments), renamed, False


def check_constants(expr: sp.Expr) -> None:
    """Evaluate every largest constant part of ``expr`` once, so a constant with no value (or
    one the bounded evaluator refuses) is reported where the expression is written."""
    fold(expr)
