"""The sparse LU's pivot order is chosen to hold over the motion (codegen.sample samples the
file's grid, lu_plan.analyse_over keeps an order every sample passes), so the examples and the
test mechanisms never fall back to the dense LU along their motion: a step's cost is the
straight-line code's, every time.

Measured before this choice (order checked at t0 alone): all_drivers 36 of 101 points fell
back, offset_crank_slider 9 of 101, slide_driven 6 of 101. Where no fixed order holds (a body
turning a full turn in Euler parameters), rows of one pattern trade places at run time
(codegen.lu_interchange): cardan, rssr and spatial_slider_crank fell back 3 times each before.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import yaml
from codegen_support import HEAVY, compiled, derived

import symkin
from symkin.codegen import lu_interchange, lu_plan
from symkin.codegen import sample as codegen_sample

ROOT = Path(__file__).resolve().parents[2]
# Where a fall-back cannot be avoided, and why: the parallelograms pass through a singular
# configuration (no pivot order survives it); crank_slider_general's numerically zero
# parameters make Phi_q at the file's q0 (the first Newton iterate, before assembly) fail
# the pivot test once.
EXPECTED = {"parallelogram": 1, "parallelogram_chain": 1, "crank_slider_general": 1}
# Motions that end at a limit position (half_circle_end: the end of its curve, where the
# edge treatment's bisection factors Phi_q as it turns singular).
LIMITED = {"dead_centre", "non_grashof", "half_circle_end"}
# No motion in t: the caller gives the legs (arm angles); their fall-backs are checked along
# prescribed paths in tests/inputs/test_parallel_fk_examples.py (delta_fk, three_rrr_fk).
INPUT_DRIVEN = {"stewart_fk", "stewart_legs_fk", "delta_fk", "three_rrr_fk"}
# A body that turns half a turn or more in Euler parameters (cardan, rssr,
# spatial_slider_crank): its driver and normalisation rows meet its columns e0, e3 in the block
# 2 [[s, -c], [c, s]] (c, s the cosine and sine of half its angle), and its two axis rows meet
# e1, e2 in another rotation: every entry of such a block is zero somewhere on the turn, so no
# fixed pivot order holds over it (test_a_rotation_block_has_no_fixed_order below). The plan
# interchanges those rows at run time instead (test_interchanges_hold_over_the_turn).
FILES = sorted(p for p in [*ROOT.glob("examples/*.yaml"), *ROOT.glob("tests/mechanisms/*.yaml")]
               if p.stem not in LIMITED | INPUT_DRIVEN and "input" not in p.stem
               and (p.stem not in HEAVY or os.environ.get("SYMKIN_SLOW") == "1"))


@pytest.mark.parametrize("path", [pytest.param(p, id=p.stem) for p in FILES])
def test_no_dense_fallback_along_the_motion(path: Path) -> None:
    kernel = compiled(path, "c")  # the examples from their goldens, the rest shared
    trajectory = symkin.solve(kernel)
    assert trajectory.lu_fallbacks == EXPECTED.get(path.stem, 0)


def _plan_for(rows, cols, samples):
    return lu_plan.analyse_over(2, rows, cols, samples)


def test_an_order_failing_later_is_replaced_by_one_that_holds() -> None:
    """[[2, 1], [1, -1]] at the start; later the entry the start's order pivots on first
    shrinks to 1e-3 of its column, failing the run-time test (ratio < 0.01): the order kept
    must pass on both, and its factors must solve both systems."""
    rows, cols = [0, 0, 1, 1], [0, 1, 0, 1]
    early = [2.0, 1.0, 1.0, -1.0]
    alone = lu_plan.analyse(2, rows, cols, early)
    first = list(zip(rows, cols)).index((alone.row_perm[0], alone.col_perm[0]))
    late = list(early)
    late[first] = 1e-3
    assert lu_plan.pivot_ratio(alone, rows, cols, late) < alone.tau
    plan = _plan_for(rows, cols, [early, late])
    for sample in (early, late):
        assert lu_plan.pivot_ratio(plan, rows, cols, sample) >= plan.tau
        a = np.zeros((2, 2))
        a[rows, cols] = sample
        b = np.array([1.0, 2.0])
        assert np.allclose(lu_interchange.solve_with_plan(plan, sample, b), np.linalg.solve(a, b),
                           rtol=1e-12, atol=0)


def test_one_sample_gives_the_order_of_old() -> None:
    rows, cols = [0, 0, 1, 1], [0, 1, 0, 1]
    sample = [1.0, 1.0, 1.0, 1.0]
    assert _plan_for(rows, cols, [sample]) == lu_plan.analyse(2, rows, cols, sample)


def _solves(plan, rows, cols, sample) -> bool:
    a = np.zeros((plan.n, plan.n))
    a[rows, cols] = sample
    b = np.arange(1.0, plan.n + 1)
    return bool(np.allclose(lu_interchange.solve_with_plan(plan, sample, b), np.linalg.solve(a, b),
                            rtol=1e-12, atol=0))


def test_the_order_is_chosen_over_all_samples_at_once() -> None:
    """[[a, b], [c, d]]: at the first sample [[1e-3, -1e-3], [1, 1]] its own order pivots on
    c (a and b fail the threshold test in their columns), at the second [[1, 1], [1e-3, 1]]
    on a; each of those orders fails the run-time test at the other sample. Only d passes
    at both: pivot d, then a - b c / d (2e-3 and 1 - 1e-3, alone in its column: ratio 1)."""
    rows, cols = [0, 0, 1, 1], [0, 1, 0, 1]
    first, second = [1e-3, -1e-3, 1.0, 1.0], [1.0, 1.0, 1e-3, 1.0]
    for own, other in ((first, second), (second, first)):
        alone = lu_plan.analyse(2, rows, cols, own)
        assert lu_plan.pivot_ratio(alone, rows, cols, other) < alone.tau
    plan = _plan_for(rows, cols, [first, second])
    assert (plan.row_perm, plan.col_perm) == ((1, 0), (1, 0))
    for sample in (first, second):
        assert lu_plan.pivot_ratio(plan, rows, cols, sample) == 1.0
        assert _solves(plan, rows, cols, sample)


ROTATION = ([0, 0, 1, 1], [0, 1, 0, 1],
            [[2 * np.sin(a), -2 * np.cos(a), 2 * np.cos(a), 2 * np.sin(a)]
             for a in np.linspace(0.0, np.pi / 2, 9)])


def test_a_rotation_block_has_no_fixed_order() -> None:
    """2 [[s, -c], [c, s]] over half a turn (c, s from 1, 0 to 0, 1) vanishes in every entry
    somewhere, so every one of the four first pivots fails the run-time test at one end,
    whatever fixed order is chosen."""
    rows, cols, samples = ROTATION
    plan = _plan_for(rows, cols, samples)
    assert not plan.swaps
    assert min(lu_plan.pivot_ratio(plan, rows, cols, s) for s in samples) < plan.tau


def test_interchanges_hold_over_the_turn() -> None:
    """The same block with its two rows (one pattern) interchanged at run time: every sample
    passes every pivot test, and the solutions are numpy's."""
    rows, cols, samples = ROTATION
    plan = lu_interchange.analyse_over(2, rows, cols, samples)
    assert [(s.k, s.p) for s in plan.swaps] == [(0, 1)]
    for sample in samples:
        assert lu_interchange.factor(plan, sample).failed is None
        assert _solves(plan, rows, cols, sample)


def test_the_input_walk_starts_at_the_drawing_s_leg_lengths() -> None:
    """stewart_fk's leg rows, |B - P|^2 - u^2, are flat in u at the nominal u = 0, yet the walk
    of its inputs starts at the drawn legs' lengths |P_i - B_i|, read here from the file."""
    system = derived(ROOT / "examples" / "stewart_fk.yaml")
    kernel = codegen_sample._SampleKernel(system, system.pattern())
    p = codegen_sample.start_inputs(system, kernel, np.array(system.q0, dtype=float))
    bodies = yaml.safe_load((ROOT / "examples" / "stewart_fk.yaml").read_text())["bodies"]
    drawn = [np.linalg.norm(np.subtract(bodies["platform"]["points"][f"P{i}"],
                                        bodies["ground"]["points"][f"B{i}"])) for i in range(1, 7)]
    assert np.max(np.abs(p[len(system.p):len(system.p) + 6] - drawn)) < 1e-9
