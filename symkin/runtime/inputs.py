"""Runs driven by inputs: drivers whose functions are ``input`` take their values, rates and
accelerations from the caller at each time point (sensors, encoders), not from a formula in t.

Each point is solved from the last solution, without a Taylor prediction (the inputs say where
the mechanism is): Newton at the inputs, then dq (2.73) with Phi_t holding the rates and ddq
(2.74) with Gamma holding the accelerations. Rates not given leave dq (and ddq) NaN: a
position-only run never pretends to know them. A C kernel solves each point in its generated
``<prefix>_solve_inputs``; any other kernel through the runtime's Newton. Imports NumPy only.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from symkin.contract.options import Options
from symkin.contract.status import NOT_FINITE, OK
from symkin.errors import SolveError
from symkin.runtime.assembly import Assembly, assemble
from symkin.runtime.newton import Newton, Point, kinematics, newton
from symkin.runtime.result_arrays import Run

Array = NDArray[np.float64]
InputValues = Mapping[str, ArrayLike] | ArrayLike


class InputStepper(Protocol):
    """A backend's generated one-point solve at given inputs (the C ``solve_inputs``)."""

    fallbacks: int
    """The sparse LU's fall-backs to dense LU since start."""

    branch_jump: bool
    """Whether the last step's solution may lie on another assembly than the step before's
    (the generated solve's own form of runtime.branch's tests)."""

    def start(self, options: Options, q: Array) -> None:
        """Begin from q (the assembled first point)."""

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
    return Inputs(*(None if values is None else _table(values, what, names, times)
                    for values, what in ((inputs, "inputs"), (rates, "input_rates"),
                                         (accels, "input_accels"))))  # type: ignore[arg-type]


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
        options: Options) -> tuple[Newton, Array, Assembly | None]:
    """Solve every point of the run from the last solution (the first assembled from q0).

    Returns the outcome at the last point attempted (status OK when all are solved), the
    generated functions' p[] there and the assembly at the first point.
    """
    t0 = float(run.t[0])
    first_p = inputs.row(kernel, p, 0)
    assembly = assemble(kernel, q0, t0, first_p, options)
    if assembly.result.status != OK:
        return assembly.result, first_p, assembly
    stepper = kernel.input_stepper()
    if stepper is not None:
        return (*_c_points(kernel, run, inputs, stepper, assembly.result.q, p, options),
                assembly)
    result, pu = _python_points(kernel, run, inputs, assembly.result, p, options)
    return result, pu, assembly


def _python_points(kernel: Any, run: Run, inputs: Inputs, first: Newton, p: Array,
                   options: Options) -> tuple[Newton, Array]:
    result, pu = first, inputs.row(kernel, p, 0)
    for k in range(run.t.size):
        t, pu = float(run.t[k]), inputs.row(kernel, p, k)
        if k > 0:
            nq, ndq, nddq = (float(np.nan_to_num(np.abs(v[k - 1])).max(initial=0.0))
                             for v in (run.q, run.dq, run.d2q))  # NaN: not asked for
            result = newton(kernel, run.q[k - 1].copy(), t, pu, options, (nq, ndq, nddq))
            if result.status != OK:
                return result, pu
        point = kinematics(kernel, result, t, pu, options)
        if point is None:
            return Newton(result.q, NOT_FINITE, result.iterations, result.residual, None), pu
        run.store(k, _without_unknown_rates(point, inputs.rates))
    return result, pu


def _without_unknown_rates(point: Point, rates: int) -> Point:
    """dq (ddq) NaN where the rates (accelerations) of the inputs were not given."""
    if rates == 2:
        return point
    nan = np.full_like(point.dq, np.nan)
    return Point(point.q, point.dq if rates else nan, nan, point.cond, point.flagged)


def _c_points(kernel: Any, run: Run, inputs: Inputs, stepper: InputStepper, q: Array,
              p: Array, options: Options) -> tuple[Newton, Array]:
    pu = inputs.row(kernel, p, 0)
    stepper.start(options, q)
    for k in range(run.t.size):
        pu = inputs.row(kernel, p, k)
        outcome = stepper.step(float(run.t[k]), pu, inputs.rates)
        run.fallbacks = stepper.fallbacks
        if isinstance(outcome, Newton):
            return outcome, pu
        run.store(k, outcome)
    return Newton(run.q[run.done - 1], OK, 0, 0.0, None), pu
