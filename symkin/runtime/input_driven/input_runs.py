"""The loop over input rows (runtime.input_driven.inputs: drivers whose functions are ``input``), as
``symkin.solve(kernel, inputs=...)`` runs it: decided in the unit that brings the mechanism
near unit size (runtime.solving.units), as a run over t is; each row's inputs in the generated
functions' p[]; Ctrl-C and failures raised with the rows solved (runtime.solving.run_outcome); the
branch test of runtime.input_driven.branch over the rows. Imports NumPy only: part of the runtime.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options
from symkin.contract.status import OK
from symkin.errors import SymkinWarning
from symkin.runtime.arguments import first_guess, parameter_values, time_points
from symkin.runtime.input_driven import branch
from symkin.runtime.input_driven.inputs import Inputs, InputValues, check_inputs, solve_points
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.solving import units
from symkin.runtime.solving.assembly import flag_flips
from symkin.runtime.solving.result_arrays import Out, allocate
from symkin.runtime.solving.run_outcome import (
    SolveFailure,
    SolveInterrupted,
    _fail,
    _trajectory,
    rows_kept,
)

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]


def solve_inputs(kernel: Any, t: ArrayLike | None, q0: ArrayLike | None,
                 params: Mapping[str, float] | ArrayLike | None, options: Options,
                 out: Out | None, progress: Progress | None,
                 given: tuple[InputValues | None, ...]) -> Trajectory:
    """A run driven by inputs (runtime.input_driven.inputs), failures raised as by the time loop;
    decided in the unit that brings the mechanism near unit size (runtime.solving.units), as
    runtime.driver decides a run over t, the rows converted back to the kernel's unit."""
    times = time_points(kernel, t)
    table = check_inputs(kernel, times, *given)
    p = parameter_values(kernel, params)
    q = first_guess(kernel, q0)
    unit = (units.unit_for(kernel, q, float(times[0]), table.row(kernel, p, 0))
            if times.size else 1.0)
    if unit == 1.0:
        trajectory = _inputs_run(kernel, times, table, q, p, options, out, progress)
    else:
        scaled = units.ScaledKernel(kernel, unit)
        try:
            trajectory = _inputs_run(scaled, times, table, q / scaled.column, p, options,
                                     out, progress)
        except (SolveFailure, SolveInterrupted) as stop:
            units.to_kernel_unit(scaled, stop.trajectory.q, stop.trajectory.dq,
                                 stop.trajectory.d2q)
            raise
        units.to_kernel_unit(scaled, trajectory.q, trajectory.dq, trajectory.d2q)
    jumped = trajectory.branch_jumps
    if jumped is not None and jumped.any():
        warnings.warn(branch.message(trajectory.t, jumped), SymkinWarning, stacklevel=3)
    return trajectory


def _inputs_run(kernel: Any, times: Array, table: Inputs, q: Array, p: Array,
                options: Options, out: Out | None, progress: Progress | None) -> Trajectory:
    """The points of an input-driven run (q, the first guess, and the rows in the kernel's
    unit: a ScaledKernel's for a run decided in another), with its branch test made in that
    unit, as the generated C solve_inputs makes it."""
    run = allocate(times, kernel.nq, out)
    with np.errstate(all="ignore"):
        try:
            result, pu, assembly = solve_points(kernel, run, table, q, p, options, progress)
        except KeyboardInterrupt:
            # The rows done so far are whole (run.done counts only finished rows): hand them on.
            stop = float(times[min(run.done, times.size - 1)])
            raise SolveInterrupted(_trajectory(kernel, run, p, loads_p=_input_rows(
                kernel, table, p, run.done)), stop) from None
        if result.status != OK:
            at = float(times[run.done])
            _fail(kernel, run, pu, result, at, assembling=run.done == 0, assembly=assembly
                  if run.done == 0 else None, params=p)
    # each row's efforts and reactions at its own inputs (an actuator's depend on them)
    rows = _input_rows(kernel, table, p, run.done)
    trajectory = _trajectory(kernel, run, p, loads_p=rows)
    with np.errstate(all="ignore"), rows_kept(trajectory, "the solved rows were checked"):
        trajectory.__dict__["branch_jumps"] = branch.jump_rows(kernel, trajectory.t,
                                                               trajectory.q, rows)
        flag_flips(kernel, trajectory, rows)  # a jump off the assembly
    return trajectory


def _input_rows(kernel: Any, table: Inputs, p: Array, count: int) -> Array:
    """The generated functions' p[] of the first ``count`` rows, (count, NP + 3 NU)."""
    width = p.size + 3 * len(kernel.input_names)
    return np.array([table.row(kernel, p, k) for k in range(count)],
                    dtype=float).reshape(count, width)
