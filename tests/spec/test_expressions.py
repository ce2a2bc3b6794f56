"""The whitelist expression parser: attacks are refused, arithmetic is exact.

The reference values here are computed independently of SymPy: with Python's Fraction for
exact arithmetic (a hypothesis property over random expression trees) and with math for
functions.
"""

from __future__ import annotations

import ast
import inspect
import math
import warnings
from fractions import Fraction

import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from symkin.errors import ExpressionError
from symkin.spec import expressions
from symkin.spec.expressions import parse, parse_time_function

t = sp.Symbol("t", real=True)
a = sp.Symbol("a", real=True)
NAMES = {"t": t, "a": a}
COORDINATES = {("crank", "phi"): sp.Symbol("crank.phi", real=True)}


# ----- attacks ---------------------------------------------------------------------------------

ATTACKS = {
    "__import__('os').system('ls')": "only plain function names may be called",
    "().__class__.__bases__": "attribute access is not allowed",
    "t.__class__": "attribute access is not allowed",
    "sin.__globals__": "attribute access is not allowed",
    "crank.__dict__": "attribute access is not allowed",
    "rod.phi": "unknown coordinate 'rod.phi'; use body.x, body.y or body.phi of a body among "
               "crank",
    "__builtins__": "unknown name '__builtins__'",
    "lambda: 1": "lambda is not allowed",
    "(lambda x: x)(1)": "only plain function names may be called",
    "sin(x=1)": "keyword arguments are not allowed in sin()",
    "Max(*[t, a])": "*arguments are not allowed",
    "2**10**10": "is larger than 64",
    "t**65": "exponent 65 is larger than 64",
    "99999**64": "the power would have more than 300 digits",
    "(10**60)**6": "the power would have more than 300 digits",
    "[x for x in (1, 2)]": "comprehensions is not allowed",
    "(x for x in (1, 2))": "comprehensions is not allowed",
    "{x: 1 for x in (1, 2)}": "DictComp is not allowed",
    "'rm -rf'": "the literal 'rm -rf' is not a number",
    "f'{t}'": "strings is not allowed",
    "b'x'": "is not a number",
    "eval('1')": "unknown function 'eval'",
    "exec('1')": "unknown function 'exec'",
    "getattr(t, 'x')": "unknown function 'getattr'",
    "open": "unknown name 'open'",
    "sympify('t')": "unknown function 'sympify'",
    "t[0]": "indexing (a[i]) is not allowed",
    "t if t > 0 else 0": "'if' expressions (use Piecewise) is not allowed",
    "t and 1": "'and'/'or' is not allowed",
    "(x := 1)": "':=' assignments is not allowed",
    "1 ^ 2": "'^' (use ** for powers)",
    "t < 1": "Compare is not allowed",
    "{1: 2}": "Dict is not allowed",
    "[1, 2]": "List is not allowed",
    "1j": "the literal 1j is not a number",
    "True": "the literal True is not a number",
    "...": "the literal Ellipsis is not a number",
    "1e400": "is not a finite number",
    "1/0": "not finite",
    "log(0)": "not finite",
    "sqrt(-1)": "not real",
    "Min(t)": "Min() takes 2 to 8 arguments, got 1",
    "atan2(t)": "atan2() takes 2 arguments, got 1",
    "Piecewise((1, t))": "a Piecewise condition must be one comparison",
    "Piecewise((1, 0 < t < 1))": "a Piecewise condition must be one comparison",
    "Piecewise(1)": "Piecewise takes pairs (value, condition)",
    "Piecewise()": "Piecewise needs at least one",
    "Piecewise((1, 2 < 1))": "no condition of this Piecewise can hold",
    "t +": "this is not a valid expression",
    "import os": "this is not a valid expression",
    "t\x00": "this is not a valid expression",
    "": "the expression is empty",
    "   ": "the expression is empty",
    "x" * 1001: "longer than 1000 characters",
    "-" * 100 + "t": "nested deeper than 60 levels",
    "sin(" * 70 + "t" + ")" * 70: "nested deeper than 60 levels",
    "(" * 300 + "t" + ")" * 300: "",  # the parser's own limit or ours: refused either way
}


@pytest.mark.parametrize("text", list(ATTACKS), ids=lambda s: repr(s[:30]))
def test_attack_is_refused_with_a_clear_error(text: str) -> None:
    with pytest.raises(ExpressionError) as caught:
        parse(text, NAMES, COORDINATES)
    assert ATTACKS[text] in str(caught.value)


def test_python_syntax_warnings_do_not_reach_the_user() -> None:
    """ast.parse warns about '2t' or '1if' on stderr; symkin's own error is enough."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(ExpressionError, match="'if' expressions"):
            parse("1if t < 1 else 0", NAMES)
        with pytest.raises(ExpressionError, match="not a valid expression"):
            parse("2t", NAMES)
    assert not [w for w in caught if issubclass(w.category, SyntaxWarning)]


def test_error_points_at_the_column() -> None:
    with pytest.raises(ExpressionError) as caught:
        parse("sin(t) + foo(t)", NAMES)
    assert caught.value.column == 9
    assert "at column 10" in str(caught.value)


@pytest.mark.parametrize("value", [True, None, [1], {"a": 1}, float("nan"), float("inf")])
def test_non_expression_values_are_refused(value: object) -> None:
    with pytest.raises(ExpressionError):
        parse(value, NAMES)  # type: ignore[arg-type]


def test_time_and_coordinates_are_only_known_where_allowed() -> None:
    with pytest.raises(ExpressionError, match="unknown name 't'"):
        parse("t", {"a": a})
    with pytest.raises(ExpressionError, match="attribute access is not allowed"):
        parse("crank.phi", NAMES)
    assert parse("crank.phi + t", NAMES, COORDINATES) == COORDINATES[("crank", "phi")] + t


def test_the_parser_never_hands_user_text_to_eval_or_sympify() -> None:
    """No call of eval/exec/compile/sympify/parse_expr/S appears in the parser's source."""
    tree = ast.parse(inspect.getsource(expressions))
    forbidden = {"eval", "exec", "compile", "sympify", "parse_expr", "S", "__import__"}
    called = {node.func.attr if isinstance(node.func, ast.Attribute) else
              getattr(node.func, "id", None) for node in ast.walk(tree)
              if isinstance(node, ast.Call)}
    assert not called & forbidden


# ----- correct parsing -------------------------------------------------------------------------

@pytest.mark.parametrize("raw,expected", [
    (0.1, sp.Rational(1, 10)),
    (0.05, sp.Rational(1, 20)),
    ("0.05", sp.Rational(1, 20)),
    (1e-10, sp.Rational(1, 10**10)),
    ("1e-10", sp.Rational(1, 10**10)),
    ("2.5e3", sp.Integer(2500)),
    (3, sp.Integer(3)),
    ("12345678901234567890123", sp.Integer(12345678901234567890123)),
    ("-1.25", sp.Rational(-5, 4)),
    ("+2", sp.Integer(2)),
    ("2*pi/3", 2 * sp.pi / 3),
    ("E**2", sp.E**2),
    ("2**-3", sp.Rational(1, 8)),
    ("Heaviside(0)", sp.Rational(1, 2)),
    ("Min(3, 1, 2)", sp.Integer(1)),
    ("Max(3, 1, 2)", sp.Integer(3)),
    ("Abs(-2.5)", sp.Rational(5, 2)),
])
def test_numbers_are_exact(raw: object, expected: sp.Expr) -> None:
    value = parse(raw, NAMES)  # type: ignore[arg-type]
    assert value == expected
    assert not value.has(sp.Float)


def test_chapter_driver_and_functions() -> None:
    assert parse("t**2 + pi/2", NAMES) == t**2 + sp.pi / 2
    assert parse("atan2(a, t) + asin(t/2) - acos(t/3)", NAMES) == \
        sp.atan2(a, t) + sp.asin(t / 2) - sp.acos(t / 3)
    assert parse("sinh(t)*cosh(t)/tanh(t) + tan(t) + exp(-t) + log(a)", NAMES) == \
        sp.sinh(t) * sp.cosh(t) / sp.tanh(t) + sp.tan(t) + sp.exp(-t) + sp.log(a)


def test_piecewise_motion_law() -> None:
    law = parse("Piecewise((t**2/2, t < 1), (t - 1/2, t <= 2), (3/2, True))", NAMES)
    reference = {0.5: 0.125, 1.5: 1.0, 2.0: 1.5, 3.0: 1.5}
    for time, value in reference.items():
        assert float(law.subs(t, time)) == pytest.approx(value, abs=1e-15)
    with pytest.raises(ExpressionError):
        parse("Piecewise((t, t != 1), (0, True))", NAMES)


def test_polynomial_time_function_of_eq_2_75() -> None:
    poly = parse_time_function({"poly": [1, "a", 0.5, "-pi"]}, {"a": a}, t)
    assert sp.expand(poly - (1 + a * t + t**2 / 2 - sp.pi * t**3)) == 0
    assert parse_time_function("t**2 + pi/2", {}, t) == t**2 + sp.pi / 2


@pytest.mark.parametrize("text,function", [
    ("sin(0.3)", math.sin), ("cos(0.3)", math.cos), ("tan(0.3)", math.tan),
    ("exp(0.3)", math.exp), ("log(0.3)", math.log), ("sqrt(0.3)", math.sqrt),
    ("asin(0.3)", math.asin), ("acos(0.3)", math.acos), ("atan(0.3)", math.atan),
    ("sinh(0.3)", math.sinh), ("cosh(0.3)", math.cosh), ("tanh(0.3)", math.tanh),
])
def test_functions_mean_what_libm_means(text: str, function) -> None:
    assert float(parse(text, NAMES)) == pytest.approx(function(0.3), rel=1e-15)


# ----- a property: random arithmetic parses to the exact value --------------------------------

A_VALUE, T_VALUE = Fraction(3, 7), Fraction(-5, 4)
_DECIMALS = st.decimals(min_value=-100, max_value=100, places=3, allow_nan=False,
                        allow_infinity=False)


@st.composite
def arithmetic(draw, depth: int = 0) -> tuple[str, Fraction]:
    """A random expression text and its exact value (computed with Fraction, not SymPy)."""
    if depth > 4 or draw(st.booleans()):
        kind = draw(st.sampled_from(["int", "decimal", "a", "t"]))
        if kind == "int":
            value = draw(st.integers(-1000, 1000))
            return str(value), Fraction(value)
        if kind == "decimal":
            value = draw(_DECIMALS)
            return str(value), Fraction(value)
        return kind, A_VALUE if kind == "a" else T_VALUE
    operation = draw(st.sampled_from(["+", "-", "*", "/", "**", "neg"]))
    left, left_value = draw(arithmetic(depth + 1))
    if operation == "neg":
        return f"-({left})", -left_value
    if operation == "**":
        exponent = draw(st.integers(-3, 3))
        assume(not (left_value == 0 and exponent < 0))
        return f"({left})**{exponent}", left_value**exponent
    right, right_value = draw(arithmetic(depth + 1))
    if operation == "/":
        assume(right_value != 0)
        return f"({left})/({right})", left_value / right_value
    value = {"+": left_value + right_value, "-": left_value - right_value,
             "*": left_value * right_value}[operation]
    return f"({left}){operation}({right})", value


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(arithmetic())
def test_random_arithmetic_parses_to_its_exact_value(case: tuple[str, Fraction]) -> None:
    text, value = case
    assume(len(text) <= expressions.MAX_LENGTH)
    parsed = parse(text, NAMES).subs({a: sp.Rational(A_VALUE.numerator, A_VALUE.denominator),
                                      t: sp.Rational(T_VALUE.numerator, T_VALUE.denominator)})
    assert parsed == sp.Rational(value.numerator, value.denominator)


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet="0123456789+-*/()., etaisnpxqrcoE_<>=TrueP[]:'\"!@#lambd", max_size=40))
def test_arbitrary_text_either_parses_or_raises_expression_error(text: str) -> None:
    try:
        result = parse(text, NAMES, COORDINATES)
    except ExpressionError:
        return
    assert isinstance(result, sp.Basic)
