"""Random states (q, dq, t) and parameter values at which derivations are compared."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from symkin.symbolic.derivation import System

# ----- sampling -------------------------------------------------------------------------------

@dataclass(frozen=True)
class State:
    """One sample point: coordinates, velocities, time and parameter values."""

    q: np.ndarray
    dq: np.ndarray
    t: float
    p: np.ndarray


def length_scale(system: System) -> float:
    """A typical size of the mechanism: the median non-zero nominal parameter, else 1."""
    sizes = [abs(v) for v in system.p_values if v != 0 and math.isfinite(v)]
    return float(np.median(sizes)) if sizes else 1.0


def sample_states(system: System, samples: int, seed: int, spread: float) -> list[State]:
    """Random states, and parameters within ``spread`` of the nominal design.

    A non-zero parameter p becomes p (1 + spread u); a zero one becomes spread L u, with u
    uniform in [-1, 1] and L the mechanism's length scale — so zero dimensions are varied too.
    Positions are uniform in [-2L, 2L], angles in [-pi, pi], rates in [-L, L] and [-2, 2],
    t in the file's time grid. The states need not satisfy Phi = 0: every function is compared
    as an identity in q, dq, t and p.
    """
    rng = np.random.default_rng(seed)
    size = len(system.q)
    scale = length_scale(system)
    angle = np.array([name.endswith(".phi") for name in system.coordinates])
    nominal = np.array(system.p_values, dtype=float)
    t0, t1, _ = system.time_grid
    states = []
    for _ in range(samples):
        q = np.where(angle, rng.uniform(-np.pi, np.pi, size), rng.uniform(-2, 2, size) * scale)
        dq = np.where(angle, rng.uniform(-2, 2, size), rng.uniform(-1, 1, size) * scale)
        u = rng.uniform(-1, 1, len(nominal))
        p = np.where(nominal != 0, nominal * (1 + spread * u), spread * scale * u)
        states.append(State(q, dq, float(rng.uniform(t0, t1)), p))
    return states
