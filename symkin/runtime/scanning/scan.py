"""A first look at a mechanism over its driver range: what a designer asks before anything else.

At t0 (and at given values of the input drivers), the assembly branches: the damped assembly
(runtime.solving.assembly) from q0, then the deflated multi-start search
(runtime.scanning.assemblies: seeded, so scans repeat) for the others, each distinct (angles modulo
2 pi, Euler parameters up to their sign) and genuine (no spatial revolute's axes reversed, no angle
driver half a turn away: runtime.solving.assembly.genuine). The branch a run takes is the one
reached from q0.

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

from symkin.contract.status import OK
from symkin.errors import SolveError
from symkin.runtime import driver
from symkin.runtime.dynamics.model import refuse_motion
from symkin.runtime.outputs import redundant
from symkin.runtime.protocol import KinematicsKernel
from symkin.runtime.scanning.assemblies import SAME, Shape, search
from symkin.runtime.solving import units
from symkin.runtime.solving.assembly import assemble, genuine
from symkin.runtime.solving.edges import LIMIT_COND

Array = NDArray[np.float64]

InputPoint = Mapping[str, float] | ArrayLike
"""The input drivers' values at which a scan looks for assemblies."""


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
    inputs: Mapping[str, float] = dataclasses.field(default_factory=dict)
    """The input drivers' values of the assemblies (empty without input drivers)."""


def scan(kernel: KinematicsKernel, t: ArrayLike | None = None,
         params: Mapping[str, float] | ArrayLike | None = None, *,
         all_branches: bool = False, inputs: InputPoint | None = None) -> ScanReport:
    """Branches at t[0] and the motion over t from the branch reached from q0 (and from every
    branch with ``all_branches``). t defaults to the file's grid.

    A mechanism with input drivers needs ``inputs``: their values (a dict by driver name, or
    NU values in the order of kernel.input_names); the branches are then the assemblies at
    those inputs, and no motion is followed (the inputs are one set of values, not a path).

    Raises:
        SolveError: bad t, params or inputs (the caller's input), never for what the motion
            meets.
        SolveInterrupted: on Ctrl-C during a motion.
    """
    refuse_motion(kernel, "symkin scan")
    times = driver.time_points(kernel, t)
    p = driver.parameter_values(kernel, params)
    values = input_point(kernel, inputs)
    if values:
        p = kernel.with_inputs(p, list(values.values()))  # type: ignore[attr-defined]
    t0 = float(times[0])
    with np.errstate(all="ignore"):
        # In the unit that brings the mechanism near unit size (runtime.solving.units), as solve
        # does; the branches' q back in the kernel's unit.
        unit = units.unit_for(kernel, np.array(kernel.q0, dtype=float), t0, p)
        if unit == 1.0:
            branches = _branches(kernel, t0, p)
        else:
            scaled = units.ScaledKernel(kernel, unit)
            branches = [dataclasses.replace(branch, q=scaled.to_length(branch.q))
                        for branch in _branches(scaled, t0, p)]
    motions = []
    for index, branch in enumerate(branches):
        if not values and (branch.taken or all_branches):
            motions.append(_motion(kernel, times, p, index, branch))
    return ScanReport(tuple(kernel.coordinates), t0, float(times[-1]), tuple(branches),
                      tuple(motions), values)


def input_point(kernel: KinematicsKernel, inputs: InputPoint | None) -> dict[str, float]:
    """The input drivers' values by name, checked (empty for a mechanism without inputs).

    Raises:
        SolveError: inputs missing, unknown, of the wrong count or not finite.
    """
    names = tuple(getattr(kernel, "input_names", ()))
    if not names:
        if inputs is not None:
            raise SolveError("this mechanism has no input drivers (a driver function written "
                             "`input`): leave out inputs=")
        return {}
    if inputs is None:
        raise SolveError(f"this mechanism's drivers {', '.join(names)} are inputs: a scan "
                         "needs their values, inputs= (a dict by driver name or "
                         f"{len(names)} numbers)")
    if isinstance(inputs, Mapping):
        unknown = sorted(set(inputs) - set(names))
        missing = [name for name in names if name not in inputs]
        if unknown or missing:
            raise SolveError("inputs: " + "; ".join(
                [f"no input driver named {', '.join(map(repr, unknown))}"] * bool(unknown)
                + [f"missing {', '.join(map(repr, missing))}"] * bool(missing))
                + f" (the input drivers are {', '.join(names)})")
        listed = [inputs[name] for name in names]
    else:
        listed = list(np.ravel(np.asarray(inputs, dtype=object)))
        if len(listed) != len(names):
            raise SolveError(f"inputs: give {len(names)} values ({', '.join(names)}), got "
                             f"{len(listed)}")
    values = {}
    for name, value in zip(names, listed):
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = math.nan
        if not math.isfinite(number):
            raise SolveError(f"inputs: {name} is {value!r}; every input must be a finite "
                             "number")
        values[name] = number
    return values


def _branches(kernel: KinematicsKernel, t0: float, p: Array) -> list[Branch]:
    """The distinct assemblies at t0, the one reached from q0 first (when there is one): the
    deflated multi-start search of runtime.scanning.assemblies."""
    options = driver.default_options(kernel)
    shape = Shape(tuple(kernel.coordinates))
    q0 = np.array(kernel.q0, dtype=float)
    found: list[Branch] = []
    first = assemble(kernel, q0, t0, p, options).result
    # An over-constrained file's rows removed at t0 must hold too: elsewhere the kept rows
    # alone are assembled, which is no assembly of the file (runtime.outputs.redundant).
    if (first.status == OK and redundant.holds(kernel, first.q, t0, p, options.target_q)
            and genuine(kernel, first.q, t0, p)):
        found.append(Branch(shape.canonical(first.q), first.cond, True))
    turns = first.q if first.status == OK else q0  # the turn the angles are driven to
    for result in search(kernel, q0, t0, p, options, [b.q for b in found], turns):
        found.append(Branch(shape.canonical(result.q), result.cond, False))
    return found


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
    """The indices of the coordinates that tell the branches apart as printed (``printed``):
    the (at most ``most``) that differ most between branches, the angles first (they tell
    elbow up from elbow down), by their spread modulo 2 pi; then, while two branches still
    print alike in every one of them, the coordinate that tells the most such pairs apart
    (two branches of a spherical four-bar can agree in the two that spread most)."""
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
    chosen = [c for _, gap, c in spread[:most] if gap > SAME]
    alike = [(a, b) for a in range(len(qs)) for b in range(a)
             if not any(_apart(qs[a, c], qs[b, c]) for c in chosen)]
    while alike:
        told, c = max(((sum(_apart(qs[a, c], qs[b, c]) for a, b in alike), c)
                       for _, _, c in spread if c not in chosen), default=(0, -1))
        if not told:
            break  # no coordinate tells them apart: they print alike in every one
        chosen.append(c)
        alike = [(a, b) for a, b in alike if not _apart(qs[a, c], qs[b, c])]
    return chosen


def _apart(a: float, b: float) -> bool:
    """Two values that differ beyond SAME (relative to their size) and as printed (a value
    near zero printed -2e-17 in one branch and 4e-13 in another tells nothing apart)."""
    return abs(a - b) > SAME * (1.0 + max(abs(a), abs(b))) and printed(a) != printed(b)


def printed(value: float) -> str:
    """A coordinate's value as a scan report prints it."""
    return f"{value:.6g}"
