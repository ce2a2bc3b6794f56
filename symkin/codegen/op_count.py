"""Floating-point operation counts of generated code, by kind, from the printed statements.

The budget of a generated solver step (``backends.c.op_budget``) adds up what each routine
executes. A routine's operations are read from the C text the templates render (its CSE'd
temporaries and outputs, the sparse LU's straight-line statements), so whatever a printer or
an emitter writes is counted, a new kind of statement included: every ``+ - * /`` (also in
``+= -= *= /=``), every negation, comparison, ``fabs``, ``sqrt`` and other math call
(comments and braces, as around the sparse LU's run-time row interchanges, count nothing). An
operation between two number literals (``1.0/2.0``, a rational coefficient) is folded by the
compiler and not counted; nor is the sign of a literal (``-1``). Index arithmetic never
appears in these texts (indices are literal integers inside brackets, which are skipped).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields

KINDS = ("add", "mul", "div", "sqrt", "call", "abs", "cmp")
"""add: additions, subtractions and negations; call: sin, cos, atan2, pow, ... (one each);
abs: fabs; cmp: comparisons (a ternary select or a branch is counted by its comparison)."""


@dataclass(frozen=True)
class Flops:
    """Operation counts by kind; ``total`` is their sum (every kind costs about one
    instruction but the calls, which are library functions of tens of instructions)."""

    add: int = 0
    mul: int = 0
    div: int = 0
    sqrt: int = 0
    call: int = 0
    abs: int = 0
    cmp: int = 0

    def __add__(self, other: Flops) -> Flops:
        return Flops(**{k: getattr(self, k) + getattr(other, k) for k in KINDS})

    def __mul__(self, times: int) -> Flops:
        return Flops(**{k: getattr(self, k) * times for k in KINDS})

    __rmul__ = __mul__

    @property
    def total(self) -> int:
        return sum(getattr(self, k) for k in KINDS)

    @property
    def arithmetic(self) -> int:
        """The operations on values (add, mul, div, sqrt, calls): the flops proper."""
        return self.add + self.mul + self.div + self.sqrt + self.call

    def as_dict(self) -> dict[str, int]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


ZERO = Flops()

_TOKEN = re.compile(r"""
    (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?[fF]?)
  | (?P<name>[A-Za-z_]\w*)
  | (?P<index>\[[^\[\]]*\])
  | (?P<op><<=|>>=|\+=|-=|\*=|/=|<=|>=|==|!=|&&|\|\||[-+*/<>!?:=(),;&|~%^{}])
  | (?P<space>\s+)
""", re.VERBOSE)

_COMMENT = re.compile(r"/\*.*?\*/", re.DOTALL)

_BINARY = {"+": "add", "-": "add", "*": "mul", "/": "div", "+=": "add", "-=": "add",
           "*=": "mul", "/=": "div", "<": "cmp", ">": "cmp", "<=": "cmp", ">=": "cmp",
           "==": "cmp", "!=": "cmp"}
# after one of these a '-' or '+' is a sign, not a subtraction
_OPERAND_ENDS = {"number", "name", "index", ")"}
_CALLS = {"sqrt": "sqrt", "sqrtf": "sqrt", "fabs": "abs", "fabsf": "abs"}
_NOT_CALLS = {"if", "return", "while", "for", "sizeof"}


def _tokens(text: str) -> list[tuple[str, str]]:
    """(kind, text) of each token; kind is the group name, or the operator itself."""
    out: list[tuple[str, str]] = []
    text = _COMMENT.sub(" ", text)  # a comment's '/' and '*' are no operations
    position = 0
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None:
            raise ValueError(f"cannot count the operations of {text!r} at {position}")
        position = match.end()
        kind = match.lastgroup or ""
        if kind != "space":
            out.append((match.group() if kind == "op" else kind, match.group()))
    return out


def count(text: str, helpers: Mapping[str, Flops] | None = None) -> Flops:
    """The operations one execution of the C statements or expression ``text`` performs.

    Args:
        text: C statements or an expression (no loops: each operation runs once).
        helpers: the cost of one call of a function of the generated code (by name); any
            other call is one ``call`` (a math function), ``sqrt`` and ``fabs`` their kinds.
    """
    counts = dict.fromkeys(KINDS, 0)
    extra = ZERO
    tokens = _tokens(text)
    for k, (kind, word) in enumerate(tokens):
        before = tokens[k - 1][0] if k else None
        after = tokens[k + 1][0] if k + 1 < len(tokens) else None
        if kind == "name" and after == "(" and word not in _NOT_CALLS:
            if helpers and word in helpers:
                extra = extra + helpers[word]
            else:
                counts[_CALLS.get(word, "call")] += 1
        elif kind == "-" and before not in _OPERAND_ENDS:
            counts["add"] += after != "number"  # the sign of a literal is part of it
        elif kind in _BINARY and not (before == "number" and after == "number"):
            counts[_BINARY[kind]] += before in _OPERAND_ENDS or kind.endswith("=")
    return Flops(**counts) + extra


def count_all(texts: Iterable[str], helpers: Mapping[str, Flops] | None = None) -> Flops:
    """The sum of :func:`count` over several statements."""
    total = ZERO
    for text in texts:
        total = total + count(text, helpers)
    return total
