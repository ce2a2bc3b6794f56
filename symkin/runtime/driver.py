"""Stage 6 — driver: position, velocity and acceleration analysis over a time grid.

The chapter's algorithm (Example 2.6, section 2.7) on any compiled kernel:

    q   = q + dq h + ddq h^2 / 2                 Taylor predictor                (2.76)
    Newton-Raphson on Phi(q, t) = 0              test the residual of the iterate (2.72)
    Phi_q dq  = -Phi_t                           velocity                         (2.73)
    Phi_q ddq = Gamma                            acceleration                     (2.74)

One LU factorization (partial pivoting) of the converged Phi_q serves both linear solves, and
the condition estimate of each point (runtime.solving.accuracy) that decides whether it is flagged.
The first point is assembled from the file's q0, which may be poor (the chapter starts from
q = 0): plain Newton first, then damped Newton from several starts (runtime.solving.assembly). Where
several assemblies exist, the one reached from q0 is taken. A grid point the plain step cannot
solve goes to runtime.solving.edges: a too-large step is subdivided, a singular configuration is
passed on the predicted branch, a limit position is bisected and reported.

With a C kernel that carries the generated solver, the grid loop runs in C: one call per
trajectory, written straight into the result arrays (runtime.solving.result_arrays: fresh, or the
caller's ``out=``). When it solves the whole grid, the usual case, the Trajectory is returned at
once; only where it stops does the general path above take over, from that point. Imports NumPy and
SciPy only: it is part of the runtime.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options
from symkin.contract.options import defaults as newton_defaults
from symkin.contract.status import NOT_FINITE, OK, SINGULAR
from symkin.errors import SolveError
from symkin.runtime.arguments import first_guess as first_guess
from symkin.runtime.arguments import grid as grid
from symkin.runtime.arguments import parameter_values as parameter_values
from symkin.runtime.arguments import time_points as time_points
from symkin.runtime.input_driven import input_runs
from symkin.runtime.input_driven.inputs import InputValues
from symkin.runtime.kernel import Kernel
from symkin.runtime.loads import forces
from symkin.runtime.outputs import ranges, redundant
from symkin.runtime.outputs.results import Trajectory
from symkin.runtime.protocol import GridSolver, KinematicsKernel
from symkin.runtime.solving import call_plan, failures, units
from symkin.runtime.solving import start as start_check
from symkin.runtime.solving.assembly import assemble, flag_flips, genuine
from symkin.runtime.solving.c_loop import _c_loop, _c_outcome, _c_run
from symkin.runtime.solving.call_plan import Plan
from symkin.runtime.solving.edges import Resolution, resolve
from symkin.runtime.solving.newton import Newton, kinematics, newton
from symkin.runtime.solving.result_arrays import Out, allocate
from symkin.runtime.solving.result_arrays import Run as _Run
from symkin.runtime.solving.run_outcome import SolveFailure as SolveFailure
from symkin.runtime.solving.run_outcome import SolveInterrupted as SolveInterrupted
from symkin.runtime.solving.run_outcome import _fail, refuse_reversed, rows_kept
from symkin.runtime.solving.run_outcome import _trajectory as _trajectory
from symkin.runtime.solving.start import factored_lever_arm, singular_start, start_threshold

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]

# ----- the time loop -------------------------------------------------------------------------

def _python_loop(kernel: KinematicsKernel, run: _Run, q: Array, p: Array, options: Options,
                 progress: Progress | None) -> Newton:
    """The grid loop in Python from point run.done (q: the first guess when it is the first
    point); returns the Newton outcome at the last point attempted."""
    result = Newton(q, OK, 0, 0.0, None)
    for k in range(run.done, run.t.size):
        t = float(run.t[k])
        previous = (0.0, 0.0, 0.0)  # max |q|, |dq|, |ddq| of the last point (error model)
        if k > 0:
            h = t - run.t[k - 1]
            q = run.q[k - 1] + run.dq[k - 1] * h + run.d2q[k - 1] * (h * h / 2)  # (2.76)
            nq, ndq, nddq = (float(np.abs(v[k - 1]).max(initial=0.0))
                             for v in (run.q, run.dq, run.d2q))
            previous = (nq, ndq, nddq)
        result = newton(kernel, q, t, p, options, previous)
        if result.status != OK:
            return result
        point = kinematics(kernel, result, t, p, options)
        if point is None:
            return Newton(result.q, NOT_FINITE, result.iterations, result.residual, None)
        run.store(k, point)
        if k == 0 and isinstance(kernel, Kernel):  # its Phi_q is phi_q_nz's (not a view's)
            run.lever_arm = factored_lever_arm(kernel, result.factors)
        if progress is not None:
            progress(k + 1, run.t.size)
    return result


def default_options(kernel: KinematicsKernel) -> Options:
    """Options() for double precision; looser ones for a C kernel computing in float."""
    return newton_defaults(getattr(kernel, "real", "double"))


def solve(kernel: KinematicsKernel, t: ArrayLike | None = None, q0: ArrayLike | None = None,
          params: Mapping[str, float] | ArrayLike | None = None, *,
          options: Options | None = None, progress: Progress | None = None,
          use_c_solver: bool = True, stop_at_singular: bool = False,
          sensitivities: bool = False, out: Out | None = None,
          inputs: InputValues | None = None, input_rates: InputValues | None = None,
          input_accels: InputValues | None = None) -> Trajectory:
    """Positions, velocities and accelerations of a mechanism over a time grid.

    Args:
        kernel: a compiled kernel (``symkin.compile``), NumPy or C.
        t: the times to solve at, increasing; default: the file's grid t0 + k dt, t1 included.
        q0: the first guess at t[0]; default: the file's q0.
        params: parameter values by name (a mapping, others nominal) or all of them in order.
        options: Newton tolerances and the singularity threshold; default: suited to the
            kernel's real type (looser for a C kernel generated with float).
        progress: called as progress(done, total) while the grid is solved.
        use_c_solver: run the grid loop in the generated C solver when the kernel has one.
        stop_at_singular: stop at the first singular point (SolveFailure) instead of passing
            through it, and do not subdivide a step that fails (the behaviour of old).
        sensitivities: also compute ``q_p`` = dq/dp (T, N, NP) from Phi_q q_p = -Phi_p.
        out: arrays to write the result into instead of fresh ones (numpy's ``out=``): a
            Trajectory from an earlier solve with as many time points (its t, q, dq, d2q,
            cond and flagged are overwritten), or a tuple (q, dq, d2q) of writable
            C-contiguous float64 arrays of shape (T, N). The returned Trajectory holds these
            very arrays; the rest of ``out`` (params, singular, ...) is left as it was.
        inputs: for a mechanism with input drivers (a driver function written ``input``),
            their values at every t: an array (T, NU) in ``kernel.input_names`` order or a
            dict by driver name of arrays (T,). Each point is then solved from the last
            solution (runtime.input_driven.inputs); t defaults to the file's grid as above.
        input_rates, input_accels: the inputs' rates and accelerations, the same shapes;
            without them dq (and d2q) are NaN: positions only.

    Returns:
        The Trajectory.

    Raises:
        SolveFailure (a SolveError) with the partial trajectory when the mechanism cannot be
        assembled at t[0], Newton does not converge, or Phi_q is singular. SolveError for a
        bad t, q0, params or out.
    """
    plan = getattr(kernel, "call_plan", None) or call_plan.of(kernel)  # of(): on the first call
    if plan.moves_under_forces:  # forward dynamics: runtime.dynamics
        from symkin.runtime.dynamics import run as motion

        if options or sensitivities or out is not None or inputs is not None:
            raise SolveError("options=, sensitivities=, out= and inputs= are not supported "
                             "for a mechanism that its forces move")
        return motion.solve(kernel, t, q0, params, progress=progress,  # type: ignore[arg-type]
                            stop_at_singular=stop_at_singular)
    options = options or plan.options
    if stop_at_singular:
        options = dataclasses.replace(options, stop_at_singular=True)
    try:
        if plan.has_inputs or inputs is not None or input_rates is not None \
                or input_accels is not None:
            trajectory = _solved(kernel, plan, t, q0, params, options, progress, use_c_solver,
                                 out, (inputs, input_rates, input_accels), sensitivities)
        else:  # the usual case, straight on (a loop of calls pays for every call made)
            trajectory = _solve_in_unit(kernel, plan, t, q0, params, options, progress,
                                        use_c_solver, out)
    except SolveFailure as failure:  # past a curve's range first: that is the cause to name
        if plan.after_rows:
            _stop_outside_range(kernel, failure.trajectory)
        raise
    if plan.after_rows:  # ranges, removed rows or senses: else each check has nothing to do
        with rows_kept(trajectory, "the solved rows were checked"):
            _stop_outside_range(kernel, trajectory)
            trajectory = redundant.check(kernel, trajectory, options)
            flag_flips(kernel, trajectory, trajectory.params)  # a jump off the assembly
    if sensitivities:
        from symkin.runtime.outputs.sensitivity import with_sensitivities

        with rows_kept(trajectory, "the sensitivities were computed"):
            return with_sensitivities(kernel, trajectory)
    return trajectory


def _stop_outside_range(kernel: KinematicsKernel, trajectory: Trajectory) -> None:
    """A SolveFailure at the first point where a pair's coordinate left its range (the rows
    before it kept); nothing when every point is inside."""
    found = ranges.first_outside(kernel, trajectory)
    if found is not None:
        k, message = found
        raise SolveFailure(message, ranges.head(trajectory, k), float(trajectory.t[k]),
                           math.nan, 0, reason="out of range")


def _solved(kernel: KinematicsKernel, plan: Plan, t: ArrayLike | None, q0: ArrayLike | None,
            params: Mapping[str, float] | ArrayLike | None, options: Options,
            progress: Progress | None, use_c_solver: bool, out: Out | None,
            given: tuple[Any, Any, Any], sensitivities: bool) -> Trajectory:
    """The trajectory of the grid loop that fits: with input values, or the general one."""
    inputs, input_rates, input_accels = given
    if plan.has_inputs or inputs is not None:
        if sensitivities:
            raise SolveError("sensitivities= is not supported for a mechanism with input "
                             "drivers (q_p would need the inputs at every point)")
        return input_runs.solve_inputs(kernel, t, q0, params, options, out, progress,
                             (inputs, input_rates, input_accels))
    if input_rates is not None or input_accels is not None:
        raise SolveError("input_rates= and input_accels= need inputs= (and a mechanism with "
                         "input drivers)")
    return _solve_in_unit(kernel, plan, t, q0, params, options, progress, use_c_solver, out)


def _solve_in_unit(kernel: KinematicsKernel, plan: Plan, t: ArrayLike | None,
                   q0: ArrayLike | None,
                   params: Mapping[str, float] | ArrayLike | None, options: Options,
                   progress: Progress | None, use_c_solver: bool, out: Out | None
                   ) -> Trajectory:
    """_solve in the unit that brings the mechanism's length scale near 1 (runtime.solving.units),
    the rows converted back to the kernel's unit (also those a failure or an interrupt
    carries)."""
    times = time_points(kernel, t)
    p = parameter_values(kernel, params)
    q = first_guess(kernel, q0)
    p_bytes = p.tobytes()
    # The solver is taken first: started from q with p, it measures the unit's length scale
    # on its own arrays, and it runs the grid in the usual case, the kernel's own unit.
    solver = kernel.grid_solver(options, q, p) if use_c_solver and plan.has_grid_solver \
        else None
    unit = plan.unit(kernel, q, times.item(0), p, p_bytes, solver)
    if unit == 1.0:
        return _solve(kernel, times, q, p, options, progress, solver, out,
                      (plan, unit, p_bytes))
    if solver is not None:
        solver.release()
    scaled = units.ScaledKernel(kernel, unit)
    q = q / scaled.column
    solver = scaled.grid_solver(options, q, p) if use_c_solver and scaled.has_grid_solver \
        else None
    try:
        trajectory = _solve(scaled, times, q, p, options, progress, solver, out,
                            (plan, unit, p_bytes))
    except (SolveFailure, SolveInterrupted) as stop:
        units.to_kernel_unit(scaled, stop.trajectory.q, stop.trajectory.dq, stop.trajectory.d2q)
        raise
    units.to_kernel_unit(scaled, trajectory.q, trajectory.dq, trajectory.d2q)
    return trajectory


def _solve(kernel: KinematicsKernel, times: Array, q: Array, p: Array, options: Options,
           progress: Progress | None, solver: GridSolver | None, out: Out | None,
           planned: tuple[Plan, float, bytes]) -> Trajectory:
    """The C grid loop over the whole grid (``solver``, started from q with p; None: no C);
    only where it stops (a failed assembly from q0, a singular point, a limit, a failure) or
    without the C solver, the general loop with the assembly and the edge treatments takes
    over. The arguments as _solve_in_unit checked them (not checked again: a loop of calls
    pays for that once a call); ``planned``: the kernel's call plan, the length unit
    ``kernel`` is seen in and the bytes of p."""
    plan, _, p_bytes = planned
    run = allocate(times, q.size, out)
    try:
        if solver is not None:
            if plan.has_dynamics:
                run.forces_out = forces.allocate(kernel, times.size)
            solver.bind(run.t, run.q, run.dq, run.d2q, run.cond, run.flagged, run.forces_out)
            solved = _c_run(run, solver, progress)
            # The usual first row, a clearly regular start of a mechanism without senses, is
            # settled here by the solver's condition estimate and lever arm there with a few
            # multiplications (clears); any other, by _first_row_stands.
            threshold = plan.start_threshold if options is plan.options \
                else start_threshold(options, len(plan.coordinates))
            if run.done and (plan.has_senses or not start_check.clears(
                    run.cond.item(0), run.lever_arm, threshold)) \
                    and not _first_row_stands(kernel, run, p, options, planned):
                # Plain Newton in C found Phi = 0 where the mechanism is not assembled as
                # meant (a revolute's axes reversed): the damped assembly looks for the one
                # meant, as without C, and the grid is run again from it.
                run.done, first = 0, None
            else:
                if run.done == times.size:  # the usual case: nothing left to treat
                    run.fallbacks = solver.fallbacks
                    return _whole(kernel, plan, run, p, plan.point_vectors(p_bytes, solver))
                first = _c_outcome(kernel, run, solver, p, solved)
        else:
            first = None
        # An expression singular at some t gives inf/NaN there; that is reported as a
        # failure (status NOT_FINITE), so NumPy's floating-point warnings would only repeat it.
        with np.errstate(all="ignore"):
            result = _grid(kernel, run, solver, first, q, p, options, progress)
    except KeyboardInterrupt:
        # The rows done so far are whole (run.done counts only finished rows): hand them on.
        stop = float(times[min(run.done, times.size - 1)])
        raise SolveInterrupted(_trajectory(kernel, run, p), stop) from None
    finally:
        if solver is not None:
            solver.release()  # back to the kernel's pool for the next run
    with np.errstate(all="ignore"):
        if isinstance(result, Resolution):
            _fail_edge(kernel, run, p, result, float(times[run.done]))
        elif result.status != OK:
            if result.status == SINGULAR and run.done == 0 and result.residual <= options.tol_phi:
                _check_start(kernel, run, p, options, result.q)  # assembled, singular there
            _fail(kernel, run, p, result, float(times[run.done]), assembling=run.done == 0)
        return _trajectory(kernel, run, p)


def _first_row_stands(kernel: KinematicsKernel, run: _Run, p: Array, options: Options,
                      planned: tuple[Plan, float, bytes]) -> bool:
    """Whether the first row the C grid loop solved stands, where _solve's test of the
    solver's estimate did not clear it (or the mechanism has senses). Raises SolveFailure
    where it is a singular start (_check_start); False where it solves Phi = 0 but is no
    assembly (assembly.genuine).

    The verdict depends on the row to the bit, t0, the parameters, the condition estimate,
    the unit and the options alone, and a row the plan has judged before is not judged
    again."""
    plan, unit, p_bytes = planned
    estimate = run.cond.item(0)
    t0 = run.t.item(0)
    key = (unit, run.q[0].tobytes(), t0, p_bytes, estimate)
    if plan.judged_regular(key, options):
        return True
    if plan.has_senses and not genuine(kernel, run.q[0], t0, p):
        return False
    _check_start(kernel, run, p, options)  # raises where it is not regular
    plan.remember_regular(key, options)
    return True


def _whole(kernel: KinematicsKernel, plan: Plan, run: _Run, p: Array, vectors: Array
           ) -> Trajectory:
    """The Trajectory of a grid solved whole by C: _trajectory's, built from the plan's
    names where there are no efforts and reactions to attach."""
    if plan.has_dynamics:
        return _trajectory(kernel, run, p, vectors)
    return Trajectory.solved(run.t, run.q, run.dq, run.d2q, plan.coordinates, plan.points,
                             vectors, p, run.fallbacks, run.flagged, run.cond, (),
                             space=plan.space)


def _grid(kernel: KinematicsKernel, run: _Run, solver: GridSolver | None,
          first: Newton | None, q: Array, p: Array, options: Options,
          progress: Progress | None) -> Newton | Resolution:
    """Go on from where the C grid loop stopped (first: its outcome; None without C):
    assemble at t[0] if it could not, then solve the grid; a point the plain step cannot
    solve goes to edges.resolve and the loop resumes after it. Returns the outcome that
    stopped the run (status OK when the grid is done)."""
    # The C solver assembles t[0] itself by plain Newton from q0; only when that fails does
    # the damped assembly in Python take over (and the grid is run again from its result).
    result = first
    if result is None or (result.status != OK and run.done == 0):
        assembly = assemble(kernel, q, float(run.t[0]), p, options)
        start = assembly.result
        if start.status == SINGULAR and start.residual <= options.tol_phi:
            _check_start(kernel, run, p, options, start.q)  # assembled, but singular there
        if start.status != OK:
            _fail(kernel, run, p, start, float(run.t[0]), assembling=True, assembly=assembly)
        if solver is not None:
            solver.start(options, start.q, p)
        result = _resume(kernel, run, solver, start.q, p, options, progress)
        _check_start(kernel, run, p, options)
    while result.status not in (OK, NOT_FINITE) and run.done > 0 \
            and not options.stop_at_singular:
        k = run.done
        resolution = resolve(kernel, p, options, run.state(k - 1), float(run.t[k]))
        if resolution.passage is not None:
            run.passages.append(resolution.passage)
        if resolution.point is None:
            return resolution
        run.store(k, resolution.point)
        if solver is not None:
            solver.set_state(float(run.t[k]), run.q[k], run.dq[k], run.d2q[k])
        if progress is not None:
            progress(run.done, run.t.size)
        result = _resume(kernel, run, solver, resolution.point.q, p, options, progress)
    return result


def _resume(kernel: KinematicsKernel, run: _Run, solver: GridSolver | None, q: Array, p: Array,
            options: Options, progress: Progress | None) -> Newton:
    if solver is not None:
        return _c_loop(kernel, run, solver, p, progress)
    return _python_loop(kernel, run, q, p, options, progress)


def _check_start(kernel: KinematicsKernel, run: _Run, p: Array, options: Options,
                 assembled: Array | None = None) -> None:
    """Raise SolveFailure (reason "singular") when the start is a singular or limit
    configuration (runtime.solving.start): the first point solved, keeping only that point (the rows
    stepped from it are not trusted), or the ``assembled`` q that Newton found singular (no
    row). Nothing to check before the first point is solved."""
    if assembled is None and run.done == 0:
        return
    t0 = float(run.t[0])
    first = run.q[0] if assembled is None else assembled
    refuse_reversed(kernel, run, first, t0, p)
    # The solver's condition estimate and lever arm at the first row, from the Phi_q there.
    estimate = float(run.cond[0]) if assembled is None else math.nan
    singular = singular_start(kernel, first, t0, p, options, estimate,
                              run.lever_arm if assembled is None else None)
    if singular is None:
        return
    run.done = 0 if assembled is not None else 1
    rows = [row for group in singular.groups for row in group]
    raise SolveFailure(failures.explain_start(singular, t0), _trajectory(kernel, run, p), t0,
                       math.nan, 0, rows, "singular", math.nan, singular.aligned,
                       singular.drivers)


def _fail_edge(kernel: KinematicsKernel, run: _Run, p: Array, stop: Resolution,
               t: float) -> None:
    """Raise SolveFailure for a grid point that could not be reached even by substeps."""
    message, reason = failures.explain_stop(stop, t)
    reached = math.nan if stop.reached is None else stop.reached.t
    raise SolveFailure(message, _trajectory(kernel, run, p), t, math.nan, 0,
                       [row for group in stop.groups for row in group], reason, reached,
                       stop.aligned, stop.drivers)
