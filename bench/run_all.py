"""Run every crank-slider solver on the long grid side by side and print a table.

    python3 bench/run_all.py [--steps 20000] [--repeat 20] [--quick] [--c-only] [--all]
                             [--default-malloc]

Grid: t = k dt, k = 0..steps, dt = 1.5 / steps (20000 by default), from the chapter's start
q = 0. Accuracy: the largest deviation from Example 2.7's closed form. Time per step: CPU time
of this process (robust to a busy machine); for the C solvers the best of --repeat runs of the
whole grid, taken in interleaved rounds; one run for the Python baselines (on a 10x shorter
grid with --quick). Ratios are against the faster build of the hand-written dense C.
symkin's rows go through the public API (symkin.compile, then symkin.solve over the grid); its
C kernels are timed in the same interleaved rounds as the hand-written C, with -O2 (what
symkin.compile uses) and with -O3.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import subprocess
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

# glibc mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def steady_malloc() -> bool:
    """Keep freed result arrays in the heap, so that no timed run pays page faults.

    Every solver writes its q, dq, d2q into fresh arrays (1.4 MB each on the long grid). With
    glibc's default settings those often come from new mmap pages, and the kernel's zeroing of
    the pages on first touch (about 2 ms a grid here) is charged to whichever solver writes
    them, the same for all of them. Fixed thresholds (32 MB, glibc's largest) keep the memory
    in the heap instead. Returns False where mallopt is not available (not glibc).
    """
    try:
        libc = ctypes.CDLL(None)
        limit = 32 << 20
        return bool(libc.mallopt(_M_MMAP_THRESHOLD, limit) and
                    libc.mallopt(_M_TRIM_THRESHOLD, limit))
    except (OSError, AttributeError):
        return False


def timed(run: Callable[[], tuple[np.ndarray, np.ndarray, np.ndarray]], times: np.ndarray,
          repeat: int) -> tuple[float, tuple[float, float, float]]:
    """Best CPU time per step over ``repeat`` runs, and the accuracy of the last run."""
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        q, dq, d2q = run()
        best = min(best, time.process_time() - start)
    return best / len(times) * 1e6, reference.errors(times, q, dq, d2q)


# One timed run of a C solver over the grid: (us/step, (errors of q, dq, d2q), note).
Timing = tuple[float, tuple[float, float, float], str]


def c_rows(steps: int, repeat: int, folder: Path) -> list[Row]:
    """Every C solver, hand-written and symkin's, timed in the same interleaved rounds so that
    a busy machine hurts them alike; the best round of each counts."""
    times = reference.grid(steps)
    solvers = handwritten_solvers(steps, times, folder) + symkin_solvers(times, folder)
    best: dict[str, Timing] = {label: (float("inf"), (0.0, 0.0, 0.0), "")
                               for label, _ in solvers}
    for _ in range(repeat):
        for label, run in solvers:
            timing = run()
            if timing[0] < best[label][0]:
                best[label] = timing
    return [(label, steps, *best[label]) for label, _ in solvers]


def handwritten_solvers(steps: int, times: np.ndarray, folder: Path
                        ) -> list[tuple[str, Callable[[], Timing]]]:
    dt = reference.T1 / steps
    builds = [("hand-written C, dense LU", handwritten_c.build_dense),
              ("hand-written C loop + generated sparse LU", handwritten_c.build_sparse)]

    def runner(solver: handwritten_c.Solver) -> Callable[[], Timing]:
        def run() -> Timing:
            start = time.process_time()
            result = solver.solve_grid(steps, dt)
            us = (time.process_time() - start) / len(times) * 1e6
            note = f"Newton its {result.newton_iterations}, fall-backs {result.fallbacks}"
            return us, reference.errors(times, result.q, result.dq, result.d2q), note
        return run

    return [(f"{label} ({flag})", runner(build(folder, flag)))
            for label, build in builds for flag in ("-O2", "-O3")]


def symkin_solvers(times: np.ndarray, folder: Path) -> list[tuple[str, Callable[[], Timing]]]:
    """symkin's generated C through the public API (symkin.compile, then symkin.solve over the
    grid from q = 0, assembly included): built as symkin.compile builds it (-O2), and once more
    with -O3 (into a private cache folder) for the pair with the hand-written -O3 build."""
    import symkin
    from symkin.backends.c import cffi_build as build

    system = symkin.derive(ROOT / "examples" / "crank_slider.yaml")

    def runner(kernel) -> Callable[[], Timing]:
        def run() -> Timing:
            start = time.process_time()
            trajectory = symkin.solve(kernel, t=times, q0=np.zeros(9))
            us = (time.process_time() - start) / len(times) * 1e6
            errors = reference.errors(times, trajectory.q, trajectory.dq, trajectory.d2q)
            return us, errors, f"symkin.solve, fall-backs {trajectory.lu_fallbacks}"
        return run

    return [(label, runner(_compile_with(build, system, linalg, flag, folder)))
            for label, linalg, flag in (
                ("symkin generated C, dense LU (-O2)", "dense", "-O2"),
                ("symkin generated C, sparse LU (-O2)", "sparse", "-O2"),
                ("symkin generated C, sparse LU (-O3)", "sparse", "-O3"))]


def _compile_with(build, system, linalg: str, optimisation: str, folder: Path):
    """symkin.compile, with its -O2 replaced by ``optimisation`` (-O3: in its own cache)."""
    import symkin

    if optimisation == "-O2":
        return symkin.compile(system, backend="c", linalg=linalg)
    saved = build.C_FLAGS
    build.C_FLAGS = tuple(optimisation if flag == "-O2" else flag for flag in saved)
    try:
        return symkin.compile(system, backend="c", linalg=linalg,
                              cache_dir=folder / f"cache{optimisation}")
    finally:
        build.C_FLAGS = saved


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


def numpy_backend_row(steps: int) -> Row:
    """symkin's NumPy backend through the public API, one run."""
    import symkin

    kernel = symkin.compile(symkin.derive(ROOT / "examples" / "crank_slider.yaml"),
                            backend="numpy")
    times = reference.grid(steps)

    def run() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        trajectory = symkin.solve(kernel, t=times, q0=np.zeros(9))
        return trajectory.q, trajectory.dq, trajectory.d2q

    us, err = timed(run, times, 1)
    return ("symkin NumPy backend", steps, us, err, "symkin.solve over the grid")


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
    parser.add_argument("--default-malloc", action="store_true",
                        help="leave glibc's malloc thresholds alone (results then include the "
                        "page faults of fresh result arrays, for every solver alike)")
    args = parser.parse_args(argv)
    steady = False if args.default_malloc else steady_malloc()
    python_steps = args.steps // 10 if args.quick else args.steps
    with tempfile.TemporaryDirectory() as folder:
        rows = c_rows(args.steps, args.repeat, Path(folder))
    baseline = min(r[2] for r in rows if r[0].startswith("hand-written C, dense"))
    rows.append(numpy_backend_row(python_steps))
    if not args.c_only:
        rows += python_rows(python_steps)
    print(f"grid dt = 1.5/{args.steps}; ratios against the faster hand-written dense C build; "
          f"malloc: {'fixed thresholds (no page faults)' if steady else 'default'}")
    print_table(rows, baseline)
    if args.all:
        import scaling_family

        sizes = [11, 21, 41, 81, 161, 301]
        print("\nchain of four-bar loops: generated sparse LU alone")
        scaling_family.report_lu(scaling_family.measure_sparse_lu(sizes))
        print("\nchain of four-bar loops: symkin's generated C solver, sparse LU")
        scaling_family.report_solver(scaling_family.measure_solver(sizes))
        print("\ncold and warm `symkin run` of the textbook example (fresh processes)", flush=True)
        subprocess.run([sys.executable, str(Path(__file__).with_name("cold_warm.py"))],
                       check=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
