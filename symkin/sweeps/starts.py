"""The unit and the start of every set of a sweep, decided as ``symkin.solve`` decides them
(runtime.solving.units, runtime.solving.start) without a Python call per set.

The unit: the generated ``<prefix>_length_scales`` gives each set's length scale at its first
guess in one C call, and runtime.solving.units.units_for turns them into units; the C batch then
solves each set in its own unit (a mechanism drawn in millimetres stays in the C loop).

The start: symkin.solve refuses to step from a singular or limit configuration at t0 (runtime.
start: the condition of Phi_q in units of the mechanism's length scale L above
start_threshold). The batch reports the condition estimate of Phi_q at each set's first row
in the set's unit u; Phi_q in units of L differs from it by the diagonal scalings of the
length columns and rows by s = L / u, which change the 1-norm condition by at most
max(s, 1/s)^2. A set whose estimate, so bounded and times SAFETY (the estimator's lower
bound can fall short of the true norm), stays under the threshold cannot be a singular start;
only the others, few where a sweep does not start near a singular position, are checked by
runtime.solving.start itself on their first row, in the set's unit as symkin.solve checks it.

The senses: a first row that solves Phi = 0 with a spatial revolute's axes reversed (or an
angle driver half a turn away) is no assembly (runtime.solving.assembly); symkin.solve refuses to
run from it. Only kernels with senses (spatial files) pay a call per set for that check; such a
set is handed to symkin.solve, which searches further or stops with "no assembly".
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import Options
from symkin.runtime.protocol import BatchSolver, KinematicsKernel
from symkin.runtime.solving.assembly import reversed_senses
from symkin.runtime.solving.start import SAFETY, singular_start, start_threshold
from symkin.runtime.solving.units import ScaledKernel, units_for

Array = NDArray[np.float64]

def set_units(batch: BatchSolver, params: Array, t0: float, q0: Array) -> Array:
    """The unit each set is solved in (runtime.solving.units.unit_for at its first guess q0, (N,) or
    (m, N))."""
    return units_for(batch.length_scales(params, q0, t0))


def singular_starts(kernel: KinematicsKernel, batch: BatchSolver, params: Array, t0: float,
                    first: Array, rows: NDArray[np.integer], start_cond: Array, units: Array,
                    options: Options) -> NDArray[np.bool_]:
    """Per set, whether its first row ``first[j]`` (where the batch solved ``rows[j]`` > 0
    rows) is a singular or limit configuration, as symkin.solve judges it."""
    singular = np.zeros(params.shape[0], dtype=bool)
    solved = np.flatnonzero(rows > 0)
    if solved.size == 0:
        return singular
    scales = batch.length_scales(params[solved], first[solved], t0)
    unit = units[solved]
    with np.errstate(all="ignore"):
        ratio = np.where(scales > 0, scales / unit, 1.0)  # no lever arm: Phi_q as it is
        bound = start_cond[solved] * np.maximum(ratio, 1.0 / ratio) ** 2
        threshold = start_threshold(options, len(kernel.coordinates))
        clear = np.isfinite(scales) & (bound * SAFETY <= threshold)
    for j in solved[~clear]:
        with np.errstate(all="ignore"):
            if units[j] == 1.0:
                found = singular_start(kernel, first[j], t0, params[j], options)
            else:
                view = ScaledKernel(kernel, float(units[j]))
                found = singular_start(view, first[j] / view.column, t0, params[j], options)
        singular[j] = found is not None
    return singular


def reversed_starts(kernel: KinematicsKernel, params: Array, t0: float, first: Array,
                    rows: NDArray[np.integer]) -> NDArray[np.bool_]:
    """Per set, whether its first row ``first[j]`` (where the batch solved ``rows[j]`` > 0
    rows) solves Phi = 0 where a sense is not positive: no assembly, as symkin.solve judges
    it (the senses hold no lengths: the set's unit does not matter)."""
    found = np.zeros(params.shape[0], dtype=bool)
    if not getattr(kernel, "senses", ()):
        return found
    for j in np.flatnonzero(rows > 0):
        found[j] = bool(reversed_senses(kernel, first[j], t0, params[j]))
    return found
