"""A first look at a mechanism over its driver range: what a designer asks before anything else.

At t0, the assembly branches: the damped assembly (runtime.assembly) is run from all its starts
and from more sets of random angles (a fixed seed, so scans repeat); the converged solutions
are clustered (angles compared modulo 2 pi) into distinct branches. The branch a run takes is
the one reached from q0.

Over the time grid, the motion on that branch (and, on request, on every other): the singular
configurations passed, the stretches of flagged points, and where the motion stops, a limit
position with its aligned joints, or another failure. Nothing is raised for what the motion
meets: it is collected. Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.dense_solvers import levenberg_marquardt
from symkin.contract.status import OK
from symkin.runtime import driver, redundant, units
from symkin.runtime.assembly import RANDOM_ANGLES, assemble, starts
from symkin.runtime.edges import LIMIT_COND
from symkin.runtime.inputs import refuse_inputs
from symkin.runtime.newton import newton
from symkin.runtime.protocol import KinematicsKernel

Array = NDArray[np.float64]

EXTRA_RANDOM_ANGLES = 24
"""Sets of random angles tried besides the assembly's own starts (more branches found)."""

SAME = 1e-6
"""Two assemblies closer than this (radians; lengths relative to the mechanism's size) are
one branch."""


@dataclass(frozen=True)
class Branch:
    """An assembly at t0: q, Phi_q's condition there, and whether a run from q0 takes it."""

    q: Array
    cond: float
    taken: bool

    @property
    def near_singular(self) -> bool:
        """Phi_q nearly singular: the assembly lies on or near a singular configuration,
        where branches meet (Newton may stop anywhere near it: such branches are not exact
        and not counted reliably)."""
        return not self.cond <= LIMIT_COND


@dataclass(frozen=True)
class Stop:
    """Where a motion stops before the end of the grid.

    t: the last time reached (a limit position's time, bisected); reason: "limit position",
    "no convergence", "not finite", "singular" ...; joints: the joints that become aligned at
    a limit position; drivers: the drivers that cannot be followed beyond it; message: the
    solver's explanation.
    """

    t: float
    reason: str
    joints: tuple[str, ...]
    drivers: tuple[str, ...]
    message: str


@dataclass(frozen=True)
class Motion:
    """The motion over the grid from one branch.

    branch: its index in ScanReport.branches; reached: the last grid time solved; singular:
    (t, rank loss, dependent row groups) of each singular configuration passed; flagged:
    (first, last) time of each stretch of flagged points; stop: None when the grid's end is
    reached.
    """

    branch: int
    reached: float
    singular: tuple[tuple[float, int, tuple[tuple[str, ...], ...]], ...]
    flagged: tuple[tuple[float, float], ...]
    stop: Stop | None


@dataclass(frozen=True)
class ScanReport:
    """Branches at t0 and the motions followed (the taken branch's first)."""

    coordinates: tuple[str, ...]
    t0: float
    t1: float
    branches: tuple[Branch, ...]
    motions: tuple[Motion, ...]


def scan(kernel: KinematicsKernel, t: ArrayLike | None = None,
         params: Mapping[str, float] | ArrayLike | None = None, *,
         all_branches: bool = False) -> ScanReport:
    """Branches at t[0] and the motion over t from the branch reached from q0 (and from every
    branch with ``all_branches``). t defaults to the file's grid.

    Raises:
        SolveError: bad t or params (the caller's input), never for what the motion meets.
        SolveInterrupted: on Ctrl-C during a motion.
    """
    refuse_inputs(kernel, "a scan")
    times = driver.time_points(kernel, t)
    p = driver.parameter_values(kernel, params)
    t0 = float(times[0])
    with np.errstate(all="ignore"):
        # In the unit that brings the mechanism near unit size (runtime.units), as solve does;
        # the branches' q back in the kernel's unit.
        unit = units.unit_for(kernel, np.array(kernel.q0, dtype=float), t0, p)
        if unit == 1.0:
            branches = _branches(kernel, t0, p)
        else:
            scaled = units.ScaledKernel(kernel, unit)
            branches = [dataclasses.replace(branch, q=scaled.to_length(branch.q))
                        for branch in _branches(scaled, t0, p)]
    motions = []
    for index, branch in enumerate(branches):
        if branch.taken or all_branches:
            motions.append(_motion(kernel, times, p, index, branch))
    return ScanReport(tuple(kernel.coordinates), t0, float(times[-1]), tuple(branches),
                      tuple(motions))


def _branches(kernel: KinematicsKernel, t0: float, p: Array) -> list[Branch]:
    """The distinct assemblies at t0, the one reached from q0 first (when there is one)."""
    options = driver.default_options(kernel)
    angles = np.array([name.endswith(".phi") for name in kernel.coordinates])
    q0 = np.array(kernel.q0, dtype=float)
    found: list[Branch] = []
    first = assemble(kernel, q0, t0, p, options).result
    if first.status == OK:
        found.append(Branch(_wrapped(first.q, angles), first.cond, True))
    for start in starts(kernel, q0, t0, p, random_angles=RANDOM_ANGLES + EXTRA_RANDOM_ANGLES):
        q, _ = levenberg_marquardt(kernel, start, t0, p, options)
        result = newton(kernel, q, t0, p, options)
        if result.status != OK:
            continue
        q = _wrapped(result.q, angles)
        # An over-constrained file's rows removed at t0 must hold too: elsewhere the kept rows
        # alone are assembled, which is no assembly of the file (runtime.redundant).
        if not redundant.holds(kernel, result.q, t0, p, options.target_q):
            continue
        if not any(_same(q, b.q, angles) for b in found):
            found.append(Branch(q, result.cond, False))
    return found


def _wrapped(q: Array, angles: NDArray[np.bool_]) -> Array:
    """q with its angles in (-pi, pi]."""
    q = np.array(q, dtype=float)
    q[angles] = math.pi - np.mod(math.pi - q[angles], 2 * math.pi)
    return q


def _same(a: Array, b: Array, angles: NDArray[np.bool_]) -> bool:
    difference = np.abs(a - b)
    difference[angles] = np.minimum(difference[angles], 2 * math.pi - difference[angles])
    size = 1.0 + float(np.abs(a[~angles]).max(initial=0.0))
    return bool(difference[angles].max(initial=0.0) <= SAME
                and difference[~angles].max(initial=0.0) <= SAME * size)


def _motion(kernel: KinematicsKernel, times: Array, p: Array, index: int,
            branch: Branch) -> Motion:
    stop = None
    try:
        trajectory = driver.solve(kernel, t=times, q0=branch.q, params=p)
    except driver.SolveFailure as failure:
        trajectory = failure.trajectory
        last = float(trajectory.t[-1]) if trajectory.t.size else float(times[0])
        at = failure.reached if math.isfinite(failure.reached) else last
        stop = Stop(at, failure.reason, failure.aligned, failure.drivers, str(failure))
    reached = float(trajectory.t[-1]) if trajectory.t.size else math.nan
    return Motion(index, reached, trajectory.singular, _stretches(trajectory.t,
                                                                   trajectory.flagged), stop)


def _stretches(t: Array, flagged: NDArray[np.bool_]) -> tuple[tuple[float, float], ...]:
    """(first, last) time of each run of consecutive flagged points."""
    found = []
    k = 0
    while k < flagged.size:
        if flagged[k]:
            end = k
            while end + 1 < flagged.size and flagged[end + 1]:
                end += 1
            found.append((float(t[k]), float(t[end])))
            k = end + 1
        else:
            k += 1
    return tuple(found)


def distinguishing(report: ScanReport, most: int = 2) -> list[int]:
    """The indices of the (at most ``most``) coordinates that differ most between branches:
    the angles first (they tell elbow up from elbow down), by their spread modulo 2 pi."""
    if len(report.branches) < 2:
        return []
    qs = np.array([b.q for b in report.branches])
    spread = []
    for c, name in enumerate(report.coordinates):
        values = qs[:, c]
        if name.endswith(".phi"):
            gaps = np.abs(values[:, None] - values[None, :])
            gap = float(np.minimum(gaps, 2 * math.pi - gaps).max())
            spread.append((gap > SAME, gap, c))
        else:
            gap = float(values.max() - values.min())
            spread.append((False, gap, c))
    spread.sort(reverse=True)
    return [c for _, gap, c in spread[:most] if gap > SAME]
