"""Assembly at t0 from a rough first guess.

Plain Newton from q0 first. When it fails (also when Phi_q is singular at the guess itself,
e.g. every body of a slider chain placed on the slider's axis), Levenberg-Marquardt runs from
several starts, in a fixed order, and the first start that Newton then finishes wins:

1. q0 itself;
2. the bodies placed along their joints: q0's angles kept, the positions solved for in the
   least-squares sense (for fixed angles every pair of the chapter is linear in x and y);
3. q0 perturbed (a fixed seed, so runs repeat);
4. the bodies placed along their joints at random angles (fixed seed).

An outcome counts only where the kernel's senses are positive (:func:`genuine`): Phi = 0
also holds with a spatial revolute's axes reversed or an angle driver half a turn away, which
is no assembly of the mechanism; Newton landing there is one more failed start (and only when
every start lands on such a solution is it returned, as before).

When every start fails, the outcome says how close the best came and which evidence there is:
the same least residual reached from many different starts points at the dimensions (the
links cannot close); different residuals from different starts point at local minima (a
better q0 will do).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.contract.dense_solvers import levenberg_marquardt
from symkin.contract.options import Options
from symkin.contract.status import OK, SINGULAR
from symkin.errors import SymkinWarning
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving.newton import Newton, newton

Array = NDArray[np.float64]

PERTURBED, RANDOM_ANGLES = 3, 8
SEED = 20240


@dataclass
class Assembly:
    """The outcome: ``result`` is Newton's at the assembled (or best) q. When it failed,
    ``residuals`` are the least max |Phi| reached from each start and ``evidence`` is
    "link lengths" or "a better q0"."""

    result: Newton
    starts: int
    residuals: tuple[float, ...] = ()
    evidence: str = ""


def assemble(kernel: KinematicsKernel, q0: Array, t0: float, p: Array,
             options: Options) -> Assembly:
    """Assemble the mechanism at t0 from q0 (see the module docstring)."""
    first = newton(kernel, q0, t0, p, options)
    if first.status == OK and genuine(kernel, first.q, t0, p):
        return Assembly(first, 1)
    spurious = first if first.status == OK else None  # Phi = 0, but a sense is not positive
    best: Newton | None = None
    singular: Newton | None = None  # assembled, but in a singular configuration
    residuals = []
    for count, start in enumerate(starts(kernel, q0, t0, p), start=1):
        q, residual = levenberg_marquardt(kernel, start, t0, p, options)
        polished = newton(kernel, q, t0, p, options)
        polished.iterations += first.iterations
        if polished.status == OK and genuine(kernel, polished.q, t0, p):
            return Assembly(polished, count + 1)
        residuals.append(residual)
        if polished.status == OK:
            spurious = spurious or polished
            continue
        if polished.status == SINGULAR and polished.residual <= options.tol_phi:
            singular = singular or polished
        elif best is None or residual < best.residual:
            best = Newton(q, polished.status, polished.iterations, residual, None)
    if spurious is not None:
        return Assembly(spurious, len(residuals) + 1)
    if singular is not None:
        return Assembly(singular, len(residuals) + 1, tuple(residuals))
    assert best is not None
    return Assembly(best, len(residuals) + 1, tuple(residuals), _evidence(residuals))


def genuine(kernel: KinematicsKernel, q: Array, t: float, p: Array) -> bool:
    """Whether every sense of the kernel (``sense_values``: a spatial revolute's axes'
    cosine, an angle driver's cos(theta - psi)) is positive at q: whether a solution of
    Phi = 0 is an assembly of the mechanism."""
    return not reversed_senses(kernel, q, t, p)


def reversed_senses(kernel: KinematicsKernel, q: Array, t: float, p: Array
                    ) -> tuple[str, ...]:
    """The labels of the kernel's senses that are not positive at q (none: q is genuine).
    The senses hold no lengths, so a kernel in another length unit (runtime.solving.units) answers
    the same."""
    labels = tuple(getattr(kernel, "senses", ()))
    if not labels:
        return ()
    with np.errstate(all="ignore"):
        values = np.asarray(kernel.sense_values(q, t, p),  # type: ignore[attr-defined]
                            dtype=np.float64)
    return tuple(label for label, value in zip(labels, values) if not value > 0.0)


def reversed_rows(kernel: KinematicsKernel, t: Array, q: Array, p: Array) -> NDArray[np.bool_]:
    """(T, NSENSES): where each sense of the kernel is not positive along a run's rows (p:
    the kernel's p[], or (T, NP) one per row). A sense cannot change sign along a continuous
    motion (its value is +1 or -1 wherever Phi = 0 holds), so a row where one is negative is
    a jump to a solution of Phi = 0 that is no assembly of the mechanism: a step too large for
    Newton to follow. One evaluation per row; nothing at all without senses."""
    count = len(getattr(kernel, "senses", ()))
    if not count or not t.size:
        return np.zeros((t.size, count), dtype=bool)
    with np.errstate(all="ignore"):
        batched = getattr(kernel, "sense_rows", None)  # a Kernel's: one crossing into C
        if batched is not None:
            values = np.asarray(batched(q, t, p), dtype=np.float64)
        else:  # a stand-in (the motion's model): one call per row
            rows = np.broadcast_to(p, (t.size, np.shape(p)[-1])) if np.ndim(p) == 1 else p
            values = np.array([kernel.sense_values(  # type: ignore[attr-defined]
                q[k], float(t[k]), rows[k]) for k in range(t.size)], dtype=np.float64)
    return ~(values.reshape(t.size, count) > 0.0)


def flip_message(kernel: KinematicsKernel, t: Array, wrong: NDArray[np.bool_]) -> str:
    """One sentence locating the first row where a sense flipped (reversed_rows): its time
    and the joints or drivers, and how many rows in all."""
    labels = tuple(getattr(kernel, "senses", ()))
    rows = np.flatnonzero(wrong.any(axis=1))
    k = int(rows[0])
    named = [label for label, bad in zip(labels, wrong[k]) if bad]
    shown = ", ".join(named[:10]) + (f" and {len(named) - 10} more" if len(named) > 10 else "")
    return (f"the motion left the mechanism's assembly at row {k} (t = {float(t[k]):.10g}): "
            f"{shown} reversed (a revolute's axis, or an angle half a turn away; "
            f"{rows.size} row(s) in all, flagged): the step before it was too large for Newton "
            "to follow; use a smaller dt there")


def flag_flips(kernel: KinematicsKernel, trajectory: Any, p: Array) -> None:
    """Flag the rows of a solved run where a sense is not positive (reversed_rows), with a
    SymkinWarning that locates the first; nothing when every row is as meant."""
    wrong = reversed_rows(kernel, trajectory.t, trajectory.q, p)
    if wrong.any():
        trajectory.flagged[wrong.any(axis=1)] = True
        warnings.warn(flip_message(kernel, trajectory.t, wrong), SymkinWarning, stacklevel=3)


def _evidence(residuals: list[float]) -> str:
    """The same least residual from many starts: the dimensions; else local minima."""
    least = min(residuals)
    alike = sum(1 for r in residuals if r <= 1.05 * least + 1e-9)
    return "link lengths" if alike >= max(2, len(residuals) // 3) else "a better q0"


def starts(kernel: KinematicsKernel, q0: Array, t0: float, p: Array,
           random_angles: int = RANDOM_ANGLES) -> Iterator[Array]:
    """The starts of the damped assembly, in order (the module docstring); random_angles sets
    of random angles at the end (a fixed seed: the same starts every time)."""
    rng = np.random.default_rng(SEED)
    angles = np.array([name.endswith(".phi") for name in kernel.coordinates])
    yield np.array(q0, dtype=float)
    yield placed(kernel, q0, angles, t0, p)
    scale = np.where(angles, 0.5, 0.2 * max(1.0, float(np.abs(q0).max(initial=0.0))))
    for _ in range(PERTURBED):
        yield q0 + scale * rng.standard_normal(q0.size)
    for _ in range(random_angles):
        q = np.array(q0, dtype=float)
        q[angles] = rng.uniform(-math.pi, math.pi, int(angles.sum()))
        yield placed(kernel, q, angles, t0, p)


def placed(kernel: KinematicsKernel, q: Array, angles: NDArray[np.bool_], t0: float,
            p: Array) -> Array:
    """q with its angles kept and its positions solved in the least-squares sense."""
    q = np.array(q, dtype=float)
    q[~angles] = 0.0
    phi = kernel.phi(q, t0, p)
    jacobian = kernel.phi_q(q, t0, p)[:, ~angles]
    if not (np.all(np.isfinite(phi)) and np.all(np.isfinite(jacobian))):
        return q
    q[~angles] = np.linalg.lstsq(jacobian, -phi, rcond=None)[0]
    return q
