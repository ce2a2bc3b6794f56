"""The generated C solver's grid loop, called through cffi: every C call of the runtime's
time loop lives here, so the driver sees plain NumPy arrays and a :class:`ChunkResult`.

The C solver keeps its state (the last q, dq, ddq and t) between calls, so a grid can be run
in chunks (for progress reports, interrupts) and continues exactly as one call would.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.runtime.options import Options

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ChunkResult:
    """What one call of ``<prefix>_solve_grid`` reports.

    Attributes:
        solved: how many time points of the chunk were solved.
        status: newton.OK, NO_CONVERGENCE or SINGULAR at the last point attempted.
        t: the time of that point.
        iterations, residual: Newton's count and max |Phi| there.
        fallbacks: the sparse LU's fall-backs to dense LU so far (0 for the dense LU).
    """

    solved: int
    status: int
    t: float
    iterations: int
    residual: float
    fallbacks: int


class GridSolver:
    """One run of the generated C grid loop: options, state, workspace and report structs.

    The structs are allocated once and a solver is reused run after run (:meth:`start`), so
    a short solve pays for no allocation; :class:`SolverPool` hands one to each run.
    """

    def __init__(self, ffi: Any, lib: Any, name: str, real: str, options: Options,
                 q: Array, p: Array) -> None:
        self._ffi, self._lib, self._name = ffi, lib, name
        self._options = ffi.new(f"{name}_options *")
        self._state = ffi.new(f"{name}_state *")
        # The solver initialises its workspace on the first step, so it is not zero-filled
        # here: with the sparse LU it holds an N x N dense fall-back buffer rarely touched.
        self._work = ffi.new_allocator(should_clear_after_alloc=False)(f"{name}_workspace *")
        self._report = ffi.new(f"{name}_report *")
        self._p = ffi.new(f"{name}_real[]", max(p.size, 1))
        self._n = q.size
        self._solve_grid = getattr(lib, f"{name}_solve_grid_checked")
        self._real_pointer = f"{name}_real[]"
        self.dtype = np.float32 if real == "float" else np.float64
        self._set_options: Options | None = None
        self.pool: SolverPool | None = None
        self.start(options, q, p)

    def start(self, options: Options, q: Array, p: Array) -> GridSolver:
        """Begin a new run from q with parameters p (the state is reset, not reallocated)."""
        if options is not self._set_options:
            getattr(self._lib, f"{self._name}_default_options")(self._options)
            self._options.tol_phi, self._options.tol_dq = options.tol_phi, options.tol_dq
            self._options.max_iterations = options.max_iterations
            self._options.min_pivot_ratio = options.min_pivot_ratio
            self._options.max_cond = options.max_cond
            self._options.tighten_cond = options.tighten_cond
            self._options.target_q, self._options.target_dq = options.target_q, options.target_dq
            self._options.target_ddq = options.target_ddq
            self._set_options = options
        self._p[0:p.size] = p.tolist()
        self._state.q[0:q.size] = q.tolist()
        self._state.started = 0
        return self

    def release(self) -> None:
        """Hand the solver back to its pool for the next run (no-op outside a pool)."""
        if self.pool is not None:
            self.pool.put(self)

    def solve(self, times: Array, q_out: Array, dq_out: Array, d2q_out: Array,
              cond_out: Array, flagged_out: NDArray[np.bool_]) -> ChunkResult:
        """Solve the grid points ``times`` after those already solved, writing their rows,
        the condition estimate and the flag of each point.

        The output arrays are written in place when they are C-contiguous arrays of the
        kernel's real type (the flags: of bool); otherwise the rows are copied in after.
        """
        chunk = np.ascontiguousarray(times, dtype=self.dtype)
        outputs = (q_out, dq_out, d2q_out, cond_out)
        direct = all(a.dtype == self.dtype and a.flags.c_contiguous for a in outputs)
        buffers = outputs if direct else tuple(np.zeros((chunk.size, *a.shape[1:]),
                                                        dtype=self.dtype) for a in outputs)
        flags = flagged_out if flagged_out.dtype == np.bool_ and \
            flagged_out.flags.c_contiguous else np.zeros(chunk.size, dtype=np.bool_)
        pointers = [self._ffi.from_buffer(self._real_pointer, a) for a in (chunk, *buffers)]
        flag_pointer = self._ffi.from_buffer("unsigned char[]", flags)
        solved = self._solve_grid(self._options, self._p, chunk.size, pointers[0], self._state,
                                  pointers[1], pointers[2], pointers[3], pointers[4],
                                  flag_pointer, self._work, self._report)
        if not direct:
            for target, source in zip(outputs, buffers):
                target[:solved] = source[:solved]
        if flags is not flagged_out:
            flagged_out[:solved] = flags[:solved]
        report = self._report
        return ChunkResult(int(solved), int(report.status), float(report.t),
                           int(report.iterations), float(report.residual),
                           int(report.fallbacks))

    def set_state(self, t: float, q: Array, dq: Array, ddq: Array) -> None:
        """Continue from a point solved elsewhere (the driver's treatment of a singular point):
        the next step predicts from it. Only after a first step (the workspace is set up)."""
        n = self._n
        self._state.q[0:n], self._state.dq[0:n] = q.tolist(), dq.tolist()
        self._state.ddq[0:n] = ddq.tolist()
        self._state.t = t
        self._state.started = 1

    def last_q(self) -> Array:
        """The solver's current q: the last converged point, or the failed iterate."""
        return np.array(self._ffi.unpack(self._state.q, self._n), dtype=float)


class SolverPool:
    """Idle GridSolvers of one kernel, so that the per-run structs are allocated once.

    A solver is taken for one run and put back after it; concurrent runs (threads, or a solve
    inside a progress callback) each take their own, so sharing a kernel stays safe.
    """

    def __init__(self, ffi: Any, lib: Any, name: str, real: str) -> None:
        self._arguments = (ffi, lib, name, real)
        self._idle: list[GridSolver] = []

    def take(self, options: Options, q: Array, p: Array) -> GridSolver:
        try:
            solver = self._idle.pop()  # atomic under the GIL
        except IndexError:
            solver = GridSolver(*self._arguments, options, q, p)
            solver.pool = self
            return solver
        return solver.start(options, q, p)

    def put(self, solver: GridSolver) -> None:
        if len(self._idle) < 8:
            self._idle.append(solver)
