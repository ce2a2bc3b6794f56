"""The generated ``<prefix>_solve_batch`` called through cffi: many parameter sets in one C
call (the C backend's ``runtime.protocol.BatchSolver``, used by ``sweeps.batch``).

The C batch runs plain Newton from q0 at t[0] per set, like the first attempt of
``symkin.solve``; a set it reports as failed goes on in ``sweeps.stops`` (the generated
``<prefix>_solve_edge``) or is re-run through ``symkin.solve``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin.backends.c.csolver import fill_options
from symkin.contract.options import Options
from symkin.runtime.protocol import BatchStatus

Array = NDArray[np.float64]


def solve(ffi: Any, lib: Any, name: str, real: str, params: Array, t: Array, q0: Array,
          options: Options, rows: tuple[Array, Array, Array], units: Array) -> BatchStatus:
    """Run ``<prefix>_solve_batch`` over all sets into ``rows`` = (q, dq, d2q), each
    (m, T, N) float64, set j decided in the length unit ``units[j]``; returns (status,
    iterations, solved, cond, start_cond) per set."""
    dtype = np.float32 if real == "float" else np.float64
    m = params.shape[0]
    direct = dtype == np.float64
    outputs = rows if direct else tuple(np.empty(rows[0].shape, dtype=dtype) for _ in range(3))
    inputs = [np.ascontiguousarray(a, dtype=dtype) for a in (params, q0, t, units)]
    pointer = f"{name}_real *"
    pointers = [ffi.cast(pointer, ffi.from_buffer(a)) if a.size else ffi.NULL
                for a in (*inputs, *outputs)]
    c_options = _options(ffi, lib, name, options)
    state = ffi.new(f"{name}_state *")
    work = ffi.new_allocator(should_clear_after_alloc=False)(f"{name}_workspace *")
    reports = ffi.new(f"{name}_batch_report[]", max(m, 1))
    stride = rows[0].shape[2] if q0.ndim == 2 else 0
    getattr(lib, f"{name}_solve_batch")(
        c_options, pointers[3], m, pointers[0], pointers[1], stride, t.size, pointers[2],
        pointers[4], pointers[5], pointers[6], state, work, reports)
    if not direct:
        for target, source in zip(rows, outputs):
            target[...] = source
    status = np.frombuffer(ffi.buffer(reports, m * ffi.sizeof(f"{name}_batch_report")),
                           dtype=_report_dtype(ffi, name))
    found: BatchStatus = (status["status"].astype(np.int32), status["iterations"].astype(np.int32),
                          status["solved"].astype(np.int32), status["cond"].astype(np.float64),
                          status["start_cond"].astype(np.float64))
    return found


def length_scales(ffi: Any, lib: Any, name: str, real: str, params: Array, q: Array,
                  t: float) -> Array:
    """``<prefix>_length_scales``: per set the largest lever arm in Phi_q at its parameters
    ``params`` (m, NP) and coordinates ``q`` ((N,) for every set, or (m, N); any strides),
    at time t."""
    dtype = np.float32 if real == "float" else np.float64
    m = params.shape[0]
    if m == 0:
        return np.empty(0)
    table = np.ascontiguousarray(params, dtype=dtype)
    rows = np.ascontiguousarray(q, dtype=dtype)
    scales = np.empty(m, dtype=dtype)
    pointer = f"{name}_real *"
    p, q_rows = (ffi.cast(pointer, ffi.from_buffer(a)) if a.size else ffi.NULL
                 for a in (table, rows))
    getattr(lib, f"{name}_length_scales")(m, p, q_rows, rows.shape[-1] if rows.ndim == 2 else 0,
                                          t, ffi.cast(pointer, ffi.from_buffer(scales)))
    return scales.astype(np.float64, copy=False)


def _report_dtype(ffi: Any, name: str) -> np.dtype[Any]:
    """The NumPy view of ``<prefix>_batch_report`` (offsets from cffi, not assumed)."""
    struct = f"{name}_batch_report"
    real = np.float32 if ffi.sizeof(f"{name}_real") == 4 else np.float64
    fields = {"status": np.int32, "solved": np.int32, "t": real, "iterations": np.int32,
              "residual": real, "cond": real, "start_cond": real}
    return np.dtype({"names": list(fields), "formats": list(fields.values()),
                     "offsets": [ffi.offsetof(struct, f) for f in fields],
                     "itemsize": ffi.sizeof(struct)})


def _options(ffi: Any, lib: Any, name: str, options: Options) -> Any:
    """The C options struct from every field of ``options`` (each set's unit is passed apart,
    in ``units``). Before, only the Newton tolerances were copied and the batch ran with the
    default max_cond, tighten_cond and targets whatever the caller gave."""
    c_options = ffi.new(f"{name}_options *")
    fill_options(lib, name, c_options, options)
    return c_options


class Batch:
    """The C backend's ``runtime.protocol.BatchSolver``: ``<prefix>_solve_batch`` and
    ``<prefix>_length_scales`` of one extension."""

    def __init__(self, ffi: Any, lib: Any, name: str, real: str, scale_free: bool) -> None:
        self._c = (ffi, lib, name, real)
        self.scale_free = scale_free
        # Looked up once: symkin.solve asks for a length scale or two on every call
        # (runtime.solving.start.lever_arm), where the lookups cost more than the C.
        self._length_scales = getattr(lib, f"{name}_length_scales")
        # parsed once (from_buffer given the type's text parses it on every call)
        self._real_array = ffi.typeof(f"{name}_real[]") if real == "double" else None

    def __call__(self, params: Array, t: Array, q0: Array, options: Options, q: Array,
                 dq: Array, d2q: Array, units: Array) -> BatchStatus:
        return solve(*self._c, params, t, q0, options, (q, dq, d2q), units)

    def length_scales(self, params: Array, q: Array, t: float) -> Array:
        if self._real_array is None or params.shape[0] != 1 or q.ndim != 1:
            return length_scales(*self._c, params, q, t)
        # One set in double (a solve's unit or start check): the arrays as they are.
        ffi, real = self._c[0], self._real_array
        table = np.ascontiguousarray(params, dtype=np.float64)
        rows = np.ascontiguousarray(q, dtype=np.float64)
        scales = np.empty(1)
        self._length_scales(1, ffi.from_buffer(real, table) if table.size else ffi.NULL,
                            ffi.from_buffer(real, rows) if rows.size else ffi.NULL, 0, t,
                            ffi.from_buffer(real, scales))
        return scales
