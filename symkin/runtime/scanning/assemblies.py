"""Every real assembly of a mechanism at one time point (and given inputs): deterministic
multi-start Newton with deflation.

Why deflation: plain multi-start Newton finds the assemblies whose basins of attraction the
starts happen to fall into; the wide basins are found again and again, the narrow ones
(a Stewart platform's many assemblies are mostly narrow) rarely. Deflation (Farrell,
Birkisson and Funke 2015) repels Newton from the assemblies already found: it solves
M(q) Phi(q) = 0 with M(q) = prod_k (1 / |q - q_k|^2 + 1), which has the same roots as Phi
except the known q_k, so a start that led to a known assembly now leads on to a new one. The
deflated Newton step is the plain step scaled by 1 / (1 - grad(log M) . step) (Sherman-
Morrison), so it costs one Phi_q solve like Newton; it is cut to STEP_CAP, then halved until
|M Phi| decreases (a line search; a start whose step cannot lower it is given up). From each
start, plain Newton first, then deflated Newton again and again until it finds nothing new,
then the next start is taken. Homotopy continuation would find every complex root too, but it
needs the equations as polynomials, which the kernel (Phi and Phi_q at points) does not give;
deflation needs only what Newton needs.

The starts decide which basins are reached at all. After q0 and the damped assembly's first
starts (runtime.solving.assembly), they are the points of a low-discrepancy sequence (Roberts' R_d):
each planar angle spread over [-pi, pi) with the positions placed along the joints; each
spatial body at an orientation spread uniformly over SO(3) (Shoemake's map from the unit cube
to unit quaternions) and its origin spread over a box about q0's origin wide enough to hold
q0's mirror images (REACH), then moved by a few Gauss-Newton steps over the positions alone.
(Random Euler parameters with origins drawn near q0's, as before, missed the mirror image of
the home pose of examples/stewart_fk.yaml below its base plane.) No symmetry of the mechanism
is assumed. The search runs in batches of BATCH starts and ends after PATIENCE batches in a
row that found nothing new, or after STARTS starts. The sequence has no seed: a scan repeats
exactly. Each root of the deflated Newton is polished by the runtime's Newton (the same test
as a run), which gives its condition; a root where a sense of the kernel is not positive (a
spatial revolute's axes anti-parallel, an angle driver at theta + pi:
runtime.solving.assembly.genuine) is no assembly and not counted; two roots are one assembly when
they agree to SAME (angles modulo 2 pi, Euler parameters up to their sign). Imports NumPy only: part
of the runtime.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from symkin.contract.dense_solvers import levenberg_marquardt
from symkin.contract.options import Options
from symkin.contract.status import OK
from symkin.runtime.outputs import redundant
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.solving.assembly import genuine, placed
from symkin.runtime.solving.assembly import starts as assembly_starts
from symkin.runtime.solving.newton import Newton, newton

Array = NDArray[np.float64]

STARTS = 1200
"""Starts tried at most."""

BATCH = 40
"""Starts per batch: the search ends after PATIENCE batches in a row found nothing new."""

PATIENCE = 3
"""Batches in a row without a new assembly that end the search."""

PLACING = 5
"""Gauss-Newton steps over the positions alone that place a spatial start."""

HALVINGS = 8
"""Halvings of a deflated Newton step tried before the line search takes the last."""

REACH = 2.0
"""Spatial starts place a body's origin within REACH times the mechanism's size of q0's:
enough to hold q0's mirror image through any plane through the global origin (a Stewart
platform's assemblies come in mirror pairs through its base plane)."""

DEFLATED_ITERATIONS = 50
"""Deflated Newton iterations per attempt (steps far from a root are not quadratic)."""

STEP_CAP = 0.5
"""The longest deflated Newton step (max-norm: radians, Euler parameters, and lengths in the
unit near the mechanism's size that a scan solves in, runtime.solving.units)."""

FOUND = 1e-8
"""The deflated Newton stops at max |Phi| below this; the runtime's Newton then polishes."""

SAME = 1e-6
"""Two assemblies closer than this (radians; lengths relative to the mechanism's size) are
one."""



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

    def differences(self, q: Array, roots: list[Array]) -> Array:
        """difference(q, root) for every root at once, one row each (no roots: no rows)."""
        if not roots:
            return np.zeros((0, q.size))
        others = np.array(roots)
        differences = q - others
        differences[:, self.angles] = np.remainder(differences[:, self.angles] + math.pi,
                                                   2 * math.pi) - math.pi
        for block in self.euler:
            flip = others[:, block] @ q[block] < 0
            differences[np.ix_(flip, block)] = q[block] + others[np.ix_(flip, block)]
        return differences

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
           known: list[Array], turns: Array | None = None) -> list[Newton]:
    """The assemblies at t0 (generated functions' parameters p) other than ``known``, each
    the runtime Newton's converged outcome, in the order found (see the module docstring).
    ``turns``: a configuration whose angles say about which turn the starts' angles spread
    (an assembly found already, its driven angles at the inputs' values; default q0)."""
    shape = Shape(tuple(kernel.coordinates))
    roots = [np.array(q, dtype=float) for q in known]
    found: list[Newton] = []
    idle = 0
    batch: list[Newton] = []
    centre = np.array(q0 if turns is None else turns, dtype=float)
    for count, start in enumerate(_starts(kernel, shape, q0, t0, p, centre), start=1):
        batch.extend(_from_start(kernel, shape, start, t0, p, options, roots))
        if count % BATCH == 0:
            found.extend(batch)
            idle = 0 if batch else idle + 1
            batch = []
            if idle >= PATIENCE or count >= STARTS:
                break
    return found + batch


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
                and genuine(kernel, result.q, t0, p)
                and not any(shape.same(result.q, root) for root in roots)):
            roots.append(result.q)
            new.append(result)
        elif deflate is roots:
            return new
        deflate = roots


def _deflated_newton(kernel: KinematicsKernel, shape: Shape, q: Array, t0: float, p: Array,
                     roots: list[Array]) -> Array | None:
    """Newton on M(q) Phi(q) from q, with a backtracking line search on |M Phi|: a point with
    max |Phi| <= FOUND, or None. The step is first cut to STEP_CAP (the deflated step grows
    without bound where 1 - grad(log M) . step nears zero), then halved until |M Phi|
    decreases: a full step from far away overshoots into another basin or out of the
    mechanism, which made the narrow basins the rarest finds."""
    q = np.array(q, dtype=float)
    size = 10.0 * (1.0 + float(np.abs(q[shape.positions]).max(initial=0.0)))
    with np.errstate(all="ignore"):
        phi = np.asarray(kernel.phi(q, t0, p), dtype=float)
        merit = _merit(shape, q, phi, roots)
        for _ in range(DEFLATED_ITERATIONS):
            if not math.isfinite(merit):
                return None
            if float(np.abs(phi).max(initial=0.0)) <= FOUND:
                return q
            step = _deflated_step(kernel, shape, q, phi, t0, p, roots)
            if step is None:
                return None
            lowered = _line_search(kernel, shape, q, step, merit, t0, p, roots)
            if lowered is None:
                return None  # no step along the Newton direction lowers |M Phi|: stalled
            q, phi, merit = lowered
            if not np.abs(q[shape.positions]).max(initial=0.0) <= 100.0 * size:
                return None  # gone far beyond the mechanism: deflation pushed it away
    return None


def _deflated_step(kernel: KinematicsKernel, shape: Shape, q: Array, phi: Array, t0: float,
                   p: Array, roots: list[Array]) -> Array | None:
    """The Newton step of M Phi (Sherman-Morrison on the plain step), cut to STEP_CAP."""
    try:
        step: Array = np.linalg.solve(np.asarray(kernel.phi_q(q, t0, p), dtype=float), -phi)
    except np.linalg.LinAlgError:
        return None
    denominator = 1.0 - float(_log_gradient(shape, q, roots) @ step)
    if not (math.isfinite(denominator) and abs(denominator) > 1e-12):
        return None
    step = step / denominator
    longest = float(np.abs(step).max(initial=0.0))
    return step if longest <= STEP_CAP else step * (STEP_CAP / longest)


def _line_search(kernel: KinematicsKernel, shape: Shape, q: Array, step: Array, merit: float,
                 t0: float, p: Array, roots: list[Array]
                 ) -> tuple[Array, Array, float] | None:
    """q, Phi and |M Phi| after the first of step, step / 2, ... (HALVINGS times) that lowers
    |M Phi|; None when none does."""
    for _ in range(HALVINGS + 1):
        trial = q + step
        phi = np.asarray(kernel.phi(trial, t0, p), dtype=float)
        trial_merit = _merit(shape, trial, phi, roots)
        if trial_merit < merit:
            return trial, phi, trial_merit
        step = 0.5 * step
    return None


def _merit(shape: Shape, q: Array, phi: Array, roots: list[Array]) -> float:
    """|M(q) Phi(q)|, M = prod_k (1 / d_k^2 + 1) (shape's distance d_k to root k)."""
    squared = np.maximum(np.sum(shape.differences(q, roots)**2, axis=1), 1e-300)
    return float(np.prod(1.0 / squared + 1.0)) * float(np.linalg.norm(phi))


def _log_gradient(shape: Shape, q: Array, roots: list[Array]) -> Array:
    """grad log M at q, M = prod_k (1 / d_k^2 + 1), d_k = |q - q_k| (shape's distance):
    each root adds -2 (q - q_k) / (d_k^2 (1 + d_k^2))."""
    differences = shape.differences(q, roots)
    squared = np.sum(differences**2, axis=1)
    weights = np.divide(-2.0, squared * (1.0 + squared), out=np.zeros_like(squared),
                        where=squared > 0.0)
    gradient: Array = weights @ differences
    return gradient


def _starts(kernel: KinematicsKernel, shape: Shape, q0: Array, t0: float, p: Array,
            centre: Array) -> Iterator[Array]:
    """q0 and the damped assembly's other first starts (runtime.solving.assembly: the bodies placed
    along their joints, q0 perturbed), then the points of a low-discrepancy sequence
    (_sequence): each planar angle uniform over one turn, [-pi, pi) shifted by the whole
    turns of its value in ``centre`` (an angle driven to 30 rad, an encoder's count of turns,
    has its assemblies there: Newton from [-pi, pi) had to travel five turns in steps of
    STEP_CAP and found none), with the positions placed along the joints; each spatial body at
    a uniformly distributed orientation (Shoemake) with its origin in the box of half-width
    REACH times the mechanism's size about q0's origin."""
    first = assembly_starts(kernel, q0, t0, p, random_angles=0)
    yield from first
    size = max(1.0, float(np.abs(q0[shape.positions]).max(initial=0.0)))
    angles = int(shape.angles.sum())
    whole_turns = 2 * math.pi * np.round(centre[shape.angles] / (2 * math.pi))
    for point in _sequence(angles + 6 * len(shape.euler)):
        q = np.array(q0, dtype=float)
        if angles:
            q[shape.angles] = whole_turns + math.pi * (2.0 * point[:angles] - 1.0)
            q = placed(kernel, q, shape.angles, t0, p)
        for k, (block, origin) in enumerate(zip(shape.euler, shape.origins)):
            u = point[angles + 6 * k: angles + 6 * k + 6]
            q[block] = _shoemake(u[:3])
            q[origin] = q0[origin] + REACH * size * (2.0 * u[3:] - 1.0)
        yield _translated(kernel, shape, q, t0, p) if shape.euler else q


def _translated(kernel: KinematicsKernel, shape: Shape, q: Array, t0: float, p: Array
                ) -> Array:
    """q with its orientations kept and its positions moved by PLACING Gauss-Newton steps
    (least squares over the positions alone): a start that closes the loops as far as its
    orientations allow."""
    q = np.array(q, dtype=float)
    with np.errstate(all="ignore"):
        for _ in range(PLACING):
            phi = np.asarray(kernel.phi(q, t0, p), dtype=float)
            jacobian = np.asarray(kernel.phi_q(q, t0, p), dtype=float)[:, shape.positions]
            if not (np.all(np.isfinite(phi)) and np.all(np.isfinite(jacobian))):
                break
            q[shape.positions] += np.linalg.lstsq(jacobian, -phi, rcond=None)[0]
    return q


def _sequence(dimension: int) -> Iterator[Array]:
    """Roberts' R_d sequence in [0, 1)^dimension: x_n = frac(1/2 + n alpha), alpha_j =
    g^-(j+1) with g the root > 1 of g^(d+1) = g + 1. Chosen over random draws for even
    coverage with few points (no clusters, no gaps), and over Halton because it stays even
    in the many dimensions of a mechanism with many bodies (Halton's large prime bases
    correlate); it needs no seed, so a scan repeats exactly."""
    g = 2.0
    for _ in range(60):
        g = (1.0 + g) ** (1.0 / (dimension + 1))
    alpha = g ** -np.arange(1, dimension + 1, dtype=float)
    n = 0
    while True:
        n += 1
        yield np.mod(0.5 + n * alpha, 1.0)


def _shoemake(u: Array) -> Array:
    """The unit quaternion (Euler parameters) of a uniformly distributed rotation from three
    numbers uniform in [0, 1) (Shoemake 1992, Graphics Gems III): uniform starts over SO(3)
    give every orientation's basin the same chance."""
    a, b = math.sqrt(1.0 - u[0]), math.sqrt(u[0])
    return np.array([a * math.sin(2 * math.pi * u[1]), a * math.cos(2 * math.pi * u[1]),
                     b * math.sin(2 * math.pi * u[2]), b * math.cos(2 * math.pi * u[2])])
