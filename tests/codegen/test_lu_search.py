"""The Markowitz search that remembers each row's and column's offer between pivots
(codegen.lu_search) chooses exactly the pivots of the search that looked at every entry
again at every step, kept here as the reference: the same plans (order, fill-in, slots,
operations, run-time interchanges) on example mechanisms, on the chain and the lazy tongs
(fill-in) and on random sparse patterns whose samples hold exact zeros and ties."""

from __future__ import annotations

import dataclasses
import importlib.util
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import symkin
from symkin.codegen import lu_interchange, lu_plan, sample
from symkin.codegen.lu_search import Active
from symkin.errors import SolveError
from symkin.spec import validate as model

ROOT = Path(__file__).resolve().parents[2]


class EveryEntrySearch:
    """The search as it was: every entry of the lines it visits, looked at again at each step
    (its cost and, with a threshold, its ratio to its column's largest magnitude)."""

    def __init__(self, active: Active, u: float | None) -> None:
        self.active = active
        self.u = u
        self.best: tuple[int, tuple[int, int]] | None = None
        self.structural: tuple[int, tuple[int, int]] | None = None
        self.column_max: dict[int, np.ndarray] = {}

    def ratio(self, i: int, j: int) -> float:
        if j not in self.column_max:
            self.column_max[j] = self.active.column_max(j)
        largest = self.column_max[j]
        ratios = np.divide(np.abs(self.active.row_entries[i][j]), largest,
                           out=np.zeros_like(largest), where=largest > 0)
        return float(ratios.min())

    def consider(self, i: int, j: int) -> bool:
        cost = self.active.cost(i, j)
        if self.structural is None or (cost, (i, j)) < self.structural:
            self.structural = (cost, (i, j))
        if self.u is not None:
            ratio = self.ratio(i, j)
            if ratio == 0.0 or ratio < self.u:
                return False
        if self.best is None or (cost, (i, j)) < self.best:
            self.best = (cost, (i, j))
        return cost == 0

    def scan(self) -> None:
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


def both(monkeypatch: pytest.MonkeyPatch, analyse: Any, *args: Any
         ) -> tuple[lu_plan.LUPlan, lu_plan.LUPlan]:
    """``analyse(*args)`` by the search in the package and by the reference."""
    new = analyse(*args)
    with monkeypatch.context() as patch:
        patch.setattr(lu_plan, "Search", EveryEntrySearch)
        old = analyse(*args)
    return new, old


def _bench(name: str) -> Any:
    spec = importlib.util.spec_from_file_location(name, ROOT / "bench" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _systems() -> list[tuple[str, Any]]:
    family = _bench("scaling_family")
    limit = _bench("scaling_limit")
    files = ["crank_slider", "four_bar", "andrews_squeezer", "cardan", "planetary",
             "quick_return"]
    return ([(name, ROOT / "examples" / f"{name}.yaml") for name in files]
            + [("chain of 12 loops", model.from_dict(family.chain(12))),
               ("tongs of 12 units", model.from_dict(limit.tongs(12)))])


@pytest.mark.parametrize("name, source", _systems(), ids=lambda v: v if isinstance(v, str)
                         else "")
def test_the_same_plan_on_mechanisms(name: str, source: Any,
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    system = symkin.derive(source)
    pattern = system.pattern()
    samples = sample._plan_samples(system, pattern)
    rows, cols = [r for r, _ in pattern], [c for _, c in pattern]
    new, old = both(monkeypatch, lu_interchange.analyse_over, len(system.q), rows, cols,
                    samples)
    assert dataclasses.astuple(new) == dataclasses.astuple(old), name
    if name.startswith("tongs"):
        assert new.n_lu > new.nnz  # fill-in is exercised


def _random_case(rng: np.random.Generator) -> tuple[int, list[int], list[int],
                                                      list[list[float]]]:
    """A structurally non-singular pattern of 3 to 24 rows and 1 to 4 samples of values from a
    small set (exact zeros, ties, entries just above and below the threshold)."""
    n = int(rng.integers(3, 25))
    cells = {(i, int(j)) for i, j in enumerate(rng.permutation(n))}
    for i in range(n):
        size = min(n, int(rng.integers(1, 5)))
        cells |= {(i, int(j)) for j in rng.choice(n, size=size, replace=False)}
    ordered = sorted(cells)
    levels = np.array([0.0, 0.0, 0.05, 0.1, 0.5, 1.0, 1.0, 2.0])
    samples = [(rng.choice(levels, len(ordered)) * rng.choice([-1.0, 1.0], len(ordered)))
               .tolist() for _ in range(int(rng.integers(1, 5)))]
    return n, [i for i, _ in ordered], [j for _, j in ordered], samples


def test_the_same_plan_on_random_patterns(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(38)
    compared = fill = 0
    for _ in range(60):
        n, rows, cols, samples = _random_case(rng)
        # the order over the samples (the interchanges' search is the mechanisms')
        new, old = both(monkeypatch, lu_plan.analyse_over, n, rows, cols, samples)
        assert dataclasses.astuple(new) == dataclasses.astuple(old), (n, rows, cols, samples)
        compared += 1
        fill += new.n_lu > new.nnz
    assert compared == 60 and fill >= 20


def test_a_structurally_singular_pattern_is_refused_alike(
        monkeypatch: pytest.MonkeyPatch) -> None:
    rows, cols, values = [0, 1, 2], [0, 0, 2], [[1.0, 2.0, 3.0]]
    with pytest.raises(SolveError) as new:
        lu_interchange.analyse_over(3, rows, cols, values)
    monkeypatch.setattr(lu_plan, "Search", EveryEntrySearch)
    with pytest.raises(SolveError) as old:
        lu_interchange.analyse_over(3, rows, cols, values)
    assert str(new.value) == str(old.value)
