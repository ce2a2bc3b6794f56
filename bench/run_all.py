"""Run every crank-slider solver on the long grid side by side and print a table.

    python3 bench/run_all.py [--steps 20000] [--repeat 20] [--quick] [--c-only] [--all]

Grid: t = k dt, k = 0..steps, dt = 1.5 / steps (20000 by default), from the chapter's start
q = 0. Accuracy: the largest deviation from Example 2.7's closed form. Time per step: CPU time
of this process (robust to a busy machine); for the C solvers the best of --repeat runs of the
whole grid, taken in interleaved rounds; one run for the Python baselines (on a 10x shorter
grid with --quick). Ratios are against the faster build of the hand-written dense C.
symkin's rows go through the public API (symkin.compile, then symkin.solve over the grid).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

# Single-threaded comparisons: an idle OpenBLAS worker pool spins after a NumPy call and that
# spinning would count as CPU time of whichever solver ran NumPy linear algebra last.
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from baselines import handwritten_c, lambdify_driver, reference, textbook_numpy

Row = tuple[str, int, float, tuple[float, float, float], str]


def timed(run: Callable[[], tuple[np.ndarray, np.ndarray, np.ndarray]], times: np.ndarray,
          repeat: int) -> tuple[float, tuple[float, float, float]]:
    """Best CPU time per step over ``repeat`` runs, and the accuracy of the last run."""
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        q, dq, d2q = run()
        best = min(best, time.process_time() - start)
    return best / len(times) * 1e6, reference.errors(times, q, dq, d2q)


def c_rows(steps: int, repeat: int, folder: Path) -> list[Row]:
    """The C solvers, timed in interleaved rounds so that a busy machine hurts them alike."""
    times = reference.grid(steps)
    dt = reference.T1 / steps
    builds = [("hand-written C, dense LU", handwritten_c.build_dense),
              ("hand-written C loop + generated sparse LU", handwritten_c.build_sparse)]
    solvers = [(f"{label} ({flag})", build(folder, flag))
               for label, build in builds for flag in ("-O2", "-O3")]
    best = {label: (float("inf"), (0.0, 0.0, 0.0), "") for label, _ in solvers}
    for _ in range(repeat):
        for label, solver in solvers:
            us, err, result = _time_c(solver, steps, dt, times)
            note = f"Newton its {result.newton_iterations}, fall-backs {result.fallbacks}"
            if us < best[label][0]:
                best[label] = (us, err, note)
    return [(label, steps, *best[label]) for label, _ in solvers]


def _time_c(solver: handwritten_c.Solver, steps: int, dt: float, times: np.ndarray
            ) -> tuple[float, tuple[float, float, float], handwritten_c.GridResult]:
    start = time.process_time()
    result = solver.solve_grid(steps, dt)
    us = (time.process_time() - start) / len(times) * 1e6
    return us, reference.errors(times, result.q, result.dq, result.d2q), result


def python_rows(steps: int) -> list[Row]:
    times = reference.grid(steps)
    dt = reference.T1 / steps

    def textbook() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        _, q, dq, d2q = textbook_numpy.KorbWodz(dt=dt, steps=steps)
        return q.T, dq.T, d2q.T

    functions = lambdify_driver.derive(ROOT / "examples" / "crank_slider.yaml")
    rows = []
    for label, run in (("literal NumPy port of the chapter", textbook),
                       ("SymPy lambdify driver", lambda: lambdify_driver.solve_grid(
                           functions, times, np.zeros(9)))):
        us, err = timed(run, times, 1)
        rows.append((label, steps, us, err, ""))
    return rows


def symkin_rows(steps: int, python_steps: int, repeat: int) -> list[Row]:
    """symkin's own backends through the public API: compile, then solve over the grid."""
    import symkin
    from symkin.errors import SymkinError

    system = symkin.derive(ROOT / "examples" / "crank_slider.yaml")
    rows = []
    for label, backend, linalg, n, runs in (
            ("symkin generated C, dense LU", "c", "dense", steps, repeat),
            ("symkin generated C, sparse LU", "c", "sparse", steps, repeat),
            ("symkin NumPy backend", "numpy", "dense", python_steps, 1)):
        times = reference.grid(n)
        try:
            kernel = (symkin.compile(system, backend="c", linalg=linalg) if backend == "c"
                      else symkin.compile(system, backend="numpy"))

            def run(kernel=kernel, times=times) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
                trajectory = symkin.solve(kernel, t=times, q0=np.zeros(9))
                return trajectory.q, trajectory.dq, trajectory.d2q

            us, err = timed(run, times, runs)
            rows.append((label, n, us, err, "symkin.solve over the grid"))
        except (SymkinError, OSError, RuntimeError) as error:  # report it and go on
            rows.append((label, n, float("nan"), (float("nan"),) * 3, f"failed: {error}"))
    return rows


def print_table(rows: list[Row], baseline: float) -> None:
    print(f"{'solver':<52} {'steps':>6} {'us/step':>9} {'x dense C':>9} "
          f"{'max|q err|':>10} {'max|dq err|':>11} {'max|d2q err|':>12}  note")
    for label, steps, us, (eq, edq, ed2q), note in rows:
        print(f"{label:<52} {steps:6d} {us:9.3f} {us / baseline:9.2f} {eq:10.1e} {edq:11.1e} "
              f"{ed2q:12.1e}  {note}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=reference.LONG_STEPS)
    parser.add_argument("--repeat", type=int, default=20,
                        help="runs of each C solver over the grid; the best one counts")
    parser.add_argument("--quick", action="store_true",
                        help="run the Python baselines on a 10x shorter grid")
    parser.add_argument("--c-only", action="store_true", help="skip the Python baselines")
    parser.add_argument("--all", action="store_true",
                        help="also the scaling family: sparse LU alone and the whole solver")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        rows = c_rows(args.steps, args.repeat, Path(folder))
    baseline = min(r[2] for r in rows if r[0].startswith("hand-written C, dense"))
    python_steps = args.steps // 10 if args.quick else args.steps
    rows += symkin_rows(args.steps, python_steps, args.repeat)
    if not args.c_only:
        rows += python_rows(python_steps)
    print(f"grid dt = 1.5/{args.steps}; ratios against the faster hand-written dense C build")
    print_table(rows, baseline)
    if args.all:
        import scaling_family

        sizes = [11, 21, 41, 81, 161, 301]
        print("\nchain of four-bar loops: generated sparse LU alone")
        scaling_family.report_lu(scaling_family.measure_sparse_lu(sizes))
        print("\nchain of four-bar loops: symkin's generated C solver, sparse LU")
        scaling_family.report_solver(scaling_family.measure_solver(sizes))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
