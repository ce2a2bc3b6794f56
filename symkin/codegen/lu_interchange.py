"""Run-time row interchanges where no fixed pivot order holds, and a plan executed in Python.

A body that turns a full turn in Euler parameters meets its driver and normalisation rows in
the block 2 [[s, -c], [c, s]] of its half angle: every entry of it is zero somewhere on the
turn, so every fixed pivot order fails the run-time test somewhere and the factorization falls
back to dense there. Two rows with the same pattern after fill (as in a dense trailing block)
can trade places without changing a slot or an operation of the plan: this is partial
pivoting restricted to rows of one pattern, decided at run time by one comparison of
magnitudes and paid for by exchanging the rows' few values.

``analyse_over`` keeps lu_plan's order and adds interchanges (``LUPlan.swaps``) only where the
samples of the motion ask for them. First where a pivot fails: at the first step whose pivot
still fails on some sample, the rows below of its pattern are compared with it (a tournament:
the larger entry of the pivot column takes the pivot row), then the samples are replayed;
where no row below shares the pattern, the pivot row and a row with an entry in its column are
padded with zeros to one (``lu_plan.padded``: more fill-in, the same order). Then, without
padding, where a pivot passes by less than MARGIN (``with_margin``). A plan that needs none
keeps its bytes. ``factor`` and ``solve_with_plan`` execute a plan, interchanges included, in
the order the generated C does: the reference both are tested against.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from symkin.codegen import lu_plan
from symkin.codegen.lu_plan import LUPlan, Swap
from symkin.errors import SolveError

MARGIN = lu_plan.GENERATION_THRESHOLD
"""A pivot whose ratio on some sample is below this (while above the run-time test's tau)
is close enough to failing between samples that an interchange is worth its compare."""


@dataclass
class Factors:
    """The plan's factorization of one Phi_q: its slots, the pivots' reciprocals, which
    interchanges were made, and the first step whose pivot failed the run-time test."""

    v: np.ndarray
    inv: np.ndarray
    swapped: list[bool]
    failed: int | None = None  # the step k, or None when every pivot passed
    ratios: list[float] = dataclasses.field(default_factory=list)  # |pivot| / max |column|


def analyse_over(n: int, rows: Sequence[int], cols: Sequence[int],
                 samples: Sequence[Sequence[float]]) -> LUPlan:
    """lu_plan.analyse_over's order, with the interchanges the samples need (none when the
    order holds on every sample, or when none helps)."""
    plan = lu_plan.analyse_over(n, rows, cols, samples)
    values = [_slots(plan, sample) for sample in samples]
    return with_margin(with_interchanges(plan, rows, cols, values), values)


@dataclass(frozen=True)
class _Trial:
    """A plan with interchanges: the padding that makes rows share a pattern, the (k, p)
    interchanges, and the samples on which a pivot still fails (index -> step)."""

    plan: LUPlan
    padding: tuple[tuple[int, int], ...]
    pairs: tuple[tuple[int, int], ...]
    failing: dict[int, int]


def with_interchanges(plan: LUPlan, rows: Sequence[int], cols: Sequence[int],
                      samples: Sequence[np.ndarray]) -> LUPlan:
    """Add interchanges at the first failing step while that gets every sample past it.

    ``plan``'s order stays; ``samples`` hold Phi_q's non-zeros in pattern order. At a failing
    step k, the rows below of k's pattern take part; when there are none, k's row and a row
    with an entry in column k are padded with zeros to one pattern (the least fill-in of
    those that work). The result is kept only when fewer samples fail than with ``plan``.
    """
    trial = _Trial(plan, (), (), _failing(plan, samples))
    while trial.failing:
        better = _past_step(plan, rows, cols, samples, trial, min(trial.failing.values()))
        if better is None:
            break
        trial = better
    return trial.plan if len(trial.failing) < len(_failing(plan, samples)) else plan


def with_margin(plan: LUPlan, samples: Sequence[np.ndarray]) -> LUPlan:
    """Interchanges where a pivot passes the run-time test on every sample but by less than
    MARGIN on some: the samples are a few points of the motion, and a pivot that comes that
    close to the limit at one of them may cross it between them. Taken, step by step, where
    rows below share the pivot row's pattern, when they raise the step's smallest ratio over
    the samples and make no sample fail."""
    groups = same_pattern_rows(plan)
    runs = [factor(plan, sample) for sample in samples]
    for k in range(plan.n):
        later = [q for q in groups.get(k, ()) if q > k]
        if not later or any(s.k == k for s in plan.swaps) or _weakest(runs, k) >= MARGIN:
            continue
        pairs = sorted([(s.k, s.p) for s in plan.swaps] + [(k, q) for q in later],
                       key=lambda pair: pair[0])
        trial = _with_swaps(plan, pairs)
        trial_runs = [factor(trial, sample) for sample in samples]
        if (_fails(trial_runs) <= _fails(runs)
                and _weakest(trial_runs, k) > _weakest(runs, k)):
            plan, runs = trial, trial_runs
    return plan


def _weakest(runs: Sequence[Factors], k: int) -> float:
    """The smallest ratio of step k over the runs that reached it."""
    return min((run.ratios[k] for run in runs if len(run.ratios) > k), default=np.inf)


def _fails(runs: Sequence[Factors]) -> int:
    return sum(run.failed is not None for run in runs)


def _past_step(base: LUPlan, rows: Sequence[int], cols: Sequence[int],
               samples: Sequence[np.ndarray], trial: _Trial, k: int) -> _Trial | None:
    """The trial that gets every sample past step k with interchanges there, or None."""
    current = _padded(base, rows, cols, trial.padding)
    partners: list[int | None] = [None, *(p for p, _ in current.steps[k].lower)]
    found: list[_Trial] = []
    for p in partners:
        padding = trial.padding if p is None else _shared(base, rows, cols, trial.padding, k, p)
        plan = _padded(base, rows, cols, padding)
        later = tuple(q for q in same_pattern_rows(plan).get(k, ()) if q > k)
        if not later:
            continue
        pairs = trial.pairs + tuple((k, q) for q in later)
        swapped = _with_swaps(plan, pairs)
        failing = _failing(swapped, samples)
        if not failing or min(failing.values()) > k:
            found.append(_Trial(swapped, padding, pairs, failing))
    return min(found, key=lambda t: t.plan.n_lu, default=None)


def _shared(base: LUPlan, rows: Sequence[int], cols: Sequence[int],
            padding: tuple[tuple[int, int], ...], k: int, p: int
            ) -> tuple[tuple[int, int], ...]:
    """Padding (original row, column) that gives the rows at positions k and p one pattern
    after fill: each gets the other's columns, until the fill-in they cause agrees too."""
    while True:
        plan = _padded(base, rows, cols, padding)
        slots = row_slots(plan)
        extra = tuple((plan.row_perm[a], plan.col_perm[j]) for a, b in ((k, p), (p, k))
                      for j in sorted(set(slots[b]) - set(slots[a])))
        if not extra:
            return padding
        padding += extra


def _padded(base: LUPlan, rows: Sequence[int], cols: Sequence[int],
            padding: tuple[tuple[int, int], ...]) -> LUPlan:
    return lu_plan.padded(base, rows, cols, padding) if padding else base


def _with_swaps(plan: LUPlan, pairs: Sequence[tuple[int, int]]) -> LUPlan:
    slots = row_slots(plan)
    return dataclasses.replace(plan, swaps=tuple(_swap(slots, k, p) for k, p in pairs))


def same_pattern_rows(plan: LUPlan) -> dict[int, tuple[int, ...]]:
    """Per pivot position, the positions whose rows of L + U have the same columns (itself
    included), for rows that share their pattern with another."""
    columns = row_slots(plan)
    groups: dict[tuple[int, ...], list[int]] = {}
    for k in range(plan.n):
        groups.setdefault(tuple(sorted(columns[k])), []).append(k)
    return {k: tuple(members) for members in groups.values() if len(members) > 1
            for k in members}


def row_slots(plan: LUPlan) -> dict[int, dict[int, int]]:
    """Per pivot position (row of the factors), its slot in each column position it fills."""
    slots: dict[int, dict[int, int]] = {k: {} for k in range(plan.n)}
    for s in plan.steps:
        slots[s.k][s.k] = s.pivot
        for i, slot in s.lower:
            slots[i][s.k] = slot
        for j, slot in s.upper:
            slots[s.k][j] = slot
    return slots


def _swap(slots: dict[int, dict[int, int]], k: int, p: int) -> Swap:
    """The interchange of rows k and p (same columns) decided at step k."""
    return Swap(k, p, (slots[k][k], slots[p][k]),
                tuple((slots[k][j], slots[p][j]) for j in sorted(slots[k])))


def _failing(plan: LUPlan, samples: Sequence[np.ndarray]) -> dict[int, int]:
    """Sample index -> the first step whose pivot fails there."""
    steps = {index: factor(plan, sample).failed for index, sample in enumerate(samples)}
    return {index: k for index, k in steps.items() if k is not None}


def _slots(plan: LUPlan, sample: Sequence[float] | np.ndarray) -> np.ndarray:
    values = np.asarray(sample, dtype=float).ravel()
    if values.size != plan.nnz:
        raise ValueError(f"a sample has {values.size} values for {plan.nnz} non-zeros")
    return values


def factor(plan: LUPlan, nz: Sequence[float] | np.ndarray) -> Factors:
    """Execute the factorization of ``plan`` on Phi_q's non-zeros (pattern order), with its
    interchanges and run-time pivot tests, as the generated C does; stops at a failing pivot
    (the C code's fall-back case)."""
    v = np.zeros(plan.n_lu)
    v[: plan.nnz] = _slots(plan, nz)
    tiny = plan.n * np.finfo(float).eps * np.abs(v).max(initial=0.0)
    out = Factors(v, np.zeros(plan.n), [False] * len(plan.swaps))
    for s in plan.steps:
        _interchange(plan, s.k, out)
        column = max([abs(v[s.pivot])] + [abs(v[slot]) for _, slot in s.lower])
        ratio = abs(v[s.pivot]) / column if column > 0 else 0.0
        out.ratios.append(ratio)
        if not (abs(v[s.pivot]) >= plan.tau * column and abs(v[s.pivot]) > tiny):
            out.failed = s.k
            return out
        out.inv[s.k] = 1.0 / v[s.pivot]
        for _, slot in s.lower:
            v[slot] *= out.inv[s.k]
        for target, l_slot, u_slot in s.updates:
            v[target] -= v[l_slot] * v[u_slot]
    return out


def _interchange(plan: LUPlan, k: int, out: Factors) -> None:
    """The interchanges of step k, in plan order: each compares against the current row k."""
    v = out.v
    for index, swap in enumerate(plan.swaps):
        if swap.k != k or not abs(v[swap.pivots[1]]) > abs(v[swap.pivots[0]]):
            continue
        out.swapped[index] = True
        for a, b in swap.pairs:
            v[a], v[b] = v[b], v[a]


def solve_with_plan(plan: LUPlan, nz: Sequence[float] | np.ndarray,
                    b: Sequence[float] | np.ndarray) -> np.ndarray:
    """Factor with the plan and solve Phi_q x = b in Python: a slow reference of what the
    generated C does.

    Raises:
        SolveError: a pivot fails the run-time relative test (the C code's fall-back case).
    """
    lu = factor(plan, nz)
    if lu.failed is not None:
        raise SolveError(f"pivot {lu.failed} failed the relative pivot test")
    v = lu.v
    x = np.asarray(b, dtype=float)[list(plan.row_perm)].copy()
    for swap, done in zip(plan.swaps, lu.swapped):
        if done:
            x[[swap.k, swap.p]] = x[[swap.p, swap.k]]
    for s in plan.steps:
        for i, slot in s.lower:
            x[i] -= v[slot] * x[s.k]
    for s in reversed(plan.steps):
        for j, slot in s.upper:
            x[s.k] -= v[slot] * x[j]
        x[s.k] *= lu.inv[s.k]
    out = np.empty(plan.n)
    out[list(plan.col_perm)] = x
    return out
