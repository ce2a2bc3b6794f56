"""``symkin.solve`` of a mechanism its forces move: the integration over a time grid and the
Trajectory of it, with efforts, reactions and the energy balance.

Every output row is the integrator's state projected onto the constraints
(runtime.dynamics.integrator), its accelerations and multipliers solved from the equations
of motion there, so Φ = 0, Φ_q q̇ = -Φ_t and Φ_q q̈ = Γ hold at each row to the Newton
tolerance; ``constraint_residual`` reports max |Φ| of each row rather than hiding it.
Rows whose augmented matrix is ill-conditioned are flagged (``cond`` holds its condition
number); where the equations of motion are singular the run stops with the rows before it
(SolveFailure, reason "singular"). Ctrl-C stops it likewise (SolveInterrupted).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.loads import reaction_parts
from symkin.runtime.arguments import first_guess, parameter_values, time_points
from symkin.runtime.dynamics import equations, initial
from symkin.runtime.dynamics.integrator import State, StepFailure, Stepper
from symkin.runtime.dynamics.model import Model, MotionKernel
from symkin.runtime.dynamics.passages import Passage
from symkin.runtime.loads.forces import Forces
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.solving import failures
from symkin.runtime.solving.assembly import flag_flips, reversed_senses
from symkin.runtime.solving.run_outcome import (
    SolveFailure,
    SolveInterrupted,
    attach_forces,
    rows_kept,
)

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]

# |Φ| every output row is projected to: the kinematic solve's position target.
POSITION_TOLERANCE = 1e-11
# The energy arrays by their NPZ names, in the order of _Rows.energy (their CSV columns:
# contract.columns.ENERGY_COLUMNS).
ENERGY = ("kinetic_energy", "potential_energy", "work_nonconservative")


@dataclass
class _Rows:
    """The output arrays, filled row by row."""

    t: Array
    q: Array
    dq: Array
    d2q: Array
    lam: Array
    energy: Array  # (T, 3): kinetic, potential, work
    residual: Array
    cond: Array
    redundant: int  # rows of Φ_q that depend on the others (equations.deficiency at t0)
    done: int = 0


def solve(kernel: MotionKernel, t: ArrayLike | None = None, q0: ArrayLike | None = None,
          params: Mapping[str, float] | ArrayLike | None = None, *,
          progress: Progress | None = None, stop_at_singular: bool = False) -> Trajectory:
    """Integrate the motion over ``t`` (default: the file's grid) from the assembled q0.

    Raises:
        SolveFailure with the rows before it where the motion cannot be followed;
        SolveInterrupted on Ctrl-C; SolveError for bad arguments or initial velocities that
        contradict the constraints (runtime.dynamics.initial).
    """
    # a load's 1/(t - 0.5) at t = 0.5 is inf in a generated NumPy kernel, as in C: the row
    # is then flagged (run_outcome.flag_not_finite) or the motion stops, never a warning
    with np.errstate(all="ignore"):
        return _solve(kernel, t, q0, params, progress, stop_at_singular)


def _solve(kernel: MotionKernel, t: ArrayLike | None, q0: ArrayLike | None,
           params: Mapping[str, float] | ArrayLike | None, progress: Progress | None,
           stop_at_singular: bool) -> Trajectory:
    model = kernel.model
    # the shared argument checks read only a kernel's grid, parameters, q0 and coordinates
    checked: Any = kernel
    times = time_points(checked, t)
    p = parameter_values(checked, params)
    q = initial.assemble(model, first_guess(checked, q0), float(times[0]), p,
                         POSITION_TOLERANCE)
    redundant = equations.deficiency(model, q, float(times[0]), p)
    state = State(float(times[0]), q,
                  initial.velocity(model, q, float(times[0]), p, redundant), 0.0)
    rows = _allocate(times, q.size, len(model.rows), redundant)
    _refuse_reversed(model, rows, q, p)
    stepper = Stepper(model, p, model.rtol, model.atol, POSITION_TOLERANCE,
                      stop_at_singular=stop_at_singular)
    try:
        stepper.watch(state.t, state.q, state.dq)
        _record(model, rows, state, p)
        for k in range(1, times.size):
            state = stepper.advance(state, float(times[k]), _no_interrupt)
            _record(model, rows, state, p)
            if stop_at_singular and rows.cond[k] > equations.FLAG_CONDITION:
                raise StepFailure("the equations of motion are ill-conditioned "
                                  f"(condition {rows.cond[k]:.3g}) and --stop-at-singular "
                                  "was given", float(times[k]))
            if progress is not None:
                progress(k + 1, times.size)
    except KeyboardInterrupt:
        at = float(times[min(rows.done, times.size - 1)])  # Ctrl-C after the last row too
        raise SolveInterrupted(_trajectory(model, rows, p), at) from None
    except (StepFailure, equations.Singular) as stop:
        at = getattr(stop, "t", float(times[rows.done]))
        # a passage is seen a step after it: rows past it are not the run's to keep
        rows.done = int(np.searchsorted(rows.t[:rows.done], at, side="left"))
        reason = getattr(stop, "reason", "the equations of motion are singular")
        kept = (f"The rows up to t = {times[rows.done - 1]:.6g} are kept." if rows.done
                else "No row was solved.")
        raise SolveFailure(f"the motion stops at t = {at:.10g}: {reason}. {kept}",
                           _trajectory(model, rows, p, stepper.found), at, math.nan, 0,
                           reason=getattr(stop, "kind", "singular")) from None
    trajectory = _trajectory(model, rows, p, stepper.found)
    with rows_kept(trajectory, "the solved rows were checked"):
        flag_flips(model, trajectory, p)  # type: ignore[arg-type]  # a jump off the assembly
    return trajectory


def _refuse_reversed(model: Model, rows: _Rows, q: Array, p: Array) -> None:
    """SolveFailure (reason "no assembly", no row) when the assembled q solves Φ = 0 with a
    spatial revolute's axes reversed or an angle driver half a turn away, as a kinematic run
    refuses to start there (runtime.solving.run_outcome.refuse_reversed)."""
    t0 = float(rows.t[0])
    wrong = reversed_senses(model, q, t0, p)  # type: ignore[arg-type]
    if not wrong:
        return
    # no row is kept (rows.done is 0): an empty Trajectory
    raise SolveFailure(failures.explain_reversed(wrong, t0), _trajectory(model, rows, p), t0,
                       math.nan, 0, wrong, "no assembly")


def _no_interrupt() -> None:
    """The integrator's check between steps (Ctrl-C arrives as KeyboardInterrupt)."""


def _allocate(times: Array, n: int, m: int, redundant: int) -> _Rows:
    size = times.size
    return _Rows(times, np.full((size, n), np.nan), np.full((size, n), np.nan),
                 np.full((size, n), np.nan), np.full((size, m), np.nan),
                 np.full((size, 3), np.nan), np.full(size, np.nan), np.full(size, np.nan),
                 redundant)


def _record(model: Model, rows: _Rows, state: State, p: Array) -> None:
    """One output row: the state, its accelerations and multipliers, energies, residual."""
    k = rows.done
    # the rank-revealing solve at every row: the same numbers as LU away from a singular
    # configuration, and the determinate q̈ near one (runtime.dynamics.equations.revealed)
    found = equations.accelerations(model, state.q, state.dq, state.t, p, revealing=True)
    rows.q[k], rows.dq[k], rows.d2q[k], rows.lam[k] = state.q, state.dq, found.d2q, found.lam
    kinetic = 0.5 * state.dq @ model.mass(state.q, p) @ state.dq
    rows.energy[k] = (kinetic, float(model.potential(state.q, state.t, p)), state.work)
    rows.residual[k] = float(np.max(np.abs(model.phi(state.q, state.t, p)), initial=0.0))
    rows.cond[k] = equations.condition(model, state.q, state.dq, state.t, p, rows.redundant)
    rows.done = k + 1


def _trajectory(model: Model, rows: _Rows, p: Array,
                passed: Sequence[Passage] = ()) -> Trajectory:
    """The Trajectory of the rows done, with forces and the energy outputs; the first row
    at or after each singular configuration ``passed`` is flagged, as kinematics flags the
    points around one (the motion through it is determinate: only the flag tells)."""
    done = rows.done
    t, q, dq, d2q = (a[:done].copy() for a in (rows.t, rows.q, rows.dq, rows.d2q))
    cond = rows.cond[:done].copy()
    flagged = ~(cond <= equations.FLAG_CONDITION)
    singular = tuple((s.t, s.rank_loss, s.groups) for s in passed
                     if done and s.t <= t[-1])
    for s in singular:
        flagged[min(int(np.searchsorted(t, s[0], side="left")), done - 1)] = True
    trajectory = Trajectory.solved(t, q, dq, d2q, model.coordinates, model.points,
                                   model.point_vectors, p, 0, flagged, cond, singular,
                                   space=model.space)
    outputs = [(name, rows.energy[:done, j].copy()) for j, name in enumerate(ENERGY)]
    outputs.append(("constraint_residual", rows.residual[:done].copy()))
    trajectory.__dict__["outputs"] = tuple(outputs)
    # an infinite or undefined load is flagged, never silent; a Ctrl-C keeps the rows
    attach_forces(trajectory, lambda: _forces(model, t, q, rows.lam[:done], p, rows.redundant))
    return trajectory


def _forces(model: Model, t: Array, q: Array, lam: Array, p: Array,
            redundant: int) -> Forces | None:
    """Efforts and reactions of each row from its multipliers (as the forces section's);
    with redundant rows, those of the minimum-norm λ, and which are determinate."""
    if getattr(model, "removed", ()) or t.size == 0:
        return None  # rows removed as redundant (the split is not unique), or no row solved
    loads = np.array([model.loads(q[k], lam[k], t[k], p) for k in range(t.size)])
    loads = loads.reshape(t.size, -1)
    n_efforts, n_joints = len(model.driver_names), len(model.joint_names)
    parts = reaction_parts(model.space)
    determinate = _determinate(model, t, q, p, redundant) if redundant else None
    return Forces(lam.copy(), loads[:, :n_efforts],
                  loads[:, n_efforts:].reshape(t.size, n_joints, len(parts)),
                  model.driver_names, model.joint_names, parts, determinate)


# A load is determinate where the multipliers' free directions move it by less than this
# share of the largest such effect (rounding), as in runtime.loads.indeterminate.
DETERMINATE = 1e-8


def _determinate(model: Model, t: Array, q: Array, p: Array, redundant: int) -> NDArray[
        np.bool_]:
    """(NLOADS,) True for a load that no self-balanced set of multipliers (the null space
    of Φ_qᵀ) changes, at every row. Loads are linear in λ, so their matrix is read off
    the unit multipliers."""
    fixed: NDArray[np.bool_] | None = None
    for k in range(t.size):
        jacobian = model.phi_q(q[k], t[k], p)
        free = np.linalg.svd(jacobian)[0][:, jacobian.shape[0] - redundant:]
        loads = np.column_stack([model.loads(q[k], unit, t[k], p)
                                 for unit in np.eye(jacobian.shape[0])])
        moved = np.abs(loads @ free).max(axis=1)
        here = moved <= DETERMINATE * max(1.0, float(np.abs(loads).max()))
        fixed = here if fixed is None else fixed & here
    return fixed if fixed is not None else np.zeros(0, dtype=bool)

