"""Every real assembly of a mechanism at one time point (and given inputs): seeded multi-start
Newton with deflation.

Why deflation: plain multi-start Newton finds the assemblies whose basins of attraction the
starts happen to fall into; the wide basins are found again and again, the narrow ones
(a Stewart platform's many assemblies are mostly narrow) rarely. Deflation (Farrell,
Birkisson and Funke 2015) repels Newton from the assemblies already found: it solves
M(q) Phi(q) = 0 with M(q) = prod_k (1 / |q - q_k|^2 + 1), which has the same roots as Phi
except the known q_k, so a start that led to a known assembly now leads on to a new one. The
deflated Newton step is the plain step scaled by 1 / (1 - grad(log M) . step) (Sherman-
Morrison), so it costs one Phi_q solve like Newton; it is cut to STEP_CAP. From each start,
plain Newton first, then deflated Newton again and again until it finds nothing new, then the
next start is taken. Homotopy continuation would find
every complex root too, but it needs the equations as polynomials, which the kernel (Phi and
Phi_q at points) does not give; deflation needs only what Newton needs.

The starts are seeded (the same every time): those of the damped assembly (runtime.assembly:
q0, the bodies placed along their joints, q0 perturbed, random angles), each after q0 with
random Euler parameters (uniform on the unit sphere). The search stops after STARTS starts
or after PATIENCE starts in a row that found nothing new. Each root of the deflated Newton is
polished by the runtime's Newton (the same test as a run), which gives its condition; two
roots are one assembly when they agree to SAME (angles modulo 2 pi, Euler parameters up to
their sign). Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from symkin.contract.dense_solvers import levenberg_marquardt
from symkin.contract.options import Options
from symkin.contract.status import OK
from symkin.runtime import redundant
from symkin.runtime.assembly import starts as assembly_starts
from symkin.runtime.newton import Newton, newton
from symkin.runtime.protocol import KinematicsKernel

Array = NDArray[np.float64]

STARTS = 160
"""Starts tried at most."""

PATIENCE = 100
"""The search ends after this many starts in a row that found no new assembly."""

DEFLATED_ITERATIONS = 50
"""Deflated Newton iterations per attempt (steps far from a root are not quadratic)."""

STEP_CAP = 0.5
"""The longest deflated Newton step (max-norm: radians, Euler parameters, and lengths in the
unit near the mechanism's size that a scan solves in, runtime.units)."""

FOUND = 1e-8
"""The deflated Newton stops at max |Phi| below this; the runtime's Newton then polishes."""

SAME = 1e-6
"""Two assemblies closer than this (radians; lengths relative to the mechanism's size) are
one."""

SEED = 2026


class Shape:
    """Which coordinates are angles (compared modulo 2 pi) and which four make each body's
    Euler parameters (compared up to their sign: e and -e are one orientation)."""

    def __init__(self, coordinates: tuple[str, ...]) -> None:
        self.angles = np.array([name.endswith(".phi") for name in coordinates])
        bodies = [name[:-3] for name in coordinates if name.endswith(".e0")]
        self.euler = [np.array([coordinates.index(f"{body}.e{k}") for k in range(4)])
                      for body in bodies]
        self.origins = [np.array([coordinates.index(f"{body}.{c}") for c in "xyz"])
                        for body in bodies]
        orientation = self.angles.copy()
        for block in self.euler:
            orientation[block] = True
        self.positions = ~orientation

    def difference(self, a: Array, b: Array) -> Array:
        """a - b with angles wrapped into (-pi, pi] and b's Euler parameters signed as a's."""
        difference = a - b
        difference[self.angles] = np.remainder(difference[self.angles] + math.pi,
                                               2 * math.pi) - math.pi
        for block in self.euler:
            if a[block] @ b[block] < 0:
                difference[block] = a[block] + b[block]
        return difference

    def canonical(self, q: Array) -> Array:
        """q with its angles in (-pi, pi] and each e0 >= 0 (the first non-zero e_k > 0)."""
        q = np.array(q, dtype=float)
        q[self.angles] = math.pi - np.mod(math.pi - q[self.angles], 2 * math.pi)
        for block in self.euler:
            lead = q[block][np.flatnonzero(np.abs(q[block]) > 1e-12)[:1]]
            if lead.size and lead[0] < 0:
                q[block] = -q[block]
        return q

    def same(self, a: Array, b: Array) -> bool:
        """One assembly: every angle and Euler parameter within SAME, every position within
        SAME times the mechanism's size."""
        difference = np.abs(self.difference(a, b))
        size = 1.0 + float(np.abs(a[self.positions]).max(initial=0.0))
        return bool(difference[~self.positions].max(initial=0.0) <= SAME
                    and difference[self.positions].max(initial=0.0) <= SAME * size)


def search(kernel: KinematicsKernel, q0: Array, t0: float, p: Array, options: Options,
           known: list[Array]) -> list[Newton]:
    """The assemblies at t0 (generated functions' parameters p) other than ``known``, each
    the runtime Newton's converged outcome, in the order found (see the module docstring)."""
    shape = Shape(tuple(kernel.coordinates))
    roots = [np.array(q, dtype=float) for q in known]
    found: list[Newton] = []
    idle = 0
    for count, start in enumerate(_starts(kernel, shape, q0, t0, p)):
        if count >= STARTS or idle >= PATIENCE:
            break
        new = _from_start(kernel, shape, start, t0, p, options, roots)
        found.extend(new)
        idle = 0 if new else idle + 1
    return found


def _from_start(kernel: KinematicsKernel, shape: Shape, start: Array, t0: float, p: Array,
                options: Options, roots: list[Array]) -> list[Newton]:
    """Plain Newton from one start first (its own basin may hold an assembly not yet known),
    then deflated Newton from it again after each new assembly, until nothing new."""
    new: list[Newton] = []
    deflate: list[Array] = []
    while True:
        q = _deflated_newton(kernel, shape, start, t0, p, deflate)
        if q is None and not roots:
            # No assembly known yet, and plain Newton fails from here: damp first.
            q = levenberg_marquardt(kernel, start, t0, p, options)[0]
        result = None if q is None else newton(kernel, q, t0, p, options)
        if (result is not None and result.status == OK
                and redundant.holds(kernel, result.q, t0, p, options.target_q)
                and not any(shape.same(result.q, root) for root in roots)):
            roots.append(result.q)
            new.append(result)
        elif deflate is roots:
            return new
        deflate = roots


def _deflated_newton(kernel: KinematicsKernel, shape: Shape, q: Array, t0: float, p: Array,
                     roots: list[Array]) -> Array | None:
    """Newton on M(q) Phi(q) from q: a point with max |Phi| <= FOUND, or None. Each step is
    cut to STEP_CAP: the deflated step grows without bound where 1 - grad(log M) . step
    nears zero, and a long step lands far outside every basin (uncut, almost every deflated
    attempt on a Stewart platform left the mechanism's size)."""
    q = np.array(q, dtype=float)
    size = 10.0 * (1.0 + float(np.abs(q[shape.positions]).max(initial=0.0)))
    with np.errstate(all="ignore"):
        for _ in range(DEFLATED_ITERATIONS):
            phi = np.asarray(kernel.phi(q, t0, p), dtype=float)
            residual = float(np.abs(phi).max(initial=0.0))
            if not math.isfinite(residual):
                return None
            if residual <= FOUND:
                return q
            try:
                step = np.linalg.solve(kernel.phi_q(q, t0, p), -phi)
            except np.linalg.LinAlgError:
                return None
            denominator = 1.0 - float(_log_gradient(shape, q, roots) @ step)
            if not (math.isfinite(denominator) and abs(denominator) > 1e-12):
                return None
            step = step / denominator
            longest = float(np.abs(step).max(initial=0.0))
            q = q + (step if longest <= STEP_CAP else step * (STEP_CAP / longest))
            if not np.abs(q[shape.positions]).max(initial=0.0) <= 100.0 * size:
                return None  # gone far beyond the mechanism: deflation pushed it away
    return None


def _log_gradient(shape: Shape, q: Array, roots: list[Array]) -> Array:
    """grad log M at q, M = prod_k (1 / d_k^2 + 1), d_k = |q - q_k| (shape's distance):
    each root adds -2 (q - q_k) / (d_k^2 (1 + d_k^2))."""
    gradient = np.zeros_like(q)
    for root in roots:
        difference = shape.difference(q, root)
        squared = float(difference @ difference)
        if squared > 0.0:
            gradient -= 2.0 * difference / (squared * (1.0 + squared))
    return gradient


def _starts(kernel: KinematicsKernel, shape: Shape, q0: Array, t0: float, p: Array
            ) -> Iterator[Array]:
    """The damped assembly's starts (q0, the bodies placed along their joints, q0 perturbed,
    random angles with the positions placed); after q0, each spatial body at a random
    orientation and a random origin about q0's (within half the mechanism's size: a body
    turned about a far point lands far from its origin as drawn)."""
    rng = np.random.default_rng(SEED)
    size = max(1.0, float(np.abs(q0[shape.positions]).max(initial=0.0)))
    for index, q in enumerate(assembly_starts(kernel, q0, t0, p, random_angles=STARTS)):
        if index:
            for block, origin in zip(shape.euler, shape.origins):
                e = rng.standard_normal(4)
                q[block] = e / np.linalg.norm(e)
                q[origin] = q0[origin] + 0.5 * size * rng.standard_normal(3)
        yield q
