"""Options are checked where they are made: a tolerance, limit or target that cannot work is a
UsageError naming the field, not a failure that blames the mechanism far away (tol_phi < 0
said "cannot be assembled"; max_cond = 0 raised ZeroDivisionError). Limits of inf ("no such
limit") and a pivot ratio of 0 stay allowed, and a solve with them runs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.contract.options import DEFAULTS, Options
from symkin.errors import UsageError

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("field", "value"), [
    ("tol_phi", -1.0), ("tol_phi", 0.0), ("tol_phi", math.nan), ("tol_phi", math.inf),
    ("tol_dq", -1e-9), ("tol_dq", math.nan), ("max_iterations", -1), ("max_iterations", 2.5),
    ("max_iterations", True), ("min_pivot_ratio", -1e-10), ("min_pivot_ratio", 2.0),
    ("max_cond", 0.0), ("max_cond", math.nan), ("tighten_cond", -1.0), ("target_q", -1.0),
    ("target_dq", 0.0), ("target_ddq", math.nan), ("tol_phi", "1e-10"),
    ("stop_at_singular", "yes"),
])
def test_a_value_that_cannot_work_is_refused_by_name(field: str, value: object) -> None:
    with pytest.raises(UsageError, match=f"^Options: {field} must be"):
        Options(**{field: value})  # type: ignore[arg-type]


def test_every_problem_is_named_at_once() -> None:
    with pytest.raises(UsageError) as caught:
        Options(tol_phi=-1, max_cond=0)
    assert "tol_phi" in str(caught.value) and "max_cond" in str(caught.value)


def test_the_defaults_and_the_limits_of_what_is_allowed_are_accepted() -> None:
    for options in DEFAULTS.values():
        Options(**{f: getattr(options, f) for f in vars(options)})
    Options(tighten_cond=0.0)  # every point tightened
    Options(tol_dq=math.inf, max_iterations=np.int64(0), min_pivot_ratio=0.0,
            max_cond=math.inf, tighten_cond=math.inf, target_q=math.inf, target_dq=math.inf,
            target_ddq=math.inf)


def test_a_solve_with_no_limits_and_no_targets_runs_and_flags_nothing() -> None:
    """Targets of inf: nothing can miss them; the positions are still Newton's, to tol_phi:
    the crank's tip on its circle of radius a (examples/crank_slider.yaml)."""
    kernel = compiled(ROOT / "examples" / "crank_slider.yaml", "numpy")  # from its goldens
    options = Options(max_cond=math.inf, tighten_cond=math.inf, target_q=math.inf,
                      target_dq=math.inf, target_ddq=math.inf)
    run = symkin.solve(kernel, t=np.linspace(0.0, 0.5, 6), options=options)
    assert not run.flagged.any()
    tip = run.point("crank", "tip")[0]
    assert np.abs(np.hypot(tip[:, 0], tip[:, 1]) - 1.0).max() <= 1e-10
