"""Extra cost of the multipliers (inverse dynamics) per time step, against the kinematic step,
in the same run.

    python3 bench/forces.py [--steps 20000] [--repeat 15]

For each example with forces and the spatial slider-crank with forces of this folder (C
kernels, symkin.compile's build, nominal parameters, the file's q0, a grid of --steps + 1
points over the file's interval), in interleaved rounds, best of --repeat, CPU time of this
process:

- ``kinematic``: the generated grid loop (``<prefix>_solve_grid_checked`` through the
  GridSolver the driver uses) with NULL multiplier outputs: predictor, Newton, condition
  estimate, velocity, acceleration;
- ``with forces``: the same loop writing lam and the loads (what ``symkin.solve`` runs for a
  file with masses or forces): per step also Q - M ddq - h, one transposed solve with the
  step's own factors, and the efforts and reactions;
- ``post-pass``: ``<prefix>_multipliers_grid`` on the rows solved (the path for rows the
  runtime's edge treatment solved): per row Phi_q and its factorization again, then the same.

The extra cost per step is (with forces - kinematic) / kinematic (the goal: at most 0.5).
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
from symkin.contract.loads import load_count  # noqa: E402
from symkin.runtime.driver import default_options  # noqa: E402

EXAMPLES = ("crank_slider_load", "four_bar_dynamics")
SPATIAL = ("spatial_slider_crank_forces",)  # files in bench/ (their names are the mechanisms')


def _path(name: str) -> Path:
    folder = "bench" if name in SPATIAL else "examples"
    return ROOT / folder / f"{name}.yaml"


def measure(name: str, steps: int, repeat: int) -> tuple[float, float, float]:
    kernel = symkin.compile(symkin.derive(_path(name)), backend="c")
    t0, t1, _ = kernel.time_grid
    t = np.linspace(t0, t1, steps + 1)
    n = kernel.nq
    q, dq, d2q = (np.empty((t.size, n)) for _ in range(3))
    cond, flagged = np.empty(t.size), np.empty(t.size, dtype=bool)
    p = kernel.p_values
    solver = kernel.grid_solver(default_options(kernel), kernel.q0, p)
    lam = np.empty((t.size, n))
    loads = np.empty((t.size, load_count(len(kernel.driver_names), len(kernel.joint_names),
                                         kernel.space)))
    best = [float("inf")] * 3
    for _ in range(repeat):
        for k, forces_out in enumerate((None, (lam, loads))):
            solver.start(default_options(kernel), kernel.q0, p)
            solver.bind(t, q, dq, d2q, cond, flagged, forces_out)
            began = time.process_time()
            solved = solver.advance(0, t.size)
            best[k] = min(best[k], time.process_time() - began)
            assert solved == t.size, f"{name}: the grid stopped at row {solved}"
        began = time.process_time()
        kernel.multipliers_grid(t, q, dq, d2q, p)
        best[2] = min(best[2], time.process_time() - began)
    kinematic, with_forces, post = (b / t.size for b in best)
    return kinematic, with_forces, post


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=15)
    args = parser.parse_args()
    print(f"{'mechanism':<28} {'kinematic':>10} {'with forces':>12} {'extra':>6} "
          f"{'post-pass':>10} {'extra':>6}   (us/step; extra: x the kinematic step)")
    for name in EXAMPLES + SPATIAL:
        kinematic, with_forces, post = measure(name, args.steps, args.repeat)
        print(f"{name:<28} {kinematic * 1e6:>10.3f} {with_forces * 1e6:>12.3f} "
              f"{(with_forces - kinematic) / kinematic:>6.2f} {post * 1e6:>10.3f} "
              f"{post / kinematic:>6.2f}")


if __name__ == "__main__":
    main()
