"""What ``symkin.solve`` works out once per kernel, and what it remembers between calls.

A Python loop of solves (a test, an optimiser) calls the same kernel again and again, most
often with the same parameters and the same q0. The work around the generated C solve was
then mostly asking the same questions again: which rooms of the driver apply to this kernel
(inputs, senses, ranges, removed rows, efforts), the default options, the named points' local
vectors, and the start check of a first row already judged. A :class:`Plan` answers the first
kind once per kernel (kept on the kernel: ``Kernel.call_plan``); it remembers the second kind
for a few recent parameter sets and starts, keyed on the exact bytes of the values they
depend on, so that a changed parameter, q0 or t0 is a miss and is worked out afresh.

Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.contract.options import defaults as newton_defaults
from symkin.runtime.protocol import GridSolver, KinematicsKernel
from symkin.runtime.solving import start, units

Array = NDArray[np.float64]

RECENT = 8
"""Parameter sets and starts a plan remembers: a loop over a few sets hits, a sweep-like loop
over many sets misses at the cost of one dictionary look-up."""

StartKey = tuple[float, bytes, float, bytes, float]
"""What the start check's verdict depends on besides the options: the unit the first row was
solved in, the row's exact bytes, t0, the parameters' bytes and the solver's condition estimate
at the row (runtime.solving.start.singular_start and assembly.genuine are functions of these
alone)."""


@dataclass
class Plan:
    """The facts of one kernel a solve reads on every call, and its recent answers.

    Attributes:
        moves_under_forces: forward dynamics (runtime.dynamics), not the kinematic solve.
        has_inputs: input drivers: the input room (runtime.input_driven).
        after_rows: ranges, removed rows or senses: the checks after the loop apply.
        has_dynamics: efforts and reactions are computed for a run's rows.
        has_senses: a first row may solve Phi = 0 and be no assembly (solving.assembly).
        has_grid_solver: the kernel's generated code runs whole grids (the C solver).
        coordinates, points, space, point_size: what every Trajectory carries.
        options: the Newton options of the kernel's real type (symkin.solve's default).
        start_threshold: start.start_threshold under those options for this kernel's size.
    """

    moves_under_forces: bool
    has_inputs: bool
    after_rows: bool
    has_dynamics: bool
    has_senses: bool
    has_grid_solver: bool
    coordinates: tuple[str, ...]
    points: tuple[tuple[str, str], ...]
    space: str
    point_size: int
    options: Options
    start_threshold: float
    # The named points' local vectors by the parameters' bytes (read-only: copied per run).
    _point_vectors: dict[bytes, Array] = field(default_factory=dict)
    # The length unit to solve in (runtime.solving.units) by (q0's bytes, t0, p's bytes).
    _units: dict[tuple[bytes, float, bytes], float] = field(default_factory=dict)
    # Starts judged genuine and regular (runtime.solving.start), by StartKey, with the options
    # they were judged under.
    _regular: dict[StartKey, Options] = field(default_factory=dict)

    def point_vectors(self, p_bytes: bytes, solver: GridSolver) -> Array:
        """The named points' vectors at the parameters of ``p_bytes``, an array of the
        caller's own: on a miss, those of the grid ``solver`` run with them."""
        found = self._point_vectors.get(p_bytes)
        if found is not None:
            return found.copy()
        fresh = np.asarray(solver.point_vectors(len(self.points), self.point_size),
                           dtype=np.float64).reshape(-1, self.point_size)
        kept = fresh.copy()
        kept.flags.writeable = False
        if len(self._point_vectors) >= RECENT:
            self._point_vectors.clear()
        self._point_vectors[p_bytes] = kept
        return fresh

    def unit(self, kernel: KinematicsKernel, q0: Array, t0: float, p: Array, p_bytes: bytes,
             solver: GridSolver | None = None) -> float:
        """The unit to solve in from q0 at t0 with parameters p (units.unit_for), from this
        memory (the only one it is kept in); on a miss its length scale is measured afresh,
        by the grid ``solver`` started from q0 with p on its own arrays where there is one
        (a third of the cost of the generated function called on arrays)."""
        key = (q0.tobytes(), t0, p_bytes)
        found = self._units.get(key)
        if found is None:
            raw = None if solver is None else solver.start_lever_arm(t0)
            found = units.unit_of(start.measured_lever_arm(kernel, q0, t0, p) if raw is None
                                  else start.from_raw(raw))
            if len(self._units) >= RECENT:
                self._units.clear()
            self._units[key] = found
        return found

    def judged_regular(self, key: StartKey, options: Options) -> bool:
        """Whether the start of ``key`` was judged genuine and regular under ``options``."""
        return self._regular.get(key) is options

    def remember_regular(self, key: StartKey, options: Options) -> None:
        if len(self._regular) >= RECENT:
            self._regular.clear()
        self._regular[key] = options


def of(kernel: KinematicsKernel) -> Plan:
    """The kernel's plan: made on the first call and kept on the kernel (``call_plan``);
    made afresh each call for a stand-in kernel that cannot keep one."""
    plan: Plan | None = getattr(kernel, "call_plan", None)
    if plan is None:
        plan = _make(kernel)
        with contextlib.suppress(AttributeError):  # a stand-in with slots, a frozen one
            kernel.call_plan = plan  # type: ignore[attr-defined]
    return plan


def _make(kernel: KinematicsKernel) -> Plan:
    space = str(getattr(kernel, "space", "2d"))
    coordinates = tuple(getattr(kernel, "coordinates", ()))
    options = newton_defaults(getattr(kernel, "real", "double"))
    return Plan(
        moves_under_forces=bool(getattr(kernel, "moves_under_forces", False)),
        has_inputs=bool(getattr(kernel, "input_names", ())),
        after_rows=bool(getattr(kernel, "ranges", ()) or getattr(kernel, "removed", ())
                        or getattr(kernel, "senses", ())),
        has_dynamics=bool(getattr(kernel, "has_dynamics", False)),
        has_senses=bool(getattr(kernel, "senses", ())),
        has_grid_solver=bool(getattr(kernel, "has_grid_solver", False)),
        coordinates=coordinates,
        points=tuple(getattr(kernel, "points", ())),
        space=space,
        point_size=3 if space == "3d" else 2,
        options=options,
        start_threshold=start.start_threshold(options, len(coordinates)),
    )
