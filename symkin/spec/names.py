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

# Every name <math.h> may declare besides LIBM_NAMES (the double functions the generated code
# calls): their float (f) and long double (l) variants, the GNU and X/Open extras a compiler
# declares without -std=c99 (an embedded folder is built with the user's flags), and the C99
# classification macros. A mechanism with one of these names would define its own symbol of
# the library's name. tests/trust checks the table against the compiler's own math.h.
_LIBM_LEGACY = ("drem", "finite", "gamma", "isinf", "isnan", "j0", "j1", "jn", "lgamma_r",
                "scalb", "significand", "y0", "y1", "yn")
_LIBM_MACROS = ("fpclassify", "isfinite", "isnormal", "signbit", "isgreater", "isgreaterequal",
                "isless", "islessequal", "islessgreater", "isunordered", "math_errhandling")
LIBM_RESERVED = frozenset(
    {stem + suffix for stem in (LIBM_NAMES - {"abs"}) | set(_LIBM_LEGACY)
     for suffix in ("", "f", "l")}
    | {"lgammaf_r", "lgammal_r", "abs"} | set(_LIBM_MACROS))

# What an expression could mean instead of a parameter or a body: the time, the constants, the
# functions of the expression language and the literals Python's parser treats specially.
EXPRESSION_NAMES = frozenset({"t", "pi", "E", "Piecewise", "True", "False", "None", "input"}
                             | set(FUNCTIONS))

# Standard C and POSIX header names: a mechanism named "string" would generate string.h,
# found by #include <string.h> before the system's own in some include orders.
SYSTEM_HEADERS = frozenset(["assert", "complex", "ctype", "errno", "fenv", "float", "inttypes", "iso646", "limits", "locale", "math", "setjmp", "signal", "stdalign", "stdarg", "stdatomic", "stdbool", "stddef", "stdint", "stdio", "stdlib", "stdnoreturn", "string", "tgmath", "threads", "time", "uchar", "wchar", "wctype", "unistd", "fcntl", "pthread", "dirent", "sched", "strings", "syslog", "termios", "Python"])

# The generated NumPy kernel is a Python module named after the mechanism: it must not shadow a
# module the kernel or symkin imports.
PYTHON_MODULES = frozenset(["numpy", "scipy", "cffi", "symkin", "math", "sys", "os"])

# Each kind of name has its own namespace (README, "Names"):
#   mechanism   -> the C prefix, file names and a Python module: identifiers of both languages,
#                  no libm function, no system header;
#   parameter, body -> names in expressions: anything but what an expression means otherwise;
#   point, joint, driver -> labels only (rows, columns, comments): any identifier, E and p too.
SLOT_SUFFIX = "@slot"
KINDS = ("mechanism", "parameter", "body", "point", "joint", "driver")


def name_problem(name: object, kind: str = "mechanism") -> str | None:
    """Say what is wrong with ``name`` as a name of ``kind`` (one of :data:`KINDS`), or None."""
    if not isinstance(name, str):
        return f"{name!r} is not a name"
    if kind == "point" and name.endswith(SLOT_SUFFIX):
        # the drawn layout's name for a slotted body's copy of a shared point (drawn_slots)
        name = name[: -len(SLOT_SUFFIX)]
    if not _IDENTIFIER.match(name):
        return (f"{name!r} is not a plain ASCII identifier (a letter, then letters, digits "
                f"or '_')")
    if len(name) > MAX_NAME_LENGTH:
        return f"{name!r} is longer than {MAX_NAME_LENGTH} characters"
    if "__" in name:
        return f"{name!r} contains a double underscore"
    if kind in ("parameter", "body"):
        return _expression_clash(name, kind)
    if kind == "mechanism":
        return _identifier_clash(name)
    return None


# A body's name stands in expressions only before a dot (crank.phi), where it cannot be the
# driver keyword, which is a whole value: `input` is a natural name for a link.
_BODY_NAMES_ALLOWED = frozenset({"input"})


def _expression_clash(name: str, kind: str) -> str | None:
    if name in EXPRESSION_NAMES and not (kind == "body" and name in _BODY_NAMES_ALLOWED):
        meaning = ("the time" if name == "t" else "a constant" if name in ("pi", "E") else
                   "the word of a driver whose values the caller gives" if name == "input" else
                   "a function" if name in FUNCTIONS or
                   name == "Piecewise" else "a Python literal")
        return f"{name!r} is {meaning} in expressions"
    if keyword.iskeyword(name):
        return f"{name!r} is a Python keyword, which no expression can use as a name"
    if kind == "body" and name == "ground":
        return "'ground' is the fixed frame, present in every mechanism"
    return None


def _identifier_clash(name: str) -> str | None:
    if name in C_KEYWORDS or keyword.iskeyword(name) or keyword.issoftkeyword(name):
        return f"{name!r} is a C or Python keyword"
    if name in LIBM_RESERVED:
        return f"{name!r} is the name of a C math library function or macro"
    if name in SYSTEM_HEADERS:
        return f"{name!r} would generate {name}.h, the name of a system header"
    if name in PYTHON_MODULES:
        return f"{name!r} would generate {name}.py, shadowing the Python module {name}"
    return None
