"""Singular configurations passed through along a forward-dynamics run.

The integrator watches sigma_min / sigma_max of Φ_q at every accepted step (:func:`nearness`:
structurally dependent rows, a parallelogram's extra bar, left out). Where it has a local
minimum below SUSPECT, the minimum is sought between the neighbouring steps along the
motion: the cubic Hermite interpolant of q, q̇ at the three accepted states, projected onto
Φ = 0 by minimum-norm Newton steps (so the search runs along the mechanism's own branch and
reaches the crossing of two branches, where a change point is). A minimum below PASSAGE is
a singular configuration passed through: its time, the rank Φ_q loses there and the groups
of dependent rows, as kinematics reports (runtime.solving.edges.Passage).

Why a search between steps: the steps rarely land within 1e-7 of the crossing (the A02
chain's nearest output row has a condition of only 5e5), so the accepted states alone would
not see a passage the motion makes exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.dynamics.equations import RANK_TOLERANCE
from symkin.runtime.dynamics.model import Model
from symkin.runtime.solving.linalg import dependencies

Array = NDArray[np.float64]

# A local minimum of the ratio below this is searched between the steps.
SUSPECT = 1e-2
# A minimum below this is a singular configuration (the rank test of kinematics' passages).
PASSAGE = 1e-7
SEARCH_ITERATIONS = 60
PROJECTION_ITERATIONS = 8


@dataclass(frozen=True)
class Watched:
    """An accepted state and the nearness of its Φ_q to a singular one."""

    t: float
    q: Array
    dq: Array
    ratio: float
    structural: int  # rows of Φ_q dependent to rounding there (redundant constraints)


@dataclass(frozen=True)
class Passage:
    """A singular configuration passed at t: Φ_q loses ``rank_loss`` there beyond its
    structural dependence, with the groups of dependent rows."""

    t: float
    rank_loss: int
    groups: tuple[tuple[str, ...], ...]


def watched(model: Model, t: float, q: Array, dq: Array, p: Array,
            jacobian: Array | None = None) -> Watched:
    """The accepted state with the smallest singular value of Φ_q above the structural zero
    (RANK_TOLERANCE) relative to the largest; ``jacobian``: Φ_q there, where the caller has
    it already (the integrator's projection ends with it)."""
    ratio, structural = _nearness(_values(model, q, t, p, jacobian))
    return Watched(t, q.copy(), dq.copy(), ratio, structural)


def _nearness(values: Array) -> tuple[float, int]:
    """From Φ_q's singular values (descending): the smallest above the structural zero over
    the largest, and how many are structural zeros (dependent rows to rounding)."""
    if values.size == 0 or values[0] <= 0.0:
        return 1.0, 0
    above = values[values > RANK_TOLERANCE * values[0]]
    return float(above[-1] / values[0]), int(values.size - above.size)


def search(model: Model, p: Array, trail: tuple[Watched, Watched, Watched]) -> Passage | None:
    """The passage near the middle state of ``trail`` when its ratio is a local minimum
    below SUSPECT and the minimum between the outer two falls below PASSAGE; else None."""
    before, middle, after = trail
    if not (middle.ratio < SUSPECT and middle.ratio <= before.ratio
            and middle.ratio <= after.ratio):
        return None
    structural = min(before.structural, after.structural)
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    low, high = before.t, after.t
    x1, x2 = high - golden * (high - low), low + golden * (high - low)
    f1, f2 = _ratio_at(model, p, trail, x1), _ratio_at(model, p, trail, x2)
    for _ in range(SEARCH_ITERATIONS):
        if f1 <= f2:
            high, x2, f2 = x2, x1, f1
            x1 = high - golden * (high - low)
            f1 = _ratio_at(model, p, trail, x1)
        else:
            low, x1, f1 = x1, x2, f2
            x2 = low + golden * (high - low)
            f2 = _ratio_at(model, p, trail, x2)
    t, least = (x1, f1) if f1 <= f2 else (x2, f2)
    if least >= PASSAGE:
        return None  # near a singular configuration, not through one: the rows' cond tells
    q = _on_branch(model, p, trail, t)
    rank_loss, groups = dependencies(model.phi_q(q, t, p), list(model.rows), rcond=PASSAGE)
    if rank_loss <= structural:
        return None
    return Passage(t, rank_loss - structural, tuple(tuple(g) for g in groups))


def _values(model: Model, q: Array, t: float, p: Array, jacobian: Array | None = None
            ) -> Array:
    if jacobian is None:
        jacobian = model.phi_q(q, t, p)
    if jacobian.size == 0:
        return np.zeros(0)
    return np.asarray(np.linalg.svd(jacobian, compute_uv=False), dtype=np.float64)


def _ratio_at(model: Model, p: Array, trail: tuple[Watched, Watched, Watched],
              t: float) -> float:
    values = _values(model, _on_branch(model, p, trail, t), t, p)
    if values.size == 0 or values[0] <= 0.0:
        return 1.0
    structural = min(trail[0].structural, trail[2].structural)
    return float(values[values.size - 1 - structural] / values[0])


def _on_branch(model: Model, p: Array, trail: tuple[Watched, Watched, Watched],
               t: float) -> Array:
    """q at t from the cubic Hermite interpolant of the accepted states around it,
    projected onto Φ = 0 by minimum-norm Newton steps."""
    a, b = (trail[0], trail[1]) if t <= trail[1].t else (trail[1], trail[2])
    h = b.t - a.t
    s = (t - a.t) / h if h > 0 else 0.0
    q = ((2 * s**3 - 3 * s**2 + 1) * a.q + (s**3 - 2 * s**2 + s) * h * a.dq
         + (-2 * s**3 + 3 * s**2) * b.q + (s**3 - s**2) * h * b.dq)
    for _ in range(PROJECTION_ITERATIONS):
        residual = model.phi(q, t, p)
        if np.max(np.abs(residual), initial=0.0) <= 1e-13:
            break
        q = q - np.linalg.lstsq(model.phi_q(q, t, p), residual, rcond=None)[0]
    return np.asarray(q, dtype=np.float64)


def lost_rank(model: Model, q: Array, t: float, p: Array
              ) -> tuple[int, tuple[tuple[str, ...], ...]] | None:
    """The rank Φ_q loses at (q, t) beyond its structural dependence and its groups of
    dependent rows, when its ratio is below SUSPECT (None otherwise)."""
    jacobian = model.phi_q(q, t, p)
    values = _values(model, q, t, p, jacobian)
    ratio, structural = _nearness(values)
    if ratio >= SUSPECT:
        return None
    rcond = max(PASSAGE, 2.0 * ratio)
    _, groups = dependencies(jacobian, list(model.rows), rcond=rcond)
    count = int(np.count_nonzero(values <= rcond * values[0]))
    return max(count - structural, 1), tuple(tuple(g) for g in groups)
