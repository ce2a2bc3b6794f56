"""Per-call overhead of symkin.solve with the C backend: what a Python loop over solve pays
around the generated solver.

    python3 bench/solve_overhead.py [--calls 2000] [--repeat 15] [--points 1 31 20001]

The crank-slider (C kernel, symkin.compile's build), at the nominal parameters, from the file's
q0, on grids of --points time points over 0..1.5. Three ways to solve the same grid in the
same run, in interleaved rounds, best of --repeat rounds of --calls calls each (fewer for a long
grid: --calls * 31 / points, at least 20), CPU time of this process per call:

- ``direct``: the generated ``<prefix>_solve_grid`` called through cffi on arrays, structs and
  pointers made once, with only the state reset (q0 copied in) per call: the floor;
- ``solve``: ``symkin.solve(kernel, t=t, params=p)``, fresh result arrays each call;
- ``solve out=``: the same with ``out=`` the previous call's Trajectory (no allocation of
  result arrays: on a long grid, no fresh pages to fault in).

The overhead is ``solve`` minus ``direct``. The script runs against the symkin of the source
tree it sits in (a version without ``out=`` gets a dash in that column).
"""

from __future__ import annotations

import argparse
import inspect
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402


def direct_call(kernel: Any, t: np.ndarray) -> Callable[[], None]:
    """One call of <prefix>_solve_grid through cffi, everything prepared once."""
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    options = ffi.new(f"{name}_options *")
    getattr(lib, f"{name}_default_options")(options)
    state = ffi.new(f"{name}_state *")
    work = ffi.new(f"{name}_workspace *")
    report = ffi.new(f"{name}_report *")
    p = ffi.new(f"{name}_real[]", kernel.p_values.tolist())
    q0 = np.ascontiguousarray(kernel.q0, dtype=float)
    shape = (t.size, kernel.nq)
    q, dq, ddq = (np.empty(shape) for _ in range(3))
    pointers = [ffi.from_buffer("double[]", a) for a in (t, q, dq, ddq)]
    solve_grid = getattr(lib, f"{name}_solve_grid")
    size, nbytes = t.size, q0.nbytes

    def call() -> None:
        ffi.memmove(state.q, q0, nbytes)
        state.started = 0
        if solve_grid(options, p, size, pointers[0], state, pointers[1], pointers[2],
                      pointers[3], work, report) != size:
            raise RuntimeError("the direct call did not solve the grid")

    return call


def per_call(function: Callable[[], object], calls: int) -> float:
    start = time.process_time()
    for _ in range(calls):
        function()
    return (time.process_time() - start) / calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--points", type=int, nargs="+", default=[1, 31, 20001])
    args = parser.parse_args()

    kernel = symkin.compile(symkin.derive(ROOT / "examples" / "crank_slider.yaml"), backend="c")
    assert kernel.backend == "c"
    has_out = "out" in inspect.signature(symkin.solve).parameters
    p = np.array(kernel.p_values, dtype=float)
    print(f"symkin.solve per call, crank-slider, C backend (CPU time, best of {args.repeat} "
          f"rounds of {args.calls} calls, interleaved)")
    print(f"{'points':>6} {'direct C':>10} {'solve':>10} {'solve out=':>11} {'overhead':>10}")
    for points in args.points:
        t = np.linspace(0.0, 1.5, points)
        reference = symkin.solve(kernel, t=t, params=p)
        ways: dict[str, Callable[[], object]] = {
            "direct": direct_call(kernel, t),
            "solve": lambda t=t: symkin.solve(kernel, t=t, params=p),
        }
        if has_out:
            ways["out"] = lambda t=t, out=reference: symkin.solve(kernel, t=t, params=p,
                                                                  out=out)
        calls = max(20, args.calls * 31 // max(points, 31))
        best = {way: float("inf") for way in ways}
        for _ in range(args.repeat):
            for way, function in ways.items():
                best[way] = min(best[way], per_call(function, calls))
        out = f"{best['out'] * 1e6:8.2f} us" if has_out else f"{'-':>11}"
        print(f"{points:>6} {best['direct'] * 1e6:7.2f} us {best['solve'] * 1e6:7.2f} us "
              f"{out} {(best['solve'] - best['direct']) * 1e6:7.2f} us")


if __name__ == "__main__":
    main()
