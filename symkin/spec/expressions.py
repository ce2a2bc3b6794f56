"""Safe expressions: a whitelist parser from user text to SymPy objects.

User text is never executed. It is parsed with :mod:`ast`, every node is checked against a short
whitelist, and the SymPy expression is built by hand from the accepted nodes. ``eval``,
``sympify`` and ``parse_expr`` are never applied to user text: all three can execute code.
"""

from __future__ import annotations

import ast
import math
import sys
import warnings
from collections.abc import Callable, Mapping, Sequence

import sympy as sp

from symkin.errors import ExpressionError
from symkin.limits import listed
from symkin.spec import constants

MAX_LENGTH = 1000
MAX_DEPTH = 60
MAX_EXPONENT = 64
MAX_DIGITS = 300
MAX_DERIVATIVE_OPS = 20000

# What a number-or-expression field may hold in a mechanism file.
RawExpr = int | float | str

_CONSTANTS: Mapping[str, sp.Expr] = {"pi": sp.pi, "E": sp.E}

_BINARY: Mapping[type, Callable[[sp.Expr, sp.Expr], sp.Expr]] = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
}

_COMPARE: Mapping[type, Callable[[sp.Expr, sp.Expr], sp.Basic]] = {
    ast.Lt: sp.Lt,
    ast.LtE: sp.Le,
    ast.Gt: sp.Gt,
    ast.GtE: sp.Ge,
}

# name -> (SymPy function, smallest and largest argument count)
FUNCTIONS: Mapping[str, tuple[Callable[..., sp.Expr], int, int]] = {
    "sin": (sp.sin, 1, 1),
    "cos": (sp.cos, 1, 1),
    "tan": (sp.tan, 1, 1),
    "exp": (sp.exp, 1, 1),
    "log": (sp.log, 1, 1),
    "sqrt": (sp.sqrt, 1, 1),
    "atan2": (sp.atan2, 2, 2),
    "asin": (sp.asin, 1, 1),
    "acos": (sp.acos, 1, 1),
    "atan": (sp.atan, 1, 1),
    "sinh": (sp.sinh, 1, 1),
    "cosh": (sp.cosh, 1, 1),
    "tanh": (sp.tanh, 1, 1),
    "Abs": (sp.Abs, 1, 1),
    "Min": (sp.Min, 2, 8),
    "Max": (sp.Max, 2, 8),
    "Heaviside": (lambda x: sp.Heaviside(x, sp.Rational(1, 2)), 1, 1),
}

_NODE_NAMES: Mapping[type, str] = {
    ast.Attribute: "attribute access (a.b)",
    ast.Lambda: "lambda",
    ast.Subscript: "indexing (a[i])",
    ast.Call: "this call",
    ast.BitXor: "'^' (use ** for powers)",
    ast.ListComp: "comprehensions",
    ast.GeneratorExp: "comprehensions",
    ast.IfExp: "'if' expressions (use Piecewise)",
    ast.BoolOp: "'and'/'or'",
    ast.NamedExpr: "':=' assignments",
    ast.JoinedStr: "strings",
}


def number(value: float) -> sp.Expr:
    """Turn a finite Python number into an exact SymPy number (0.05 -> 1/20)."""
    if isinstance(value, bool):
        raise ExpressionError(f"{value!r} is a boolean, not a number")
    if isinstance(value, int):
        return sp.Integer(value)
    if not math.isfinite(value):
        raise ExpressionError(f"{value!r} is not a finite number")
    if value != 0 and abs(value) < sys.float_info.min:
        # subnormal: a double keeps few of its digits, and products with it under- or
        # overflow in the generated code
        raise ExpressionError(f"{value!r} is below the smallest normal double "
                              f"({sys.float_info.min:.3g}) in magnitude: write 0, or use a "
                              "unit in which it is larger")
    # repr gives the shortest decimal that round-trips, i.e. what the user wrote.
    return sp.Rational(repr(value))


# body.x, body.y, body.phi and (in forces) their rates body.x_t, body.y_t, body.phi_t.
_COORDINATE_ATTRIBUTES = ("x", "y", "phi", "x_t", "y_t", "phi_t")


class _Builder:
    """Walks a checked AST and builds the SymPy expression."""

    def __init__(self, text: str, symbols: Mapping[str, sp.Symbol],
                 coordinates: Mapping[tuple[str, str], sp.Symbol]) -> None:
        self.text = text
        self.symbols = symbols
        self.coordinates = coordinates

    def fail(self, node: ast.AST, message: str) -> ExpressionError:
        return ExpressionError(message, self.text, getattr(node, "col_offset", None))

    def build(self, node: ast.AST, depth: int = 0) -> sp.Expr:
        if depth > MAX_DEPTH:
            raise self.fail(node, f"nested deeper than {MAX_DEPTH} levels")
        method = getattr(self, "_" + type(node).__name__, None)
        if method is None:
            what = _NODE_NAMES.get(type(node), type(node).__name__)
            raise self.fail(node, f"{what} is not allowed in an expression")
        return method(node, depth + 1)

    def _Constant(self, node: ast.Constant, depth: int) -> sp.Expr:
        if isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
            try:
                return number(node.value)
            except ExpressionError as error:
                raise self.fail(node, error.message) from None
        raise self.fail(node, f"the literal {node.value!r} is not a number")

    def _Name(self, node: ast.Name, depth: int) -> sp.Expr:
        if node.id in self.symbols:
            return self.symbols[node.id]
        if node.id in _CONSTANTS:
            return _CONSTANTS[node.id]
        known = sorted(self.symbols) + sorted(_CONSTANTS)
        raise self.fail(node, f"unknown name {node.id!r}; known names are {listed(known)}")

    def _Attribute(self, node: ast.Attribute, depth: int) -> sp.Expr:
        # Only `body.x`, `body.y`, `body.phi` in custom constraints; nothing else.
        if isinstance(node.value, ast.Name):
            key = (node.value.id, node.attr)
            if key in self.coordinates:
                return self.coordinates[key]
            parts = tuple(dict.fromkeys(part for _, part in self.coordinates))
            if self.coordinates and node.attr in (*_COORDINATE_ATTRIBUTES, *parts):
                bodies = listed(dict.fromkeys(body for body, _ in self.coordinates))
                planar = set(parts) <= {"x", "y", "phi"}
                said = ("body.x, body.y or body.phi" if planar else
                        ", ".join(f"body.{part}" for part in parts))
                raise self.fail(node, f"unknown coordinate '{key[0]}.{key[1]}'; use {said} "
                                      f"of a body among {bodies}")
        raise self.fail(node, "attribute access is not allowed (only body.x, body.y, "
                              "body.phi in custom constraints)")

    def _UnaryOp(self, node: ast.UnaryOp, depth: int) -> sp.Expr:
        operand = self.build(node.operand, depth)
        if isinstance(node.op, ast.USub):
            return -operand
        if isinstance(node.op, ast.UAdd):
            return operand
        raise self.fail(node, f"the operator {type(node.op).__name__} is not allowed")

    def _BinOp(self, node: ast.BinOp, depth: int) -> sp.Expr:
        left = self.build(node.left, depth)
        right = self.build(node.right, depth)
        if isinstance(node.op, ast.Pow):
            return self._power(node, left, right)
        operation = _BINARY.get(type(node.op))
        if operation is None:
            what = _NODE_NAMES.get(type(node.op), type(node.op).__name__)
            raise self.fail(node, f"the operator {what} is not allowed")
        return operation(left, right)

    def _power(self, node: ast.AST, base: sp.Expr, exponent: sp.Expr) -> sp.Expr:
        if exponent.is_Number and abs(exponent) > MAX_EXPONENT:
            raise self.fail(node, f"exponent {exponent} is larger than {MAX_EXPONENT}")
        if base.is_Rational and exponent.is_Number:
            # Exact powers of exact numbers are computed eagerly by SymPy: cap their size.
            digits = max(len(str(abs(base.p))), len(str(base.q))) * abs(exponent)
            if digits > MAX_DIGITS:
                raise self.fail(node, f"the power would have more than {MAX_DIGITS} digits")
        return sp.Pow(base, exponent)

    def _Call(self, node: ast.Call, depth: int) -> sp.Expr:
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only plain function names may be called")
        name = node.func.id
        if node.keywords:
            raise self.fail(node, f"keyword arguments are not allowed in {name}()")
        if any(isinstance(arg, ast.Starred) for arg in node.args):
            raise self.fail(node, f"*arguments are not allowed in {name}()")
        if name == "Piecewise":
            return self._piecewise(node, depth)
        if name not in FUNCTIONS:
            allowed = ", ".join(sorted(list(FUNCTIONS) + ["Piecewise"]))
            raise self.fail(node, f"unknown function {name!r}; allowed functions are {allowed}")
        function, fewest, most = FUNCTIONS[name]
        if not fewest <= len(node.args) <= most:
            count = str(fewest) if fewest == most else f"{fewest} to {most}"
            raise self.fail(node, f"{name}() takes {count} arguments, got {len(node.args)}")
        args = [self.build(arg, depth) for arg in node.args]
        try:
            return function(*args)
        except (TypeError, ValueError):  # e.g. Max(asin(7), 1): SymPy cannot order a non-real
            raise self.fail(node, f"the arguments of {name}() must be real") from None

    def _piecewise(self, node: ast.Call, depth: int) -> sp.Expr:
        pieces = []
        for arg in node.args:
            if not (isinstance(arg, ast.Tuple) and len(arg.elts) == 2):
                raise self.fail(arg, "Piecewise takes pairs (value, condition)")
            value, condition = arg.elts
            pieces.append((self.build(value, depth), self._condition(condition, depth)))
        if not pieces:
            raise self.fail(node, "Piecewise needs at least one (value, condition) pair")
        result = sp.Piecewise(*pieces)
        if result is sp.nan:
            raise self.fail(node, "no condition of this Piecewise can hold; end it with "
                                  "(value, True)")
        return result

    def _condition(self, node: ast.AST, depth: int) -> sp.Basic:
        if isinstance(node, ast.Constant) and node.value is True:
            return sp.true
        if isinstance(node, ast.Compare) and len(node.ops) == 1:
            relation = _COMPARE.get(type(node.ops[0]))
            if relation is not None:
                left = self.build(node.left, depth)
                right = self.build(node.comparators[0], depth)
                try:
                    return relation(left, right)
                except TypeError:  # SymPy refuses to order complex numbers
                    raise self.fail(node, "a Piecewise condition must compare real "
                                          "values") from None
        raise self.fail(node, "a Piecewise condition must be one comparison "
                              "(<, <=, >, >=) or True")


def parse(
    raw: RawExpr,
    symbols: Mapping[str, sp.Symbol],
    coordinates: Mapping[tuple[str, str], sp.Symbol] | None = None,
) -> sp.Expr:
    """Parse a number or an expression string into a SymPy expression.

    Args:
        raw: a Python int/float, or the text of an expression.
        symbols: the names the expression may use (parameters, and ``t`` where allowed).
        coordinates: ``(body, "x"|"y"|"phi") -> Symbol`` for custom constraints.

    Raises:
        ExpressionError: the text is not an expression symkin accepts.
    """
    if isinstance(raw, (int, float)) and not isinstance(raw, bool):
        return number(raw)
    if not isinstance(raw, str):
        raise ExpressionError(f"expected a number or an expression, got {type(raw).__name__}")
    text = raw.strip()
    if not text:
        raise ExpressionError("the expression is empty")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"the expression is longer than {MAX_LENGTH} characters")
    try:
        with warnings.catch_warnings():  # e.g. "1if": refused below, no warning on stderr
            warnings.simplefilter("ignore", SyntaxWarning)
            tree = ast.parse(text, mode="eval")
    except SyntaxError as error:
        column = (error.offset - 1) if error.offset else None
        raise ExpressionError("this is not a valid expression", text, column) from None
    except (RecursionError, MemoryError):
        raise ExpressionError("this expression is too deeply nested", text) from None
    except ValueError:  # e.g. a NUL character (Python 3.11)
        raise ExpressionError("this is not a valid expression", text) from None
    expr = _Builder(text, symbols, coordinates or {}).build(tree.body)
    if expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise ExpressionError("the expression is not finite (a division by zero?)", text)
    if expr.has(sp.I):
        raise ExpressionError("the expression is not real (the root or logarithm of a "
                              "negative number?)", text)
    try:
        constants.check_constants(expr)
    except ExpressionError as error:
        raise ExpressionError(error.message, text) from None
    return expr


# What the code printers of every backend can print: the nodes the parser builds, and those
# SymPy's derivatives of them introduce (sign from Abs, DiracDelta from Heaviside).
_PRINTABLE: tuple[type, ...] = (
    sp.Symbol, sp.Number, sp.NumberSymbol, sp.Add, sp.Mul, sp.Pow, sp.Piecewise,
    sp.sign, sp.DiracDelta, sp.Heaviside, sp.Min, sp.Max, sp.Abs, sp.exp, sp.log,
    sp.sin, sp.cos, sp.tan, sp.asin, sp.acos, sp.atan, sp.atan2, sp.sinh, sp.cosh, sp.tanh,
    sp.core.relational.Relational, sp.logic.boolalg.BooleanAtom, sp.functions.elementary.
    piecewise.ExprCondPair,
)


def check_derivatives(expr: sp.Expr, variables: Sequence[sp.Symbol], text: str) -> None:
    """Refuse an expression whose first or second derivatives need functions no backend
    prints (``Abs(t**t)`` differentiates into ``re`` and ``im``), or grow past the size limit.

    Raises:
        ExpressionError: naming the function that appeared, or the size.
    """
    first = [sp.diff(expr, v) for v in variables]
    # The second derivatives are symmetric: each pair once.
    second = [sp.diff(first[i], variables[j]) for i in range(len(variables))
              for j in range(i, len(variables))]
    for derivative in [expr, *first, *second]:
        if sp.count_ops(derivative) > MAX_DERIVATIVE_OPS:
            raise ExpressionError(f"its derivatives grow past {MAX_DERIVATIVE_OPS} operations; "
                                  f"simplify it", text)
        for node in sp.preorder_traversal(derivative):
            if not isinstance(node, _PRINTABLE):
                raise ExpressionError(
                    f"its derivative needs {type(node).__name__}(), which symkin cannot "
                    f"generate code for (is every argument of Abs, log and powers real "
                    f"for every t?)", text)


def parse_time_function(raw: RawExpr | Mapping[str, Sequence[RawExpr]],
                        symbols: Mapping[str, sp.Symbol], t: sp.Symbol) -> sp.Expr:
    """Parse a driver's time function: an expression of t, or ``{poly: [a0, a1, ...]}`` (2.75)."""
    if isinstance(raw, Mapping):
        coefficients = raw["poly"]
        return sp.Add(*(parse(a, symbols) * t**k for k, a in enumerate(coefficients)))
    return parse(raw, {**symbols, "t": t})
