"""The start's clearance as symkin.solve asks it on every call (start.clears, the threshold
kept in the call plan) gives the verdict of its definition, from_raw then clearly_regular
under start_threshold, on every kind of estimate and lever arm a solver can report."""

from __future__ import annotations

import itertools
import math

from symkin.contract.options import Options
from symkin.runtime.solving import call_plan
from symkin.runtime.solving.start import clearly_regular, clears, from_raw, start_threshold

ESTIMATES = (0.0, 1.0, 3.7, 9.99e3, 1e4, 1.0000001e4, 2e5, 1e300, -5.0, math.inf, -math.inf,
             math.nan)
SCALES = (None, 0.0, -1.0, 1e-320, 1e-3, 0.5, 1.0, 1.0 + 2**-52, 3.0, 1e150, math.inf,
          -math.inf, math.nan)


def _definition(estimate: float, scale: float | None, threshold: float) -> bool:
    """cleared as start.py defines it: no verdict without a scale or a finite estimate."""
    if scale is None or not math.isfinite(estimate):
        return False
    arm = from_raw(scale)
    return math.isfinite(arm) and clearly_regular(estimate, arm, threshold)


def test_clears_is_its_definition_on_every_kind_of_value() -> None:
    cases = 0
    for size in (9, 3000):
        threshold = start_threshold(Options(), size)
        for estimate, scale in itertools.product(ESTIMATES, SCALES):
            assert clears(estimate, scale, threshold) is _definition(estimate, scale,
                                                                     threshold), (
                estimate, scale, size)
            cases += 1
    # both verdicts occur: the table is not all one answer
    assert {clears(1.0, 1.0, 1e5), clears(1e5, 1.0, 1e5)} == {True, False} and cases == 312


def test_the_plan_keeps_the_threshold_of_its_kernel_size() -> None:
    class Stand:  # a kernel as the plan reads it: only the attributes it asks for
        coordinates = tuple(f"b{k}.x" for k in range(450))

    plan = call_plan.of(Stand())
    assert plan.start_threshold == start_threshold(plan.options, 450)
    assert plan.start_threshold == 1e5 * (450 / 100) ** 2  # min(LIMIT_COND, 1e7 / 10) x 4.5^2
