"""Runs driven by inputs: drivers whose functions are ``input`` take their values, rates and
accelerations from the caller at each time point (sensors, encoders), not from a formula in t.

Each point is solved from the last solution, without a Taylor prediction (the inputs say where
the mechanism is): Newton at the inputs, then dq (2.73) with Phi_t holding the rates and ddq
(2.74) with Gamma holding the accelerations. Rates not given leave dq (and ddq) NaN: a
position-only run never pretends to know them. A C kernel solves each point in its generated
``<prefix>_solve_inputs``; any other kernel through the runtime's Newton. Imports NumPy only.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options
from symkin.contract.status import NOT_FINITE, OK, SINGULAR
from symkin.errors import SolveError
from symkin.runtime.solving.assembly import Assembly, assemble
from symkin.runtime.solving.edges import Passage
from symkin.runtime.solving.linalg import dependencies
from symkin.runtime.solving.newton import Newton, Point, kinematics, newton
from symkin.runtime.solving.result_arrays import Run
from symkin.runtime.solving.run_outcome import refuse_reversed

Array = NDArray[np.float64]
InputValues = Mapping[str, ArrayLike] | ArrayLike


class InputStepper(Protocol):
    """A backend's generated one-point solve at given inputs (the C ``solve_inputs``)."""

    fallbacks: int
    """The sparse LU's fall-backs to dense LU since start."""

    branch_jump: bool
    """Whether the last step's solution may lie on another assembly than the step before's
    (the generated solve's own form of runtime.input_driven.branch's tests)."""

    def start(self, options: Options, q: Array, unit: float = 1.0) -> None:
        """Begin from q (the assembled first point, in the kernel's unit), deciding in the
        length unit ``unit`` (runtime.solving.units)."""

    def step(self, t: float, pu: Array, rates: int) -> Point | Newton:
        """Solve at time t (for drivers that are functions of t) with the generated
        functions' p[] pu: the Point, or the failed Newton outcome."""


class InputKernel(Protocol):
    """What an input-driven run needs of a kernel besides the driver's KinematicsKernel."""

    input_names: tuple[str, ...]
    real: str

    def with_inputs(self, p: ArrayLike | None, u: ArrayLike, du: ArrayLike | None = None,
                    ddu: ArrayLike | None = None) -> Array: ...
    def input_stepper(self) -> InputStepper | None: ...


class Inputs:
    """The inputs of a run, checked: u (T, NU); du and ddu (T, NU) or None (not given)."""

    def __init__(self, u: Array, du: Array | None, ddu: Array | None) -> None:
        self.u, self.du, self.ddu = u, du, ddu

    @property
    def rates(self) -> int:
        """2: rates and accelerations given, 1: rates only, 0: positions only."""
        return 0 if self.du is None else 1 if self.ddu is None else 2

    def row(self, kernel: InputKernel, p: Array, k: int) -> Array:
        """The generated functions' p[] at point k."""
        return kernel.with_inputs(p, self.u[k], None if self.du is None else self.du[k],
                                  None if self.ddu is None else self.ddu[k])


def refuse_inputs(kernel: Any, what: str) -> None:
    """Refuse ``what`` (a sweep, a scan) for a mechanism with input drivers: it runs over t
    alone, and the generated functions would read inputs nobody gave.

    Raises:
        SolveError: the kernel has input drivers.
    """
    names = tuple(getattr(kernel, "input_names", ()))
    if names:
        raise SolveError(f"{what} of a mechanism with input drivers ({', '.join(names)}) is "
                         "not supported: it runs over t alone. Solve it with symkin.solve("
                         "..., inputs=...) or symkin run --inputs TABLE.csv")


def check_inputs(kernel: InputKernel, times: Array, inputs: InputValues | None,
          rates: InputValues | None, accels: InputValues | None) -> Inputs:
    """The inputs as arrays (T, NU), refused with a message saying what is wrong where.

    Raises:
        SolveError: inputs missing, a wrong shape or name, a value not finite, accelerations
            without rates, or inputs given to a mechanism that has no input drivers.
    """
    names = kernel.input_names
    if not names:
        raise SolveError("this mechanism has no input drivers (a driver function written "
                         "`input`): leave out inputs=, input_rates= and input_accels=")
    if inputs is None:
        raise SolveError(f"this mechanism's drivers {', '.join(names)} are inputs: pass their "
                         "values as inputs= (an array (T, NU) or a dict by driver name), and "
                         "input_rates=, input_accels= for velocities and accelerations")
    if accels is not None and rates is None:
        raise SolveError("input_accels= needs input_rates= too (the accelerations of the "
                         "mechanism depend on both)")
    checked = Inputs(*(None if values is None else _table(values, what, names, times)
                       for values, what in ((inputs, "inputs"), (rates, "input_rates"),
                                            (accels, "input_accels"))))  # type: ignore[arg-type]
    negative = negative_length(checked.u, names, tuple(getattr(kernel, "input_lengths", ())))
    if negative is not None:
        k, name, message = negative
        raise SolveError(f"inputs[{name!r}] at point {k} (t = {times[k]:.10g}): {message}")
    return checked


def negative_length(u: Array, names: tuple[str, ...], lengths: tuple[str, ...]
                    ) -> tuple[int, str, str] | None:
    """The first point k and input whose value in u (T, NU) is a negative length, with the
    message's end (what is wrong and how to fix it), or None. A length (a distance driver's
    f, Kernel.input_lengths) is never negative: its row holds the square, so -1 would be
    solved, silently, as 1. The CLI's inputs table and symkin.solve both ask here."""
    for name in lengths:
        column = u[:, names.index(name)]
        negative = np.flatnonzero(column < 0)
        if negative.size:
            k = int(negative[0])
            return k, name, (f"{column[k]:.10g} is negative, but {name} is a distance driver's "
                             f"length |B - A| ({negative.size} negative value(s) in all); "
                             "give lengths >= 0")
    return None


def _table(values: InputValues, what: str, names: tuple[str, ...], times: Array) -> Array:
    """One of inputs, input_rates, input_accels as a finite (T, NU) float array."""
    size = (times.size, len(names))
    if isinstance(values, Mapping):
        unknown = sorted(set(values) - set(names))
        missing = [name for name in names if name not in values]
        if unknown or missing:
            raise SolveError(f"{what}: " + "; ".join(
                part for part in (f"no input driver named {', '.join(map(repr, unknown))}"
                                  if unknown else "",
                                  f"missing {', '.join(map(repr, missing))}" if missing else "")
                if part) + f" (the input drivers are {', '.join(names)})")
        columns = [_column(values[name], f"{what}[{name!r}]", times.size) for name in names]
        array = np.stack(columns, axis=1) if columns else np.zeros(size)
    else:
        try:
            array = np.array(values, dtype=float)
        except (TypeError, ValueError):
            raise SolveError(f"{what} must be numbers, an array of shape {size}") from None
        if array.ndim == 1 and len(names) == 1:
            array = array.reshape(-1, 1)
        if array.shape != size:
            raise SolveError(f"{what} must have shape {size} (time points, input drivers "
                             f"{', '.join(names)}), got {array.shape}")
    _finite(array, what, names, times)
    return np.ascontiguousarray(array)


def _column(values: ArrayLike, what: str, count: int) -> Array:
    try:
        column = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise SolveError(f"{what} must be numbers") from None
    if column.shape != (count,):
        raise SolveError(f"{what} must have shape ({count},) (one value per time point), got "
                         f"{column.shape}")
    return column


def _finite(array: Array, what: str, names: tuple[str, ...], times: Array) -> None:
    bad = np.argwhere(~np.isfinite(array))
    if bad.size:
        k, j = (int(v) for v in bad[0])
        raise SolveError(f"{what}: {names[j]} is {array[k, j]} at point {k} (t = "
                         f"{times[k]:.10g}); every input must be a finite number")


def solve_points(kernel: Any, run: Run, inputs: Inputs, q0: Array, p: Array,
                 options: Options, progress: Callable[[int, int], None] | None = None
                 ) -> tuple[Newton, Array, Assembly | None]:
    """Solve every point of the run from the last solution (the first assembled from q0);
    ``progress(done, total)`` after each point.

    Returns the outcome at the last point attempted (status OK when all are solved), the
    generated functions' p[] there and the assembly at the first point.
    """
    t0 = float(run.t[0])
    first_p = inputs.row(kernel, p, 0)
    assembly = assemble(kernel, q0, t0, first_p, options)
    if assembly.result.status != OK:
        return assembly.result, first_p, assembly
    # a solution of Phi = 0 with a revolute's axes reversed is no start (runtime.driver's too)
    refuse_reversed(kernel, run, assembly.result.q, t0, first_p, params=p)
    stepper = kernel.input_stepper()
    if stepper is not None:
        return (*_c_points(kernel, run, inputs, stepper, assembly.result, p, options,
                           progress), assembly)
    result, pu = _python_points(kernel, run, inputs, assembly.result, p, options, progress)
    return result, pu, assembly


def _python_points(kernel: Any, run: Run, inputs: Inputs, first: Newton, p: Array,
                   options: Options, progress: Callable[[int, int], None] | None
                   ) -> tuple[Newton, Array]:
    pu = inputs.row(kernel, p, 0)
    failed = _first_row(kernel, run, first, pu, options, inputs.rates, progress)
    if failed is not None:
        return failed, pu
    regular = 0  # the last row solved off a singular configuration: the next start
    for k in range(1, run.t.size):
        pu = inputs.row(kernel, p, k)
        kept, failed = _solve_row(kernel, run, *_from_row(run, regular), float(run.t[k]), pu,
                                  options, inputs.rates)
        if kept is None:
            return failed, pu
        if math.isfinite(kept.cond):  # (a kept singular row is no start for the next)
            regular = k
        _stored(run, k, kept, progress)
    return first, pu


def _first_row(kernel: Any, run: Run, first: Newton, pu: Array, options: Options, rates: int,
               progress: Callable[[int, int], None] | None) -> Newton | None:
    """Row 0 from the assembly's outcome (its q, dq and ddq there): stored, or the failure."""
    point = kinematics(kernel, first, float(run.t[0]), pu, options, rates)
    if point is None:
        return Newton(first.q, NOT_FINITE, first.iterations, first.residual, None)
    _stored(run, 0, _without_unknown_rates(point, rates), progress)
    return None


def _from_row(run: Run, k: int) -> tuple[Array, tuple[float, float, float]]:
    """What Newton starts a row from: row k's q and its max |q|, |dq|, |ddq| (NaN rows: rates
    not asked for, count as 0)."""
    nq, ndq, nddq = (float(np.nan_to_num(np.abs(v[k])).max(initial=0.0))
                     for v in (run.q, run.dq, run.d2q))
    return run.q[k].copy(), (nq, ndq, nddq)


def _solve_row(kernel: Any, run: Run, start: Array, norms: tuple[float, float, float],
               t: float, pu: Array, options: Options, rates: int
               ) -> tuple[Point | None, Newton]:
    """One row by the runtime's Newton from ``start`` (the last row solved off a singular
    configuration; norms: its max |q|, |dq|, |ddq|): the point to keep (a singular one too,
    _singular_row), or None and the failed outcome (q: Newton's own last iterate, where the
    failure is explained)."""
    result = newton(kernel, start, t, pu, options, norms)
    if result.status != OK:
        return _singular_row(kernel, run, result, t, pu, options), result
    point = kinematics(kernel, result, t, pu, options, rates)
    if point is None:
        return None, Newton(result.q, NOT_FINITE, result.iterations, result.residual, None)
    return _without_unknown_rates(point, rates), result


def _stored(run: Run, k: int, point: Point, progress: Callable[[int, int], None] | None
            ) -> None:
    run.store(k, point)
    if progress is not None:
        progress(run.done, run.t.size)


def _singular_row(kernel: Any, run: Run, failed: Newton, t: float, pu: Array,
                  options: Options) -> Point | None:
    """A row whose inputs put the mechanism in a singular configuration (an encoder's tick on a
    dead centre: Phi_q's condition over options.max_cond), or None for any other failure:
    Newton assembled it (its residual within tol_phi) and only Phi_q is singular. Its q
    stands; the inputs do not fix dq and ddq there (NaN), and the row is flagged, its condition
    infinite; the passage is recorded as a run over t records the singular configuration it
    passes. Before, such a row stopped the run, where the same motion driven by t passed it."""
    if failed.status != SINGULAR or not failed.residual <= options.tol_phi:
        return None
    rank_loss, groups = dependencies(np.asarray(kernel.phi_q(failed.q, t, pu), dtype=float),
                                     list(kernel.rows), rcond=1e-7)
    run.passages.append(Passage(t, rank_loss, groups))
    nan = np.full(failed.q.size, np.nan)
    return Point(failed.q, nan, nan, math.inf, True)


def _without_unknown_rates(point: Point, rates: int) -> Point:
    """dq (ddq) NaN where the rates (accelerations) of the inputs were not given."""
    if rates == 2:
        return point
    nan = np.full_like(point.dq, np.nan)
    return Point(point.q, point.dq if rates else nan, nan, point.cond, point.flagged)


def _c_points(kernel: Any, run: Run, inputs: Inputs, stepper: InputStepper, first: Newton,
              p: Array, options: Options, progress: Callable[[int, int], None] | None
              ) -> tuple[Newton, Array]:
    """Each row one call of the generated solve; a row it fails is solved again by the
    runtime's Newton as the NumPy backend solves every row (the C solve left its state at the
    last solution), so that both backends keep, flag or explain that row alike, and the C
    solve goes on from what that gave."""
    pu = inputs.row(kernel, p, 0)
    stepper.start(options, first.q)
    regular, earlier = 0, 0  # the restart row; the fall-backs of the solves before a restart
    for k in range(run.t.size):
        pu = inputs.row(kernel, p, k)
        outcome = stepper.step(float(run.t[k]), pu, inputs.rates)
        run.fallbacks = earlier + stepper.fallbacks
        if isinstance(outcome, Point):
            regular = k
            _stored(run, k, outcome, progress)
            continue
        if k == 0:  # from the assembly's outcome, as the NumPy backend takes it
            failure = _first_row(kernel, run, first, pu, options, inputs.rates, progress)
            if failure is not None:
                return failure, pu
        else:  # from the last row solved off a singular configuration
            kept, failed = _solve_row(kernel, run, *_from_row(run, regular), float(run.t[k]),
                                      pu, options, inputs.rates)
            if kept is None:
                return failed, pu
            if math.isfinite(kept.cond):
                regular = k
            _stored(run, k, kept, progress)
        earlier = run.fallbacks
        # From a singular q Newton would crawl (Phi_q singular at its start): after one the
        # C solve goes on from the last row solved off it.
        stepper.start(options, run.q[regular])
    return Newton(run.q[run.done - 1], OK, 0, 0.0, None), pu
