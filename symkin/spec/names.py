"""Which names a mechanism file may use for itself, its bodies, points and parameters.

Names from a file end up as Python identifiers in expressions and in comments of generated code,
so they must be plain ASCII identifiers that cannot be mistaken for anything else.
"""

from __future__ import annotations

import keyword
import re

from symkin.spec.expressions import FUNCTIONS

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
MAX_NAME_LENGTH = 48

C_KEYWORDS = frozenset(["auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register", "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch", "typedef", "union", "unsigned", "void", "volatile", "while", "_Alignas", "_Alignof", "_Atomic", "_Bool", "_Complex", "_Generic", "_Imaginary", "_Noreturn", "_Static_assert", "_Thread_local", "bool", "true", "false", "NULL", "main"])

LIBM_NAMES = frozenset(["acos", "acosh", "asin", "asinh", "atan", "atan2", "atanh", "cbrt", "ceil", "copysign", "cos", "cosh", "erf", "erfc", "exp", "exp2", "expm1", "fabs", "fdim", "floor", "fma", "fmax", "fmin", "fmod", "frexp", "hypot", "ilogb", "ldexp", "lgamma", "llrint", "llround", "log", "log10", "log1p", "log2", "logb", "lrint", "lround", "modf", "nan", "nearbyint", "nextafter", "nexttoward", "pow", "remainder", "remquo", "rint", "round", "scalbln", "scalbn", "sin", "sinh", "sqrt", "tan", "tanh", "tgamma", "trunc", "abs"])

# Names the generated code and the expression language use for themselves.
SYMKIN_NAMES = frozenset(
    {"t", "pi", "E", "ground", "q", "dq", "ddq", "p", "x", "y", "phi", "Piecewise", "True",
     "False", "None", "np", "numpy", "math"} | set(FUNCTIONS)
)


def name_problem(name: object) -> str | None:
    """Say what is wrong with ``name`` as a mechanism, body, point or parameter name, or None."""
    if not isinstance(name, str):
        return f"{name!r} is not a name"
    if not _IDENTIFIER.match(name):
        return (f"{name!r} is not a plain ASCII identifier (a letter, then letters, digits "
                f"or '_')")
    if len(name) > MAX_NAME_LENGTH:
        return f"{name!r} is longer than {MAX_NAME_LENGTH} characters"
    if name in SYMKIN_NAMES:
        return f"{name!r} is reserved by symkin"
    if name in C_KEYWORDS or keyword.iskeyword(name) or keyword.issoftkeyword(name):
        return f"{name!r} is a C or Python keyword"
    if name in LIBM_NAMES:
        return f"{name!r} is the name of a C math library function"
    if name.startswith("_") or "__" in name:
        return f"{name!r} contains a double underscore"
    return None
