"""An embedded Runge-Kutta pair with error control and projection, for the index-1 equations
of motion (runtime.dynamics.equations).

Why this formulation: the index-1 system gives q̈ from (q, q̇) with Φ_q q̈ = Γ, so an
explicit Runge-Kutta method integrates it as an ODE of y = (q, q̇) — simple, no Jacobian of
the forces, the same code for every mechanism. Alone it drifts: Φ and Φ_q q̇ + Φ_t grow
with the integration error. So after every accepted step q is projected back onto Φ(q, t) =
0 (minimum-norm Newton steps, the kinematic solve's tolerance) and q̇ onto Φ_q q̇ = -Φ_t
(one minimum-norm correction, exact for the linear velocity constraint). Both corrections
are of the size of the local error, so they keep the method's order; every output row then
satisfies the constraints at position, velocity and (solved for there) acceleration level
to the Newton tolerance, with no drift over long runs.

The pair is Dormand-Prince 5(4): 7 stages, the 5th-order solution is propagated, the
difference to the 4th-order one estimates the error, which a step must keep below
atol + rtol |y| (root mean square over the coordinates and velocities). Steps end exactly
on the output times. The work W of the non-conservative forces and drivers is integrated as
one more component with the same stages (runtime.dynamics.equations: its power).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from symkin.limits import listed_groups
from symkin.runtime.dynamics import passages
from symkin.runtime.dynamics.equations import TRUNCATION, Singular, accelerations
from symkin.runtime.dynamics.model import Model

Array = NDArray[np.float64]

# Dormand & Prince (1980), RK5(4)7M: the nodes, the stages' weights, the 5th-order weights
# and the difference of the 4th-order ones from them.
C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
A = [
    [],
    [1 / 5],
    [3 / 40, 9 / 40],
    [44 / 45, -56 / 15, 32 / 9],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
    [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
]
B = np.array([35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0.0])
E = B - np.array([5179 / 57600, 0.0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100,
                  1 / 40])
ORDER = 5
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 5.0
MIN_STEP_FRACTION = 1e-12  # of the interval: below it the step is refused (a stiff lock-up)
# Steps tried between two output rows before the run stops: a bound on the work one row may
# take (a stiff spring makes an explicit method take steps of 1/omega; unbounded, a run of a
# spring of 1e9 N/m went on for minutes with no word). A finer output grid allows more.
MAX_STEPS_PER_ROW = 20_000
PROJECTION_ITERATIONS = 10
# Below this sigma_min / sigma_max of Φ_q at a step's start, its stages take the rank-revealing
# solve (runtime.dynamics.equations.revealed), which costs about three LU solves.
NEAR = 1e-3


class StepFailure(Exception):
    """The integration cannot go on: ``reason`` and the time reached."""

    def __init__(self, reason: str, t: float, kind: str = "singular") -> None:
        super().__init__(reason)
        self.reason = reason
        self.t = t
        self.kind = kind  # SolveFailure.reason: "singular", or "too many substeps" (the bound)


@dataclass
class State:
    """q, q̇ and the work done since t0, at time t."""

    t: float
    q: Array
    dq: Array
    work: float


@dataclass
class Stepper:
    """Integrates one model with parameter values p; ``step`` is the step size it will try
    next (kept between output rows)."""

    model: Model
    p: Array
    rtol: float
    atol: float
    position_tolerance: float
    stop_at_singular: bool = False
    """Stop at the first singular configuration passed (StepFailure) instead of going on."""
    step: float = 0.0
    singular: str = ""
    """Why the last rejected stage failed, when the equations of motion were singular."""
    trail: list[passages.Watched] = field(default_factory=list)
    """The last three accepted states (runtime.dynamics.passages)."""
    found: list[passages.Passage] = field(default_factory=list)
    """The singular configurations passed so far."""

    def _derivative(self, t: float, y: Array) -> Array:
        n = len(self.model.coordinates)
        near = bool(self.trail) and (self.trail[-1].ratio < NEAR or self.trail[-1].structural > 0)
        found = accelerations(self.model, y[:n], y[n:2 * n], t, self.p, revealing=near)
        return np.concatenate([y[n:2 * n], found.d2q, [found.power]])

    def watch(self, t: float, q: Array, dq: Array, jacobian: Array | None = None) -> None:
        """Note an accepted state (``jacobian``: Φ_q there, where known); a singular
        configuration passed just before it is recorded, or with ``stop_at_singular`` stops
        the run there (StepFailure)."""
        self.trail = [*self.trail[-2:],
                      passages.watched(self.model, t, q, dq, self.p, jacobian)]
        if len(self.trail) < 3:
            return
        passage = passages.search(self.model, self.p, (self.trail[0], self.trail[1],
                                                       self.trail[2]))
        if passage is None:
            return
        self.found.append(passage)
        if self.stop_at_singular:
            raise StepFailure(f"a singular configuration is reached at t = {passage.t:.10g} "
                              f"(Phi_q loses rank {passage.rank_loss}) and --stop-at-singular "
                              "was given", passage.t, "singular")

    def advance(self, state: State, t_end: float, interrupted: Callable[[], None]) -> State:
        """The state at ``t_end``, by accepted steps each followed by the projection."""
        n = state.q.size
        y = np.concatenate([state.q, state.dq, [state.work]])
        t = state.t
        if self.step <= 0.0:
            self.step = self._first_step(t, y, t_end)
        tried = 0
        while t < t_end:
            interrupted()
            tried += 1
            if tried > MAX_STEPS_PER_ROW:
                raise StepFailure(
                    f"{MAX_STEPS_PER_ROW} steps did not reach the next output time "
                    f"{t_end:.6g} (the step was {self.step:.3g} s): the motion is too fast or "
                    "stiff for this explicit integrator (a stiff spring, a large force?); a "
                    "finer output grid (--dt) allows more steps", t, "too many substeps")
            h = min(self.step, t_end - t)
            if h <= MIN_STEP_FRACTION * max(1.0, abs(t_end)):
                raise StepFailure(self.singular or self._stuck(t, y[:n]), t)
            y_new, error = self._try(t, y, h, n)
            factor = MAX_FACTOR if error == 0 else SAFETY * error ** (-1 / ORDER)
            if error <= 1.0:
                t = t_end if h == t_end - t else t + h
                y, jacobian = self._project(t, y_new, n)
                self.watch(t, y[:n], y[n:2 * n], jacobian)
                proposal = h * min(MAX_FACTOR, max(MIN_FACTOR, factor))
                # a step cut short to end on the output time says little about the next one
                self.step = max(proposal, self.step) if h < self.step else proposal
            else:
                self.step = h * max(MIN_FACTOR, factor)
        return State(t, y[:n], y[n:2 * n], float(y[2 * n]))

    def _stuck(self, t: float, q: Array) -> str:
        """Why the steps shrank to nothing at (t, q): a lock-up where Phi_q is singular
        there (the motion cannot go on: a limit position of a driver), else stiffness."""
        lost = passages.lost_rank(self.model, q, t, self.p)
        if lost is None:
            return "the step size fell below its minimum: the motion is too fast or stiff to follow"
        rank, groups = lost
        return (f"a lock-up: Phi_q loses rank {rank} there (dependent rows: "
                f"{listed_groups(groups)}) and the motion "
                "cannot continue through it (a limit position of a driver, or a mechanism "
                "that jams); the steps shrank to nothing")

    def _try(self, t: float, y: Array, h: float, n: int) -> tuple[Array, float]:
        """One Dormand-Prince step: the 5th-order result and its scaled error norm."""
        stages = np.zeros((7, y.size))
        for i in range(7):
            # the state each stage is evaluated at; a non-finite one is a failure of its own
            y_i = y + h * (np.asarray(A[i]) @ stages[:i]) if i else y
            try:
                stages[i] = self._derivative(t + C[i] * h, y_i)
            except Singular as why:
                # rejected like a large error: a smaller step may pass by; if none does, the
                # singular configuration is the reason given
                self.singular = (f"the equations of motion are singular near t = "
                                 f"{t + C[i] * h:.10g}: {why or 'no unique acceleration'} (a "
                                 "lock-up, a limit position or a free body without mass)")
                return y, math.inf
        y_new = y + h * (B @ stages)
        estimate = h * (E @ stages)
        if not np.all(np.isfinite(y_new)):
            return y_new, math.inf
        scale = self.atol + self.rtol * np.maximum(np.abs(y[:2 * n]), np.abs(y_new[:2 * n]))
        error = float(np.sqrt(np.mean((estimate[:2 * n] / scale) ** 2)))
        return y_new, error

    def _project(self, t: float, y: Array, n: int) -> tuple[Array, Array]:
        """q onto Φ(q, t) = 0, then q̇ onto Φ_q q̇ = -Φ_t (module docstring); the projected
        state and Φ_q at its q."""
        q, dq = y[:n].copy(), y[n:2 * n].copy()
        model, p = self.model, self.p
        for _ in range(PROJECTION_ITERATIONS):
            residual = model.phi(q, t, p)
            if np.max(np.abs(residual), initial=0.0) <= self.position_tolerance:
                break
            # Φ_q's directions below TRUNCATION are left out (equations.TRUNCATION): near a
            # change point a residual along one moves q by residual / sigma_min; once the
            # correction is below the tolerance, what is left is rounding
            correction = np.linalg.lstsq(model.phi_q(q, t, p), residual, rcond=TRUNCATION)[0]
            q -= correction
            if np.max(np.abs(correction), initial=0.0) <= self.position_tolerance:
                break
        else:
            raise StepFailure("the projection onto the constraints did not converge: the "
                              "configuration is singular there", t)
        jacobian = model.phi_q(q, t, p)
        dq -= np.linalg.lstsq(jacobian, jacobian @ dq + model.phi_t(q, t, p),
                              rcond=TRUNCATION)[0]
        return np.concatenate([q, dq, y[2 * n:]]), jacobian

    def _first_step(self, t: float, y: Array, t_end: float) -> float:
        """Hairer and Wanner's starting step from the sizes of y and its derivative."""
        scale = self.atol + self.rtol * np.abs(y[:-1])
        d0 = float(np.sqrt(np.mean((y[:-1] / scale) ** 2)))
        d1 = float(np.sqrt(np.mean((self._derivative(t, y)[:-1] / scale) ** 2)))
        guess = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        return min(guess, t_end - t) if t_end > t else guess
