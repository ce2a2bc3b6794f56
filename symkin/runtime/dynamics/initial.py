"""The state at t0: the assembled position and a consistent initial velocity.

Position: Newton's minimum-norm steps Δq = -Φ_q⁺ Φ from the file's q0 (Φ has fewer rows
than coordinates, so the step that moves q least is taken: q0 chooses the configuration).

Velocity: the file gives some components (``initial.velocities``: a coordinate's rate, or a
spatial body's global ω); the velocity is the one of least kinetic energy that satisfies the
constraints and matches the given components,

    min ½ q̇ᵀ M q̇   subject to   Φ_q q̇ = -Φ_t,  C q̇ = c,

solved through its optimality system [M Φ_qᵀ Cᵀ; Φ_q 0 0; C 0 0]. A given component that the
constraints already decide (a pinned body's x rate) is kept only if it agrees with them;
otherwise it is refused, named.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from symkin.errors import MechanismError, SolveError
from symkin.limits import listed
from symkin.runtime.dynamics.equations import RANK_TOLERANCE
from symkin.runtime.dynamics.model import Model

Array = NDArray[np.float64]

ASSEMBLY_TOLERANCE = 1e-12
ASSEMBLY_ITERATIONS = 50
# A given component agrees with the constraints when its residual is below this, relative
# to the size of the velocities involved.
AGREEMENT = 1e-9


class ContradictoryVelocities(MechanismError):
    """Given initial velocity components contradict the constraints: a mistake in the file,
    placed at the first of them (the CLI then names its line)."""

    def __init__(self, message: str, hint: str, names: tuple[str, ...]) -> None:
        super().__init__(message, ("initial", "velocities", names[0]), hint)
        self.names = names


def assemble(model: Model, q: Array, t: float, p: Array, tolerance: float) -> Array:
    """q with Φ(q, t) = 0 to ``tolerance`` (max norm), by minimum-norm Newton steps."""
    q = np.array(q, dtype=float)
    for _ in range(ASSEMBLY_ITERATIONS):
        residual = model.phi(q, t, p)
        if np.max(np.abs(residual), initial=0.0) <= tolerance:
            return q
        q -= np.linalg.lstsq(model.phi_q(q, t, p), residual, rcond=None)[0]
        if not np.all(np.isfinite(q)):
            break
    raise SolveError(f"cannot assemble the mechanism at t = {t:g}: |Phi| = "
                     f"{np.max(np.abs(model.phi(q, t, p))):.3g} after {ASSEMBLY_ITERATIONS} "
                     "Newton steps from q0. Give bodies.<name>.q0 closer to an assembled "
                     "configuration.")


def omega_row(e: Array, axis: int) -> Array:
    """Row ``axis`` of 2 E(p): ω = 2 E ṗ in global components (REFERENCE.md, space)."""
    e0, e1, e2, e3 = e
    rates = np.array([[-e1, e0, -e3, e2], [-e2, e3, e0, -e1], [-e3, -e2, e1, e0]])
    row: Array = 2.0 * rates[axis]
    return row


def given_rows(model: Model, q: Array, p: Array) -> tuple[Array, Array, tuple[str, ...]]:
    """C, c (the given values at the run's parameters p) and the names of the given
    components."""
    n = q.size
    rows, names = [], []
    for item in model.given:
        row = np.zeros(n)
        columns = list(item.columns)
        row[columns] = 1.0 if item.axis is None else omega_row(q[columns], item.axis)
        rows.append(row)
        names.append(item.name)
    values = (np.zeros(0) if not names else
              np.asarray(model.given_values(p), dtype=float).reshape(len(names)))
    bad = [name for name, value in zip(names, values) if not np.isfinite(value)]
    if bad:
        raise SolveError(f"the initial velocity of {bad[0]} is {values[names.index(bad[0])]} "
                         "with the parameters given: give parameters for which "
                         "initial.velocities are finite numbers")
    return np.array(rows).reshape(len(rows), n), values, tuple(names)


def velocity(model: Model, q: Array, t: float, p: Array, redundant: int = 0) -> Array:
    """The consistent initial velocity of least kinetic energy (module docstring);
    ``redundant``: the rows of Φ_q that depend on the others (their multipliers are not
    unique, the velocity is)."""
    jacobian, phi_t = model.phi_q(q, t, p), model.phi_t(q, t, p)
    given, values, names = given_rows(model, q, p)
    _refuse_contradictions(jacobian, -phi_t, given, values, names)
    # keep the given rows the constraints do not already decide (they agree: checked above)
    keep = _independent(jacobian, given)
    rows = np.vstack([jacobian, given[keep]])
    targets = np.concatenate([-phi_t, values[keep]])
    n, m = q.size, rows.shape[0]
    matrix = np.zeros((n + m, n + m))
    matrix[:n, :n] = model.mass(q, p)
    matrix[:n, n:] = rows.T
    matrix[n:, :n] = rows
    solution, _, rank, _ = np.linalg.lstsq(matrix, np.concatenate([np.zeros(n), targets]),
                                           rcond=RANK_TOLERANCE)
    if rank < n + m - redundant:
        raise SolveError(f"no initial velocity at t = {t:g}: the kinetic energy does not "
                         "decide the freedoms the constraints leave open (a body without mass "
                         "or inertia moves freely). Give that body a mass and an inertia, or "
                         "give its velocity in initial.velocities.")
    found: Array = solution[:n]
    return found


def _rank(matrix: Array) -> int:
    if matrix.size == 0:
        return 0
    return int(np.linalg.matrix_rank(matrix, tol=1e-10 * max(1.0, np.abs(matrix).max())))


def _independent(jacobian: Array, given: Array) -> Array:
    """The given rows, in order, that add to the rank of Φ_q and the rows kept before."""
    keep: list[int] = []
    rank = _rank(jacobian)
    for k in range(given.shape[0]):
        trial = _rank(np.vstack([jacobian, given[keep + [k]]]))
        if trial > rank:
            keep.append(k)
            rank = trial
    return np.array(keep, dtype=int)


def _agrees(rows: Array, targets: Array) -> bool:
    solution = np.linalg.lstsq(rows, targets, rcond=None)[0]
    scale = max(1.0, float(np.abs(targets).max(initial=0.0)))
    return bool(np.abs(rows @ solution - targets).max(initial=0.0) <= AGREEMENT * scale)


def _refuse_contradictions(jacobian: Array, phi_rate: Array, given: Array, values: Array,
                           names: tuple[str, ...]) -> None:
    """A SolveError naming the given components that contradict the constraints (each
    alone, or all of them where only their combination does)."""
    everything = (np.vstack([jacobian, given]), np.concatenate([phi_rate, values]))
    if _agrees(*everything):
        return
    alone = [name for k, name in enumerate(names)
             if not _agrees(np.vstack([jacobian, given[k:k + 1]]),
                            np.concatenate([phi_rate, values[k:k + 1]]))]
    named = alone or list(names)
    shown = listed(named)
    raise ContradictoryVelocities(
        f"the initial velocities {shown} contradict the constraints (Phi_q dq = -Phi_t has "
        "no solution with them)", "Remove them from initial.velocities or change their "
        "values: the joints and drivers decide those components.", tuple(named))
