"""Microseconds per time step of the generated C solver: the Stewart-Gough platform driven by
its six leg lengths (one moving body, 7 coordinates), the same platform with its 12 leg
bodies (91 coordinates) and the planar crank-slider, in the same run.

    python3 bench/spatial_steps.py [--points 2001] [--repeat 7]

Each mechanism's kernel is built by symkin.compile (C, double, sparse LU); its generated
``<prefix>_solve_grid`` is called through cffi on arrays prepared once, over --points time
points spanning the file's time grid (positions, velocities and accelerations at each, as a
run does). The rounds are interleaved; each figure is the best of --repeat rounds, CPU time
of this process divided by the number of steps.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402

MECHANISMS = ("stewart", "stewart_legs", "crank_slider")


def grid_call(kernel: Any, t: np.ndarray) -> Callable[[], None]:
    """One solve of the whole grid by the generated C, from q0, all buffers made once."""
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    options = ffi.new(f"{name}_options *")
    getattr(lib, f"{name}_default_options")(options)
    state = ffi.new(f"{name}_state *")
    work = ffi.new(f"{name}_workspace *")
    report = ffi.new(f"{name}_report *")
    p = ffi.new(f"{name}_real[]", kernel.p_values.tolist())
    q0 = np.ascontiguousarray(kernel.q0, dtype=float)
    q, dq, ddq = (np.empty((t.size, kernel.nq)) for _ in range(3))
    pointers = [ffi.from_buffer("double[]", a) for a in (t, q, dq, ddq)]
    solve_grid = getattr(lib, f"{name}_solve_grid")

    def call() -> None:
        ffi.memmove(state.q, q0, q0.nbytes)
        state.started = 0
        solved = solve_grid(options, p, t.size, pointers[0], state, pointers[1], pointers[2],
                            pointers[3], work, report)
        if solved != t.size:
            raise RuntimeError(f"{name}: solved {solved} of {t.size} points")

    return call


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=2001)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    calls, sizes = {}, {}
    for name in MECHANISMS:
        kernel = symkin.compile(symkin.derive(ROOT / "examples" / f"{name}.yaml"), backend="c")
        t0, t1, _ = kernel.time_grid
        calls[name] = grid_call(kernel, np.linspace(t0, t1, args.points))
        sizes[name] = (kernel.nq, kernel.nnz)
    best = {name: float("inf") for name in MECHANISMS}
    for _ in range(args.repeat):
        for name in MECHANISMS:
            start = time.process_time()
            calls[name]()
            best[name] = min(best[name], time.process_time() - start)
    print(f"{'mechanism':<14} {'nq':>4} {'nnz':>5} {'us/step':>9}")
    for name in MECHANISMS:
        nq, nnz = sizes[name]
        print(f"{name:<14} {nq:>4} {nnz:>5} {1e6 * best[name] / args.points:>9.2f}")


if __name__ == "__main__":
    main()
