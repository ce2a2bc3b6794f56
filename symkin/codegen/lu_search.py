"""The Markowitz search of lu_plan: the active submatrix and the choice of each pivot.

An elimination step changes only a few rows and columns of the active submatrix (the pivot
row's columns, the pivot column's rows), yet the search visits every sparse row and column
whose entries failed the threshold test at the last step, and they stay in the sparsest
buckets (an entry that is exactly zero on the sample fails at every step). So what a row or
column offers the search (``Offer``: the first entry with no fill-in that passes, the cheapest
entry that passes, the cheapest entry) is remembered between steps, with each column's
largest magnitude and its entries' ratios, and forgotten only for the lines a step touched:
a column that changed (an entry added, removed or updated: its largest magnitude, the ratios
and the costs of its entries move) and a row whose count changed (the costs of its entries
move), each with the lines crossing it. The choice is the scan of every entry one at a time,
in the same order with the same stopping rule; only the repeated work is gone (1001-body
chain: 14 s to well under a second).
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

Candidate = tuple[int, tuple[int, int]]  # (Markowitz cost, (row, column))


@dataclass(frozen=True)
class Offer:
    """What one row or column offers a search with threshold u, from its entries in order."""

    stop: bool  # it holds a candidate with no fill-in (then ``best``): the search ends there
    best: Candidate | None  # the cheapest entry that passes the threshold test
    structural: Candidate | None  # the cheapest entry of all (until ``stop``)


class Active:
    """The active submatrix during symbolic + numeric elimination of the sample.

    Rows and columns are also kept in buckets by their entry count, so the Markowitz search
    looks at the few sparsest ones first and the analysis stays near-linear in N.
    """

    def __init__(self, n: int, rows: Sequence[int], cols: Sequence[int],
                 samples: np.ndarray) -> None:
        # an entry's value is the array of its values in the samples (one column each)
        self.row_entries: dict[int, dict[int, np.ndarray]] = {i: {} for i in range(n)}
        self.col_rows: dict[int, set[int]] = {j: set() for j in range(n)}
        self.slot: dict[tuple[int, int], int] = {}
        self.width = samples.shape[1]
        for e, (i, j) in enumerate(zip(rows, cols)):
            self.row_entries[i][j] = samples[e].copy()
            self.col_rows[j].add(i)
            self.slot[(i, j)] = e
        # count -> sorted indices, so the search visits them in a fixed order without sorting
        self.row_bucket: dict[int, list[int]] = {}
        self.col_bucket: dict[int, list[int]] = {}
        for i, entries in self.row_entries.items():
            self.row_bucket.setdefault(len(entries), []).append(i)
        for j, members in self.col_rows.items():
            self.col_bucket.setdefault(len(members), []).append(j)
        self.memo = _Memo(self)

    def column_max(self, j: int) -> np.ndarray:
        """max |a_.j| of the active column in each sample."""
        entries = [np.abs(self.row_entries[i][j]) for i in self.col_rows[j]]
        return np.max(entries, axis=0) if entries else np.zeros(self.width)

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

    def add(self, i: int, j: int, value: np.ndarray, slot: int) -> None:
        """A new (fill-in) entry."""
        self._move(self.row_bucket, i, len(self.row_entries[i]), len(self.row_entries[i]) + 1)
        self._move(self.col_bucket, j, len(self.col_rows[j]), len(self.col_rows[j]) + 1)
        self.row_entries[i][j] = value
        self.col_rows[j].add(i)
        self.slot[(i, j)] = slot
        self.memo.touch([i], [j])

    def remove_pivot(self, r: int, c: int
                     ) -> tuple[dict[int, np.ndarray], np.ndarray, list[int]]:
        """Take row r and column c out: (the rest of row r, the pivot, the other rows of c).

        The caller updates only entries (i, j) with i among the other rows and j among the
        rest of row r, which this marks as changed."""
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
        self.memo.touch([r, *others], [c, *pivot_row])
        return pivot_row, pivot, others


class _Memo:
    """Per column its largest magnitudes and its entries' ratios, per threshold each line's
    Offer; ``touch`` marks lines changed, and the next look-up forgets what they affect."""

    def __init__(self, active: Active) -> None:
        self.active = active
        self.column_max: dict[int, np.ndarray] = {}
        self.ratios: dict[int, dict[int, float]] = {}  # column -> row -> ratio
        self.offers: dict[tuple[float | None, str], dict[int, Offer]] = {}
        self.rows: set[int] = set()
        self.cols: set[int] = set()

    def touch(self, rows: Sequence[int], cols: Sequence[int]) -> None:
        self.rows.update(rows)
        self.cols.update(cols)

    def flush(self) -> None:
        """Forget what the changed lines affect: a changed column's maximum, ratios and
        offer, and the offers of the rows crossing it; a changed row's offer, and the offers
        of the columns crossing it (the cost of the entry they share moved)."""
        if not (self.rows or self.cols):
            return
        active = self.active
        stale_rows, stale_cols = set(self.rows), set(self.cols)
        for j in self.cols:
            self.column_max.pop(j, None)
            self.ratios.pop(j, None)
            stale_rows.update(active.col_rows.get(j, ()))
        for i in self.rows:
            stale_cols.update(active.row_entries.get(i, ()))
        for (_, kind), offers in self.offers.items():
            for line in stale_cols if kind == "col" else stale_rows:
                offers.pop(line, None)
        self.rows.clear()
        self.cols.clear()

    def ratio(self, i: int, j: int) -> float:
        """The least |a_ij| / max |a_.j| over the active samples (0 in a zero column)."""
        column = self.ratios.setdefault(j, {})
        if i not in column:
            if j not in self.column_max:
                self.column_max[j] = self.active.column_max(j)
            largest = self.column_max[j]
            ratios = np.divide(np.abs(self.active.row_entries[i][j]), largest,
                               out=np.zeros_like(largest), where=largest > 0)
            column[i] = float(ratios.min())
        return column[i]

    def offer(self, u: float | None, kind: str, line: int) -> Offer:
        offers = self.offers.setdefault((u, kind), {})
        if line not in offers:
            entries = (((i, line) for i in sorted(self.active.col_rows[line])) if kind == "col"
                       else ((line, j) for j in sorted(self.active.row_entries[line])))
            offers[line] = self._scan_line(u, entries)
        return offers[line]

    def _scan_line(self, u: float | None, entries: Iterable[tuple[int, int]]) -> Offer:
        """The entries of one line in order: every one counts for ``structural``; one that
        passes (|a_ij| >= u max |a_.j|, every entry when u is None) for ``best``; the first
        that passes with no fill-in ends the line."""
        best: Candidate | None = None
        structural: Candidate | None = None
        for i, j in entries:
            candidate = (self.active.cost(i, j), (i, j))
            if structural is None or candidate < structural:
                structural = candidate
            if u is not None:
                ratio = self.ratio(i, j)
                if ratio == 0.0 or ratio < u:
                    continue
            if best is None or candidate < best:
                best = candidate
            if candidate[0] == 0:
                return Offer(True, best, structural)
        return Offer(False, best, structural)


class Search:
    """The state of one Markowitz search: the best candidate so far, and the cheapest entry."""

    def __init__(self, active: Active, u: float | None) -> None:
        self.active = active
        self.u = u  # None: every structural entry is a candidate
        self.best: Candidate | None = None
        self.structural: Candidate | None = None
        active.memo.flush()

    def ratio(self, i: int, j: int) -> float:
        """The least |a_ij| / max |a_.j| over the active samples (0 in a zero column)."""
        return self.active.memo.ratio(i, j)

    def _take(self, offer: Offer) -> bool:
        """Merge a line's offer; True when nothing can beat it (a candidate with no fill)."""
        if offer.structural is not None and (self.structural is None
                                             or offer.structural < self.structural):
            self.structural = offer.structural
        if offer.best is not None and (self.best is None or offer.best < self.best):
            self.best = offer.best
        return offer.stop

    def scan(self) -> None:
        """Columns, then rows, of count 1, 2, ...; stop when nothing unseen can do better."""
        active, memo = self.active, self.active.memo
        for count in active.counts():
            for j in active.col_bucket.get(count, ()):
                if self._take(memo.offer(self.u, "col", j)):
                    return
            for i in active.row_bucket.get(count, ()):
                if self._take(memo.offer(self.u, "row", i)):
                    return
            if self.best is not None and self.best[0] <= count * count:
                return
