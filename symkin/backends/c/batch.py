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

from symkin.contract.options import Options
from symkin.runtime.protocol import BatchStatus

Array = NDArray[np.float64]


def solve(ffi: Any, lib: Any, name: str, real: str, params: Array, t: Array, q0: Array,
          options: Options, rows: tuple[Array, Array, Array]) -> BatchStatus:
    """Run ``<prefix>_solve_batch`` over all sets into ``rows`` = (q, dq, d2q), each
    (m, T, N) float64; returns (status, iterations, solved) per set."""
    dtype = np.float32 if real == "float" else np.float64
    m = params.shape[0]
    direct = dtype == np.float64
    outputs = rows if direct else tuple(np.empty(rows[0].shape, dtype=dtype) for _ in range(3))
    inputs = [np.ascontiguousarray(a, dtype=dtype) for a in (params, q0, t)]
    pointer = f"{name}_real *"
    pointers = [ffi.cast(pointer, ffi.from_buffer(a)) if a.size else ffi.NULL
                for a in (*inputs, *outputs)]
    c_options = _options(ffi, lib, name, options)
    state = ffi.new(f"{name}_state *")
    work = ffi.new_allocator(should_clear_after_alloc=False)(f"{name}_workspace *")
    reports = ffi.new(f"{name}_batch_report[]", max(m, 1))
    stride = rows[0].shape[2] if q0.ndim == 2 else 0
    getattr(lib, f"{name}_solve_batch")(
        c_options, m, pointers[0], pointers[1], stride, t.size, pointers[2], pointers[3],
        pointers[4], pointers[5], state, work, reports)
    if not direct:
        for target, source in zip(rows, outputs):
            target[...] = source
    status = np.frombuffer(ffi.buffer(reports, m * ffi.sizeof(f"{name}_batch_report")),
                           dtype=_report_dtype(ffi, name))
    found: BatchStatus = (status["status"].astype(np.int32), status["iterations"].astype(np.int32),
                          status["solved"].astype(np.int32), status["cond"].astype(np.float64))
    return found


def _report_dtype(ffi: Any, name: str) -> np.dtype[Any]:
    """The NumPy view of ``<prefix>_batch_report`` (offsets from cffi, not assumed)."""
    struct = f"{name}_batch_report"
    real = np.float32 if ffi.sizeof(f"{name}_real") == 4 else np.float64
    fields = {"status": np.int32, "solved": np.int32, "t": real, "iterations": np.int32,
              "residual": real, "cond": real}
    return np.dtype({"names": list(fields), "formats": list(fields.values()),
                     "offsets": [ffi.offsetof(struct, f) for f in fields],
                     "itemsize": ffi.sizeof(struct)})


def _options(ffi: Any, lib: Any, name: str, options: Options) -> Any:
    c_options = ffi.new(f"{name}_options *")
    getattr(lib, f"{name}_default_options")(c_options)
    c_options.tol_phi, c_options.tol_dq = options.tol_phi, options.tol_dq
    c_options.max_iterations = options.max_iterations
    c_options.min_pivot_ratio = options.min_pivot_ratio
    return c_options
