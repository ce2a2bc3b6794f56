"""Newton's tolerances and the singularity test, with their defaults per real type. Defined
once: the generated C's ``<prefix>_options`` fields and ``<prefix>_default_options`` are
rendered from :data:`SOLVER_FIELDS` and :data:`DEFAULTS` (codegen.render), its
``<prefix>_check_options`` from :data:`RULES`, which Options keeps too."""

from __future__ import annotations

import math
import numbers
from dataclasses import Field, dataclass, fields
from typing import Any

from symkin.errors import UsageError

RULES = {"tol_phi": "positive finite", "tol_dq": "positive", "max_iterations": "count",
         "min_pivot_ratio": "ratio", "max_cond": "positive", "tighten_cond": "non-negative",
         "target_q": "positive", "target_dq": "positive", "target_ddq": "positive",
         "unit": "positive finite"}  # LENGTH_UNIT
"""What each field of the C options struct may hold, checked by Options when it is made and by
the generated ``<prefix>_check_options`` (rendered from this table) at every solve: a
tolerance, limit or target > 0 (inf: no such limit), tol_phi and the unit also finite, the
iteration cap a whole number >= 0, the pivot ratio from 0 to 1, tighten_cond >= 0 (0: every
point tightened, a condition is at least 1). NaN passes none."""

RULE_WORDS = {"positive finite": "positive and finite", "positive": "positive (inf for no limit)",
              "non-negative": "0 or more (inf for no limit)", "count": "a whole number >= 0",
              "ratio": "from 0 to 1"}


def allowed(rule: str, value: float) -> bool:
    """Whether ``value`` keeps ``rule`` (of :data:`RULES`)."""
    if rule == "positive finite":
        return 0 < value < math.inf
    if rule == "positive":
        return value > 0
    if rule == "non-negative":
        return value >= 0
    if rule == "count":
        return value >= 0 and math.isfinite(value) and float(value).is_integer()
    return 0 <= value <= 1


@dataclass(frozen=True)
class Options:
    """Newton tolerances and the singularity test.

    Args:
        tol_phi: converged when max |Phi| of the current iterate is at most this...
        tol_dq: ...and the last Newton step max |dq| is at most this.
        max_iterations: Newton iterations allowed per time point.
        min_pivot_ratio: Phi_q counts as singular when min |u_kk| / max |u_kk| of its LU
            factors falls below this (a cheap estimate of the reciprocal condition number).
        max_cond: ...or when the estimated 1-norm condition number of Phi_q at the converged
            point exceeds this: the point is then handed to the singular-point treatment.
        tighten_cond: at a point the error model would flag as Newton left it, Newton solves
            for its correction and judges the point by it; where the point would still be
            flagged it goes on until it would not. Above this condition estimate it goes on
            until its step stalls near machine precision, whatever the model says (the
            default, max_cond, keeps that for points that count as singular: below it the
            model's test alone gave the same accuracy on the test mechanisms for less work).
            ``inf``: no extra iterations at all (the same work at every step).
        target_q, target_dq, target_ddq: a point is flagged when the estimated error of q, dq
            or ddq exceeds this times max(1, max |x|) (runtime.solving.accuracy).
        stop_at_singular: stop at the first singular point (the behaviour before singular
            points were passed through); also no bisection of limit positions.
    """

    tol_phi: float = 1e-10
    tol_dq: float = 1e-9
    max_iterations: int = 25
    min_pivot_ratio: float = 1e-10
    max_cond: float = 1e7
    tighten_cond: float = 1e7
    target_q: float = 1e-8
    target_dq: float = 1e-7
    target_ddq: float = 1e-6
    stop_at_singular: bool = False

    def __post_init__(self) -> None:
        # Checked here, where they are made: a bad value would otherwise surface far away as a
        # failure that blames the mechanism (tol_phi < 0: "cannot be assembled") or as a
        # ZeroDivisionError (max_cond = 0).
        problems = [problem for problem in map(self._problem, fields(self)) if problem]
        if problems:
            raise UsageError("Options: " + "; ".join(problems))

    def _problem(self, field: Field[Any]) -> str | None:
        value = getattr(self, field.name)
        if field.name == "stop_at_singular":
            return None if isinstance(value, bool) else "stop_at_singular must be True or False"
        rule = RULES[field.name]
        wanted = numbers.Integral if rule == "count" else numbers.Real  # NumPy's too
        if isinstance(value, bool) or not isinstance(value, wanted):
            return f"{field.name} must be {'a whole number' if rule == 'count' else 'a number'}" \
                f", got {value!r}"
        return None if allowed(rule, float(value)) else \
            f"{field.name} must be {RULE_WORDS[rule]}, got {value!r}"


# The defaults per real type, defined once: the generated C's <prefix>_default_options is
# rendered from this table (codegen.render), so Python and C can never disagree.
DEFAULTS = {
    "double": Options(),
    "float": Options(tol_phi=1e-5, tol_dq=1e-4, min_pivot_ratio=1e-6, max_cond=1e3,
                     tighten_cond=1e3, target_q=1e-3, target_dq=1e-2, target_ddq=1e-1),
}


def defaults(real: str) -> Options:
    """The Newton options for a kernel computing in ``real`` ("double" or "float")."""
    return DEFAULTS[real]


SOLVER_FIELDS = tuple(f.name for f in fields(Options) if f.name != "stop_at_singular")
"""The options the generated C solver reads too, in the order of its ``<prefix>_options``
struct; ``stop_at_singular`` is the Python driver's alone (it decides what happens after the C
grid loop stops)."""

LENGTH_UNIT = "unit"
"""The C solver's option beyond :data:`SOLVER_FIELDS`: the length unit its decisions are made
in (runtime.solving.units chooses it from the mechanism's length scale; 1, the default, is the
mechanism's own unit). The Python loop applies the same unit by solving a scaled view of the
kernel (runtime.solving.units.ScaledKernel), so it is no field of :class:`Options`."""

C_FIELDS = (*SOLVER_FIELDS, LENGTH_UNIT)
"""The fields of the generated ``<prefix>_options`` struct, in order."""


def c_defaults(real: str) -> dict[str, float]:
    """``<prefix>_default_options`` for a real type: the Options defaults and unit 1."""
    chosen = defaults(real)
    return {**{name: getattr(chosen, name) for name in SOLVER_FIELDS}, LENGTH_UNIT: 1.0}
