"""The generated C ``<prefix>_dynamics_step`` called through cffi: the state is carried in C
from step to step, as in a controller loop, and each step's result copied out.

Present only in a kernel of a file with masses (backends/c/templates/dynamics.*.j2);
:func:`available` says whether a loaded kernel has it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.backends.c.csolver import fill_options
from symkin.contract.options import Options
from symkin.contract.status import OK

Array = NDArray[np.float64]


def available(lib: Any, name: str) -> bool:
    """Whether the loaded C library has the dynamics step."""
    return hasattr(lib, f"{name}_dynamics_step")


@dataclass(frozen=True)
class Motion:
    """Rows of a run of fixed steps: t (T,), q, dq, ddq (T, NQ), lam (T, NR); ``status`` of
    the step that ended the run (OK when all were taken); each step's report residuals;
    ``fallbacks``: the factorizations of the run that took the dense path."""

    t: Array
    q: Array
    dq: Array
    ddq: Array
    lam: Array
    status: int
    residual: Array
    velocity_residual: Array
    fallbacks: int = 0


class DynamicsStepper:
    """Options, state, work and report structs of one forward-dynamics run."""

    def __init__(self, ffi: Any, lib: Any, name: str, real: str) -> None:
        self._ffi, self._lib, self._name = ffi, lib, name
        self._n = int(getattr(lib, f"{name.upper()}_NQ"))
        self._nr = int(getattr(lib, f"{name.upper()}_NR"))
        self._options = ffi.new(f"{name}_options *")
        self._state = ffi.new(f"{name}_dynamics_state *")
        self._work = ffi.new(f"{name}_dynamics_work *")
        self._report = ffi.new(f"{name}_dynamics_report *")
        self._step = getattr(lib, f"{name}_dynamics_step")
        self._real = f"{name}_real[]"
        self._dtype = np.float32 if real == "float" else np.float64

    def run(self, options: Options, p: Array, t0: float, q0: Array, dq0: Array, h: float,
            steps: int) -> Motion:
        """``steps`` calls of the step from (t0, q0, dq0): one row after each step taken
        (the start is not a row); the run ends early at a step that fails."""
        fill_options(self._lib, self._name, self._options, options)
        state = self._state
        state.q[0:self._n] = [float(v) for v in q0]
        state.dq[0:self._n] = [float(v) for v in dq0]
        state.t, state.started = t0, 0
        values = np.ascontiguousarray(p, dtype=self._dtype)
        buffer = self._ffi.from_buffer(self._real, values) if values.size else self._ffi.NULL
        rows: list[tuple[Any, ...]] = []
        status, fallbacks = OK, 0
        for _ in range(steps):
            status = int(self._step(self._options, buffer, h, state, self._work,
                                    self._report))
            fallbacks += int(self._report.fallbacks)
            if status != OK:
                break
            rows.append(self._row())
        columns = [np.array([row[k] for row in rows], dtype=float) for k in range(7)]
        shapes = (0,), (0, self._n), (0, self._n), (0, self._n), (0, self._nr), (0,), (0,)
        t, q, dq, ddq, lam, residual, velocity = (
            column if rows else np.zeros(shape) for column, shape in zip(columns, shapes))
        return Motion(t=t, q=q, dq=dq, ddq=ddq, lam=lam, status=status, residual=residual,
                      velocity_residual=velocity, fallbacks=fallbacks)

    def _row(self) -> tuple[Any, ...]:
        state, unpack, report = self._state, self._ffi.unpack, self._report
        return (float(state.t), unpack(state.q, self._n), unpack(state.dq, self._n),
                unpack(state.ddq, self._n), unpack(state.lam, self._nr),
                float(report.residual), float(report.velocity_residual))
