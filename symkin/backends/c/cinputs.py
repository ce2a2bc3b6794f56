"""The generated C ``<prefix>_solve_inputs`` called through cffi, one time point a call
(the C backend's ``runtime.input_driven.inputs.InputStepper``): the state is carried in C from point
to point, so each point starts from the last solution as in a controller loop."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.backends.c.csolver import fill_options
from symkin.contract.options import Options
from symkin.contract.status import OK
from symkin.runtime.solving.newton import Newton, Point

Array = NDArray[np.float64]


class InputStepper:
    """Options, state, workspace and report structs of one input-driven run."""

    def __init__(self, ffi: Any, lib: Any, name: str, real: str, nq: int) -> None:
        self._ffi, self._lib, self._name, self._n = ffi, lib, name, nq
        self._options = ffi.new(f"{name}_options *")
        self._state = ffi.new(f"{name}_state *")
        self._work = ffi.new(f"{name}_workspace *")
        self._report = ffi.new(f"{name}_report *")
        self._solve = getattr(lib, f"{name}_solve_inputs")
        self._real = f"{name}_real[]"
        self._dtype = np.float32 if real == "float" else np.float64
        self._np = int(getattr(lib, f"{name.upper()}_NP"))
        self._nu = int(getattr(lib, f"{name.upper()}_NU"))
        self.fallbacks = 0
        # the last call's report.branch_jump (runtime.input_driven.branch's tests)
        self.branch_jump = False

    def start(self, options: Options, q: Array, unit: float = 1.0) -> None:
        """Begin from q (in the kernel's unit), the decisions made in the length unit ``unit``
        (runtime.solving.units): the first call initialises the workspace."""
        fill_options(self._lib, self._name, self._options, options, unit)
        self._state.q[0:self._n] = [float(v) for v in q]
        self._state.started = 0
        self.fallbacks = 0
        self.branch_jump = False

    def step(self, t: float, pu: Array, rates: int) -> Point | Newton:
        """One call of solve_inputs at time t with p[] = pu (parameters, u, du, ddu)."""
        np_, nu = self._np, self._nu
        values = np.ascontiguousarray(pu, dtype=self._dtype)
        buffer = self._ffi.from_buffer(self._real, values)
        u = buffer + np_
        du = buffer + np_ + nu if rates >= 1 else self._ffi.NULL
        ddu = buffer + np_ + 2 * nu if rates >= 2 else self._ffi.NULL
        self._state.t = t
        status = self._solve(self._options, buffer, u, du, ddu, self._state, self._work,
                             self._report)
        report = self._report
        self.fallbacks = int(report.fallbacks)
        self.branch_jump = bool(report.branch_jump)
        q = np.array(self._ffi.unpack(self._state.q, self._n), dtype=float)
        if status != OK:
            return Newton(q, int(status), int(report.iterations), float(report.residual), None)
        dq, ddq = (np.array(self._ffi.unpack(v, self._n), dtype=float)
                   for v in (self._state.dq, self._state.ddq))
        return Point(q, dq, ddq, float(report.cond), bool(report.flagged))
