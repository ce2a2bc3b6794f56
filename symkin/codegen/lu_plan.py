"""Generation-time analysis of the sparse LU factorization of Phi_q (chapter section 2.7).

The pattern of Phi_q is known exactly before any number exists, so the pivot order, the fill-in
and every floating-point operation of the factorization can be fixed once, at generation time
(the MA28 idea: analyse once, refactor cheaply at every step). This module chooses the order
with Markowitz's rule under a threshold test on a numeric sample of the Jacobian (codegen
takes it at the mechanism assembled at t0) and returns plain data: the straight-line list of
operations of the numeric factorization and of the two triangular solves, with the row and
column permutations baked in. The C template
``sparse_lu.c.j2`` renders that data, as straight-line code or, for very large systems, as
index tables walked by loops. At run time each pivot is checked again (|pivot| >= tau times
the largest entry of its active column, and above NQ eps max |Phi_q|); a failure sends the
factorization to a counted dense partial-pivoting fall-back, never to a wrong answer.

Storage: slot ``e < nnz`` holds the ``e``-th structural non-zero of Phi_q (pattern order), slots
``nnz .. n_lu-1`` hold fill-in. After factorization each slot holds its entry of L (strictly
lower part, multipliers) or U (upper part with the diagonal) of ``A[row_perm][:, col_perm]``.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from symkin.errors import SolveError

GENERATION_THRESHOLD = 0.1
"""Markowitz threshold u at generation: a pivot is at least u times its column's largest entry
in the sample (MA28's default)."""

RUNTIME_THRESHOLD = 0.01
"""Run-time relative pivot test tau. Looser than the generation threshold so that the order
chosen at the sample survives the motion; element growth stays below 1 + 1/tau per
elimination step."""


@dataclass(frozen=True)
class Step:
    """One elimination step: pivot slot, multipliers of column k, U row k, Schur updates."""

    k: int
    row: int  # original row of the pivot
    col: int  # original column of the pivot
    pivot: int  # slot of the pivot
    lower: tuple[tuple[int, int], ...]  # (permuted row index i > k, slot of L[i, k])
    upper: tuple[tuple[int, int], ...]  # (permuted column index j > k, slot of U[k, j])
    updates: tuple[tuple[int, int, int], ...]  # (target slot, L slot, U slot): t -= l * u
    sample_ratio: float  # |pivot| / max |column| in the sample; 0 when not numerically checked


@dataclass(frozen=True)
class LUPlan:
    """The fixed sequence of operations of a sparse LU factorization and solve."""

    n: int
    nnz: int
    n_lu: int
    row_perm: tuple[int, ...]  # pivot k sits in original row row_perm[k]
    col_perm: tuple[int, ...]  # ... and original column col_perm[k]
    steps: tuple[Step, ...]
    fill: tuple[tuple[int, int], ...]  # (row, col) of slots nnz.. in order
    tau: float
    unchecked: tuple[int, ...] = field(default=())  # steps chosen on structure alone

    @property
    def flops(self) -> int:
        """Multiply-adds and divisions of one factorization (checks not counted)."""
        return sum(1 + len(s.lower) + len(s.updates) for s in self.steps)

    @property
    def solve_flops(self) -> int:
        """Multiply-adds of one forward + back substitution."""
        return sum(1 + len(s.lower) + len(s.upper) for s in self.steps)


class _Active:
    """The active submatrix during symbolic + numeric elimination of the sample.

    Rows and columns are also kept in buckets by their entry count, so the Markowitz search
    looks at the few sparsest ones first and the analysis stays near-linear in N.
    """

    def __init__(self, n: int, rows: Sequence[int], cols: Sequence[int],
                 sample: np.ndarray) -> None:
        self.row_entries: dict[int, dict[int, float]] = {i: {} for i in range(n)}
        self.col_rows: dict[int, set[int]] = {j: set() for j in range(n)}
        self.slot: dict[tuple[int, int], int] = {}
        for e, (i, j) in enumerate(zip(rows, cols)):
            self.row_entries[i][j] = float(sample[e])
            self.col_rows[j].add(i)
            self.slot[(i, j)] = e
        # count -> sorted indices, so the search visits them in a fixed order without sorting
        self.row_bucket: dict[int, list[int]] = {}
        self.col_bucket: dict[int, list[int]] = {}
        for i, entries in self.row_entries.items():
            self.row_bucket.setdefault(len(entries), []).append(i)
        for j, members in self.col_rows.items():
            self.col_bucket.setdefault(len(members), []).append(j)

    def column_max(self, j: int) -> float:
        return max((abs(self.row_entries[i][j]) for i in self.col_rows[j]), default=0.0)

    def cost(self, i: int, j: int) -> int:
        """Markowitz cost: an upper bound on the fill-in this pivot can create."""
        return (len(self.row_entries[i]) - 1) * (len(self.col_rows[j]) - 1)

    def empty(self) -> bool:
        """Whether some active row or column has no entry left (structural singularity)."""
        return bool(self.row_bucket.get(0) or self.col_bucket.get(0))

    def counts(self) -> list[int]:
        return sorted({c for c, b in self.row_bucket.items() if b} |
                      {c for c, b in self.col_bucket.items() if b})

    @staticmethod
    def _move(bucket: dict[int, list[int]], key: int, old: int, new: int | None) -> None:
        members = bucket[old]
        del members[bisect.bisect_left(members, key)]
        if new is not None:
            bisect.insort(bucket.setdefault(new, []), key)

    def add(self, i: int, j: int, value: float, slot: int) -> None:
        """A new (fill-in) entry."""
        self._move(self.row_bucket, i, len(self.row_entries[i]), len(self.row_entries[i]) + 1)
        self._move(self.col_bucket, j, len(self.col_rows[j]), len(self.col_rows[j]) + 1)
        self.row_entries[i][j] = value
        self.col_rows[j].add(i)
        self.slot[(i, j)] = slot

    def remove_pivot(self, r: int, c: int) -> tuple[dict[int, float], float, list[int]]:
        """Take row r and column c out: (the rest of row r, the pivot, the other rows of c)."""
        self._move(self.row_bucket, r, len(self.row_entries[r]), None)
        self._move(self.col_bucket, c, len(self.col_rows[c]), None)
        pivot_row = self.row_entries.pop(r)
        pivot = pivot_row.pop(c)
        others = sorted(self.col_rows.pop(c) - {r})
        for j in pivot_row:
            self._move(self.col_bucket, j, len(self.col_rows[j]), len(self.col_rows[j]) - 1)
            self.col_rows[j].discard(r)
        for i in others:
            self._move(self.row_bucket, i, len(self.row_entries[i]), len(self.row_entries[i]) - 1)
        return pivot_row, pivot, others


def analyse(n: int, rows: Sequence[int], cols: Sequence[int], sample: Sequence[float],
            generation_threshold: float = GENERATION_THRESHOLD,
            tau: float = RUNTIME_THRESHOLD) -> LUPlan:
    """Choose the pivot order and compute the operations of a sparse LU of an N x N pattern.

    Args:
        n: the size N of the square matrix.
        rows, cols: the structural non-zeros, in the order the values will be passed at run
            time (the order of ``<prefix>_phi_q``'s output).
        sample: the values of those non-zeros at a representative state (e.g. Phi_q of the
            mechanism assembled at t0); pivots are chosen so that each passes the threshold
            test on this sample.
        generation_threshold: u of the threshold test used to choose the order.
        tau: the relative pivot test applied at run time (recorded in the plan).

    Raises:
        SolveError: the pattern is structurally singular (no pivot exists in some column).
    """
    values = _check_input(n, rows, cols, sample)
    rows, cols = [int(i) for i in rows], [int(j) for j in cols]
    active = _Active(n, rows, cols, values)
    steps: list[Step] = []
    fill: list[tuple[int, int]] = []
    unchecked: list[int] = []
    for k in range(n):
        pick = _choose_pivot(active, generation_threshold)
        if pick is None:
            raise SolveError(_structural_message(active))
        (i, j), ratio = pick
        if ratio == 0.0:
            unchecked.append(k)
        steps.append(_eliminate(active, k, i, j, ratio, fill, len(rows)))
    return _permute(n, len(rows), steps, fill, tau, tuple(unchecked))


def _check_input(n: int, rows: Sequence[int], cols: Sequence[int],
                 sample: Sequence[float]) -> np.ndarray:
    values = np.asarray(sample, dtype=float).ravel()
    if not len(rows) == len(cols) == len(values):
        raise ValueError(f"pattern and sample disagree: {len(rows)} rows, {len(cols)} columns, "
                         f"{len(values)} values")
    pairs = [(int(i), int(j)) for i, j in zip(rows, cols)]
    if any(not (0 <= i < n and 0 <= j < n) for i, j in pairs):
        raise ValueError(f"a pattern index lies outside the {n} x {n} matrix")
    if len(set(pairs)) != len(pairs):
        raise ValueError("the pattern lists an entry twice")
    if not np.all(np.isfinite(values)):
        raise ValueError("the sample Jacobian has a non-finite entry")
    return values


class _Search:
    """The state of one Markowitz search: the best candidate so far, and the cheapest entry."""

    def __init__(self, active: _Active, u: float) -> None:
        self.active = active
        self.u = u
        self.best: tuple[int, float, tuple[int, int]] | None = None  # (cost, ratio, (i, j))
        self.structural: tuple[int, tuple[int, int]] | None = None  # (cost, (i, j))
        self.column_max: dict[int, float] = {}

    def consider(self, i: int, j: int) -> bool:
        """Record (i, j); True when it is a perfect pivot: no fill, largest in its column."""
        cost = self.active.cost(i, j)
        if self.structural is None or (cost, (i, j)) < self.structural:
            self.structural = (cost, (i, j))
        if j not in self.column_max:
            self.column_max[j] = self.active.column_max(j)
        size = abs(self.active.row_entries[i][j])
        if size == 0.0 or size < self.u * self.column_max[j]:
            return False
        ratio = size / self.column_max[j]
        best = self.best
        if best is None or (cost, -ratio, (i, j)) < (best[0], -best[1], best[2]):
            self.best = (cost, ratio, (i, j))
        return cost == 0 and ratio == 1.0

    def scan(self) -> None:
        """Columns, then rows, of count 1, 2, ...; stop when nothing unseen can do better."""
        active = self.active
        for count in active.counts():
            for j in active.col_bucket.get(count, ()):
                if any(self.consider(i, j) for i in sorted(active.col_rows[j])):
                    return
            for i in active.row_bucket.get(count, ()):
                if any(self.consider(i, j) for j in sorted(active.row_entries[i])):
                    return
            if self.best is not None and self.best[0] <= count * count:
                return


def _choose_pivot(active: _Active, u: float) -> tuple[tuple[int, int], float] | None:
    """Markowitz search over columns, then rows, of count 1, 2, ... (Zlatev's strategy).

    Among the entries that pass the threshold test on the sample, take the least cost, then
    the largest ratio |a_ij| / max |a_.j|, then the smallest (i, j), so the choice is
    deterministic. After every row and column of count <= c has been seen, any other entry
    costs at least c^2, so the search stops once the best cost found is that low, or at the
    first perfect pivot (no fill, largest in its column), which nothing can beat. When the
    sample passes no entry at all (a singular sample), take the cheapest structural entry; the
    run-time test still guards that pivot.
    """
    if active.empty():
        return None
    search = _Search(active, u)
    search.scan()
    if search.best is not None:
        return search.best[2], search.best[1]
    return (search.structural[1], 0.0) if search.structural is not None else None


def _eliminate(active: _Active, k: int, r: int, c: int, ratio: float,
               fill: list[tuple[int, int]], nnz: int) -> Step:
    """Eliminate pivot (r, c) from the active submatrix, recording slots and fill-in."""
    pivot_row, pivot, others = active.remove_pivot(r, c)
    lower, updates = [], []
    for i in others:
        row = active.row_entries[i]
        entry = row.pop(c)
        multiplier = entry / pivot if pivot != 0.0 else 0.0  # zero pivot: structure only
        lower.append((i, active.slot[(i, c)]))
        for j, u_value in sorted(pivot_row.items()):
            if j not in row:
                active.add(i, j, 0.0, nnz + len(fill))
                fill.append((i, j))
            row[j] -= multiplier * u_value
            updates.append((active.slot[(i, j)], active.slot[(i, c)], active.slot[(r, j)]))
    upper = tuple((j, active.slot[(r, j)]) for j in sorted(pivot_row))
    return Step(k, r, c, active.slot[(r, c)], tuple(lower), upper, tuple(updates), ratio)


def _permute(n: int, nnz: int, steps: list[Step], fill: list[tuple[int, int]], tau: float,
             unchecked: tuple[int, ...]) -> LUPlan:
    """Replace original row/column numbers in L and U entries by pivot positions."""
    row_pos = {s.row: s.k for s in steps}
    col_pos = {s.col: s.k for s in steps}
    permuted = tuple(
        Step(s.k, s.row, s.col, s.pivot,
             tuple(sorted((row_pos[i], slot) for i, slot in s.lower)),
             tuple(sorted((col_pos[j], slot) for j, slot in s.upper)),
             s.updates, s.sample_ratio)
        for s in steps)
    return LUPlan(n=n, nnz=nnz, n_lu=nnz + len(fill),
                  row_perm=tuple(s.row for s in steps), col_perm=tuple(s.col for s in steps),
                  steps=permuted, fill=tuple(fill), tau=tau, unchecked=unchecked)


def _structural_message(active: _Active) -> str:
    empty_cols = [j for j, r in active.col_rows.items() if not r]
    empty_rows = [i for i, r in active.row_entries.items() if not r]
    return ("the Jacobian's pattern is structurally singular: after eliminating what can be "
            f"eliminated, column(s) {empty_cols[:10]} and row(s) {empty_rows[:10]} have no "
            "entry left. Some coordinates are not constrained (or some equations repeat); "
            "check the joints and drivers, and that drivers match the degrees of freedom")


PART_OPS = 250
"""Statements per generated C function: gcc's optimiser is superlinear in function size, so
the straight-line factor and solve are split into parts of about this many operations."""


TABLE_FLOPS = 20000
"""Above this many factor + solve operations the C code walks index tables in loops instead of
being straight-line: constant code size and compile time. Straight-line code was faster at
every size measured (chain of 301 bodies, 5,700 operations: 14-18 us against 22 us for one
factorization and three solves, but 4.8 s of gcc against 0.3 s), hence the high limit."""


def template_context(plan: LUPlan, part_ops: int = PART_OPS,
                     style: str | None = None) -> dict[str, object]:
    """The plan as plain data for ``templates/c/sparse_lu.*.j2`` (key ``lu``).

    Args:
        plan: the analysed factorization.
        part_ops: operations per generated function in the straight-line style.
        style: "straight" (one C statement per operation) or "tables" (loops over static
            index arrays); by default straight-line up to TABLE_FLOPS operations.
    """
    if style is None:
        style = "straight" if plan.flops + plan.solve_flops <= TABLE_FLOPS else "tables"
    if style not in ("straight", "tables"):
        raise ValueError(f"unknown sparse LU style {style!r}: use 'straight' or 'tables'")
    steps = [{"k": s.k, "row": s.row, "col": s.col, "pivot": s.pivot,
              "lower": [list(x) for x in s.lower], "upper": [list(x) for x in s.upper],
              "updates": [list(x) for x in s.updates]} for s in plan.steps]
    backward = list(reversed(steps))
    return {
        "n_lu": plan.n_lu,
        "n_fill": plan.n_lu - plan.nnz,
        "tau": repr(float(plan.tau)),
        "flops": plan.flops,
        "solve_flops": plan.solve_flops,
        "row_perm": list(plan.row_perm),
        "col_perm": list(plan.col_perm),
        "fill_slots": list(range(plan.nnz, plan.n_lu)),
        "unchecked": list(plan.unchecked),
        "ratio_tests": sum(1 for s in plan.steps if s.lower),
        "factor_parts": _parts(steps, lambda s: 2 + 2 * len(s["lower"]) + len(s["updates"]),
                               part_ops),
        "forward_parts": _parts([s for s in steps if s["lower"]], lambda s: len(s["lower"]),
                                part_ops),
        "backward_parts": _parts(backward, lambda s: 1 + len(s["upper"]), part_ops),
        "style": style,
        "tables": _tables(plan),
    }


def _tables(plan: LUPlan) -> dict[str, list[int]]:
    """The plan as compressed index arrays (offsets per pivot), each ending in one zero record
    so that no C array is empty (C99 forbids it) even when a plan has no such entry."""
    tables: dict[str, list[int]] = {"pivot": [s.pivot for s in plan.steps]}
    records: tuple[tuple[str, int, Callable[[Step], Any]], ...] = (
        ("lower", 2, lambda s: s.lower), ("upper", 2, lambda s: s.upper),
        ("update", 3, lambda s: s.updates))
    for name, width, pick in records:
        start, flat = [0], []
        for step in plan.steps:
            for entry in pick(step):
                flat.extend(entry)
            start.append(start[-1] + len(pick(step)))
        tables[f"{name}_start"] = start
        tables[name] = flat + [0] * width
    return tables


def _parts(steps: list[dict[str, Any]], size: Callable[[dict[str, Any]], int],
           limit: int) -> list[dict[str, Any]]:
    """Consecutive runs of steps of at most ``limit`` operations each (at least one step);
    ``checks`` says whether a run has a ratio test (and so needs its column maximum)."""
    runs: list[list[dict[str, Any]]] = []
    total = 0
    for step in steps:
        ops = size(step)
        if not runs or (runs[-1] and total + ops > limit):
            runs.append([])
            total = 0
        runs[-1].append(step)
        total += ops
    return [{"steps": run, "checks": any(s["lower"] for s in run)} for run in runs]


def solve_with_plan(plan: LUPlan, nz: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """Execute the plan in Python: a slow reference of what the generated C does.

    Raises:
        SolveError: a pivot fails the run-time relative test (the C code's fall-back case).
    """
    v = np.zeros(plan.n_lu)
    v[: plan.nnz] = np.asarray(nz, dtype=float)
    tiny = plan.n * np.finfo(float).eps * np.abs(v).max()
    inv = np.zeros(plan.n)
    for s in plan.steps:
        column = [abs(v[s.pivot])] + [abs(v[slot]) for _, slot in s.lower]
        if not (abs(v[s.pivot]) >= plan.tau * max(column) and abs(v[s.pivot]) > tiny):
            raise SolveError(f"pivot {s.k} failed the relative pivot test")
        inv[s.k] = 1.0 / v[s.pivot]
        for _, slot in s.lower:
            v[slot] *= inv[s.k]
        for target, lslot, uslot in s.updates:
            v[target] -= v[lslot] * v[uslot]
    x = np.asarray(b, dtype=float)[list(plan.row_perm)].copy()
    for s in plan.steps:
        for i, slot in s.lower:
            x[i] -= v[slot] * x[s.k]
    for s in reversed(plan.steps):
        for j, slot in s.upper:
            x[s.k] -= v[slot] * x[j]
        x[s.k] *= inv[s.k]
    out = np.empty(plan.n)
    out[list(plan.col_perm)] = x
    return out
