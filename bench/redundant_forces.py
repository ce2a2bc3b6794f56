"""Cost of the minimum-norm completion of the reactions where rows were removed as redundant
(runtime.loads.indeterminate), per row, against the kinematic step of the same run.

    python3 bench/redundant_forces.py [--steps 2000] [--repeat 5]

parallelogram_extra_bar_loads (C kernel, nominal parameters, --steps + 1 points over the
file's interval), best of --repeat, CPU time of this process:

- ``kinematic``: the generated grid loop with NULL multiplier outputs (as bench/forces.py);
- ``kept rows``: the generated ``multipliers_grid`` (the kept rows' multipliers and loads);
- ``completion``: runtime.loads.indeterminate.complete on them (NumPy, per row: Phi_q and the
  removed rows' Jacobian from the generated code, one batched solve and QR for all rows,
  the loads of the null vectors, the minimum-norm loads and which are determinate).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402
from symkin.runtime.driver import default_options  # noqa: E402
from symkin.runtime.loads import indeterminate  # noqa: E402

NAME = "parallelogram_extra_bar_loads"


def measure(steps: int, repeat: int) -> tuple[float, float, float]:
    kernel = symkin.compile(symkin.derive(ROOT / "examples" / f"{NAME}.yaml"), backend="c")
    t0, t1, _ = kernel.time_grid
    t = np.linspace(t0, t1, steps + 1)
    q, dq, d2q = (np.empty((t.size, kernel.nq)) for _ in range(3))
    cond, flagged = np.empty(t.size), np.empty(t.size, dtype=bool)
    p = kernel.p_values
    solver = kernel.grid_solver(default_options(kernel), kernel.q0, p)
    best = [float("inf")] * 3
    for _ in range(repeat):
        solver.start(default_options(kernel), kernel.q0, p)
        solver.bind(t, q, dq, d2q, cond, flagged, None)
        began = time.process_time()
        assert solver.advance(0, t.size) == t.size, "the grid stopped early"
        best[0] = min(best[0], time.process_time() - began)
        began = time.process_time()
        lam, loads = kernel.multipliers_grid(t, q, dq, d2q, p)
        best[1] = min(best[1], time.process_time() - began)
        began = time.process_time()
        indeterminate.complete(kernel, t, q, p, lam, loads)
        best[2] = min(best[2], time.process_time() - began)
    kinematic, kept, completion = (b / t.size for b in best)
    return kinematic, kept, completion


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    kinematic, kept, completion = measure(args.steps, args.repeat)
    print(f"{NAME}: kinematic {kinematic * 1e6:.1f} us/step, kept rows' multipliers "
          f"{kept * 1e6:.1f} us/row, completion {completion * 1e6:.1f} us/row "
          f"({completion / kinematic:.1f} x the kinematic step)")


if __name__ == "__main__":
    main()
