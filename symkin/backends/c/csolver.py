"""The generated C solver's grid loop, called through cffi (the C backend's
``runtime.protocol.GridSolver``): every C call of the runtime's time loop lives here, so the
driver sees plain NumPy arrays and a :class:`ChunkResult`.

The C solver keeps its state (the last q, dq, ddq and t) between calls, so a grid can be run
in chunks (for progress reports, interrupts) and continues exactly as one call would.

A solve of a short grid is dominated by what happens around the C call, so everything that
depends only on the kernel (the structs, the function lookups, the cffi type names) is done
once per :class:`GridSolver`, and a run's output arrays are bound once (:meth:`GridSolver.bind`)
and written by the C in place, chunk after chunk, through pointers offset by the chunk's start.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.contract.options import C_FIELDS, RULE_WORDS, RULES, Options
from symkin.errors import UsageError
from symkin.runtime.protocol import ChunkResult

Array = NDArray[np.float64]


def fill_options(lib: Any, name: str, target: Any, options: Options, unit: float = 1.0
                 ) -> None:
    """The C options struct ``target`` set from the runtime's Options and the length unit the
    decisions are made in (runtime.solving.units)."""
    getattr(lib, f"{name}_default_options")(target)
    target.tol_phi, target.tol_dq = options.tol_phi, options.tol_dq
    target.max_iterations = options.max_iterations
    target.min_pivot_ratio = options.min_pivot_ratio
    target.max_cond = options.max_cond
    target.tighten_cond = options.tighten_cond
    target.target_q, target.target_dq = options.target_q, options.target_dq
    target.target_ddq = options.target_ddq
    target.unit = unit
    refused = getattr(lib, f"{name}_check_options")(target)
    if refused:  # Options kept its rules; a float kernel can still round a value to 0 or inf
        field = C_FIELDS[refused - 1]
        raise UsageError(f"Options: {field} = {getattr(options, field, unit)!r} is "
                         f"{getattr(target, field)!r} in the kernel's real type, where it must "
                         f"be {RULE_WORDS[RULES[field]]}")


class GridSolver:
    """One run of the generated C grid loop: options, state, workspace and report structs.

    The structs are allocated once and a solver is reused run after run (:meth:`start`), so
    a short solve pays for no allocation; :class:`SolverPool` hands one to each run.
    """

    def __init__(self, ffi: Any, lib: Any, name: str, real: str, options: Options,
                 q: Array, p: Array, unit: float = 1.0) -> None:
        self._ffi, self._lib, self._name = ffi, lib, name
        self._options = ffi.new(f"{name}_options *")
        self._state = ffi.new(f"{name}_state *")
        # The solver initialises its workspace on the first step, so it is not zero-filled
        # here: with the sparse LU it holds an N x N dense fall-back buffer rarely touched.
        self._work = ffi.new_allocator(should_clear_after_alloc=False)(f"{name}_workspace *")
        self._report = ffi.new(f"{name}_report *")
        self._p = ffi.new(f"{name}_real[]", max(p.size, 1))
        self._n, self._np = q.size, p.size
        self._solve_grid = getattr(lib, f"{name}_solve_grid_checked")
        # inverse dynamics: the grid loop then takes lam_out and loads_out too
        self._dynamics = hasattr(lib, f"{name}_multipliers")
        self._points = getattr(lib, f"{name}_points")
        # The lever arms the start check reads (runtime.solving.start): at the run's first
        # guess from <prefix>_length_scales on the structs as they are, at its first row from
        # the report (None: a kernel built before them).
        self._length_scales = getattr(lib, f"{name}_length_scales", None)
        if getattr(lib, f"{name.upper()}_NPU", p.size) != p.size:  # it reads the inputs too
            self._length_scales = None
        self._scale = ffi.new(f"{name}_real[1]")
        self._state_q = self._state.q  # a field's cdata is made anew on each access
        self._reports_lever_arm = "lever_arm" in dict(ffi.typeof(f"{name}_report").fields)
        # The cffi types parsed once: from_buffer given a type's text parses it on every
        # call, about a fifth of the cost of the call (six of them bind each run).
        self._real_array = ffi.typeof(f"{name}_real[]")
        self._bytes_array = ffi.typeof("unsigned char[]")
        self.dtype = np.float32 if real == "float" else np.float64
        # The bytes of q and p in the real type: they are copied into the structs as they are.
        self._q_bytes = q.size * np.dtype(self.dtype).itemsize
        self._p_bytes = p.size * np.dtype(self.dtype).itemsize
        self._set_options: tuple[Options, float] | None = None
        self._double = self.dtype is np.float64  # outputs written in place (bind)
        self._pointers: tuple[Any, ...] | None = None  # of the run's arrays (bind)
        self._size = 0  # their time points
        # (float64 target, buffer of the real type) pairs, for a float kernel only.
        self._copies: list[tuple[NDArray[Any], NDArray[Any]]] | None = None
        self.pool: SolverPool | None = None
        self.start(options, q, p, unit)

    def start(self, options: Options, q: Array, p: Array, unit: float = 1.0) -> GridSolver:
        """Begin a new run from q with parameters p, its decisions made in the length unit
        ``unit`` (the state is reset, not reallocated)."""
        if self._set_options is None or options is not self._set_options[0] \
                or unit != self._set_options[1]:
            fill_options(self._lib, self._name, self._options, options, unit)
            self._set_options = (options, unit)
        if p.size != self._np or q.size != self._n:
            raise ValueError(f"expected {self._n} coordinates and {self._np} parameters, got "
                             f"{q.size} and {p.size}")
        # Copied as bytes in the real type: no Python list of floats on the way.
        memmove, dtype = self._ffi.memmove, self.dtype
        memmove(self._p, np.ascontiguousarray(p, dtype=dtype), self._p_bytes)
        memmove(self._state_q, np.ascontiguousarray(q, dtype=dtype), self._q_bytes)
        self._state.started = 0
        return self

    def release(self) -> None:
        """Forget the run's arrays and hand the solver back to its pool (if it has one)."""
        self._pointers = self._copies = None
        pool = self.pool  # the pool's own bookkeeping, here: one call less per solve
        if pool is not None and len(pool.idle) < pool.KEEP:
            pool.idle.append(self)

    def bind(self, times: Array, q_out: Array, dq_out: Array, d2q_out: Array,
             cond_out: Array, flagged_out: NDArray[np.bool_],
             forces_out: tuple[Array, Array] | None = None) -> None:
        """The run's arrays: the grid and the rows :meth:`advance` writes.

        The time points (T,), the float64 outputs q, dq, d2q (T, N) and cond (T,) and the bool
        flags (T,) must be C-contiguous (the driver allocates or checks them; the sizes are
        checked here). A double kernel writes them in place, a float kernel through buffers
        of its real type copied over after each call.
        """
        size = times.size
        if not (q_out.size == dq_out.size == d2q_out.size == size * self._n
                and cond_out.size == flagged_out.size == size):
            raise ValueError(f"GridSolver.bind: arrays of {size} points x {self._n} expected")
        buffers: tuple[NDArray[Any], ...] = (q_out, dq_out, d2q_out, cond_out)
        if self._dynamics or not self._double:
            buffers = self._buffers(buffers, forces_out)
            if not self._double:
                times = np.ascontiguousarray(times, dtype=self.dtype)
        # cffi keeps each array alive for as long as its pointer lives.
        from_buffer, real = self._ffi.from_buffer, self._real_array
        self._size = size
        self._pointers = (from_buffer(real, times), from_buffer(real, buffers[0]),
                          from_buffer(real, buffers[1]), from_buffer(real, buffers[2]),
                          from_buffer(real, buffers[3]),
                          from_buffer(self._bytes_array, flagged_out))
        self._forces: tuple[Any, ...] = ()
        if self._dynamics:  # NULL: the loop skips them
            self._forces = tuple(
                (from_buffer(real, b) if b.size else self._ffi.NULL, b.shape[1])
                for b in buffers[4:6]) or ((self._ffi.NULL, 0), (self._ffi.NULL, 0))

    def _buffers(self, outputs: tuple[NDArray[Any], ...],
                 forces_out: tuple[Array, Array] | None) -> tuple[NDArray[Any], ...]:
        """What the C writes for ``outputs`` (with lam (T, N) and loads (T, NLOADS) of a
        dynamics kernel): the arrays themselves for a double kernel, else buffers of its
        real type copied over after each call (``_copies``)."""
        if self._dynamics and forces_out is not None:
            outputs += forces_out
        if self._double:
            return outputs
        buffers = tuple(np.empty(a.shape, dtype=self.dtype) for a in outputs)
        self._copies = list(zip(outputs, buffers))
        return buffers

    def advance(self, start: int, stop: int) -> int:
        """Solve the bound grid's points start..stop-1 (after those already solved, which
        the state continues from); returns how many were solved. :meth:`status` and
        :meth:`outcome` say why it stopped short."""
        if self._pointers is None or not 0 <= start < stop <= self._size:
            raise ValueError(f"GridSolver.advance({start}, {stop}) outside the bound grid")
        t, q, dq, d2q, cond, flagged = self._pointers
        if start:  # a later chunk: the pointers moved on to its first row
            rows = start * self._n
            t, q, dq, d2q = t + start, q + rows, dq + rows, d2q + rows
            cond, flagged = cond + start, flagged + start
        if self._forces:  # inverse dynamics: lam_out and loads_out too
            forces = tuple(pointer + start * width if start and width else pointer
                           for pointer, width in self._forces)
            solved: int = self._solve_grid(self._options, self._p, stop - start, t,
                                           self._state, q, dq, d2q, cond, flagged, *forces,
                                           self._work, self._report)
        else:  # a call without a star: the arguments are not gathered into a tuple first
            solved = self._solve_grid(self._options, self._p, stop - start, t, self._state,
                                      q, dq, d2q, cond, flagged, self._work, self._report)
        if self._copies is not None:
            for target, source in self._copies:
                target[start:start + solved] = source[start:start + solved]
        return solved

    @property
    def status(self) -> int:
        """newton.OK, NO_CONVERGENCE, SINGULAR or NOT_FINITE at the last point attempted."""
        return int(self._report.status)

    @property
    def fallbacks(self) -> int:
        """The sparse LU's fall-backs to dense LU since :meth:`start`."""
        return int(self._report.fallbacks)

    def start_lever_arm(self, t: float) -> float | None:
        """The length scale at the q and p the run was started with, at time t, raw as
        ``<prefix>_length_scales`` gives it (0: no lever arm; NaN: Phi_q not finite there);
        None for a kernel without that function."""
        if self._length_scales is None:
            return None
        self._length_scales(1, self._p, self._state_q, 0, t, self._scale)
        return float(self._scale[0])

    @property
    def first_lever_arm(self) -> float | None:
        """The length scale at the run's first row as the call that solved it reported it,
        raw as :meth:`start_lever_arm` (NaN: no row solved); None for a kernel built before
        the report had it. Valid once a call has solved the first row."""
        return float(self._report.lever_arm) if self._reports_lever_arm else None

    def outcome(self, solved: int) -> ChunkResult:
        """The last call's report, with the count it returned."""
        report = self._report
        return ChunkResult(solved, int(report.status), float(report.t),
                           int(report.iterations), float(report.residual),
                           int(report.fallbacks))

    def point_vectors(self, count: int, size: int = 2) -> Array:
        """The local vectors of the ``count`` named points at the run's parameters,
        (count, size): size 3 in a spatial mechanism."""
        out = np.empty((count, size), dtype=self.dtype)
        if count:
            self._points(self._p, self._ffi.from_buffer(self._real_array, out))
        return out if self.dtype is np.float64 else out.astype(np.float64)

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
        self.idle: list[GridSolver] = []

    KEEP = 8
    """Idle solvers kept at most."""

    def take(self, options: Options, q: Array, p: Array, unit: float = 1.0) -> GridSolver:
        try:
            solver = self.idle.pop()  # atomic under the GIL
        except IndexError:
            solver = GridSolver(*self._arguments, options, q, p, unit)
            solver.pool = self
            return solver
        return solver.start(options, q, p, unit)
