"""Sweep benchmark: symkin.sweep through the public API against one C loop over the same
generated solver, in the same run; Dask LocalCluster and local-process throughput; and the
per-call overhead of symkin.solve.

    python3 bench/sweep.py [--sets 1000] [--points 31] [--repeat 20] [--dask-sets 20000]

The C loop (bench/sweep_loop.c) is compiled here with symkin's own flags against the generated
crank-slider folder and called once per round through ctypes with fresh output arrays, as
symkin.sweep allocates fresh ones. Both run in interleaved rounds; best of --repeat, CPU time
of this process. The sets are drawn within ±10 % of the textbook design, keeping the first
--sets that solve over the grid (the others cannot be assembled everywhere; their count is
printed too).
"""

from __future__ import annotations

import argparse
import ctypes
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402  (lazy: spawned workers re-import this script, and must not
#                               pay for SymPy: import symkin.build.compile only where used)

WARNINGS = ["-Wall", "-Wextra", "-pedantic", "-Werror"]


def build_c_loop(system, folder: Path) -> Callable[..., int]:
    """Compile bench/sweep_loop.c with the generated folder; return bench_sweep."""
    from symkin.backends.c.cffi_build import C_FLAGS

    symkin.generate(system, backend="c", out_dir=folder / "gen")
    sources = sorted(str(p) for p in (folder / "gen").glob("*.c")) + [str(HERE / "sweep_loop.c")]
    library = folder / "sweep_loop.so"
    command = ["gcc", *C_FLAGS, *WARNINGS, "-shared", "-I", str(folder / "gen"), *sources, "-o",
               str(library), "-lm"]
    subprocess.run(command, check=True)
    lib = ctypes.CDLL(str(library))
    lib.bench_sweep.restype = ctypes.c_long
    lib.bench_sweep.argtypes = [ctypes.c_int, ctypes.c_void_p, ctypes.c_int] + [
        ctypes.c_void_p] * 5
    return lib.bench_sweep


def designs(kernel, count: int, points: np.ndarray, seed: int = 0) -> tuple[np.ndarray, int]:
    rng = np.random.default_rng(seed)
    drawn = kernel.p_values * (1 + rng.uniform(-0.1, 0.1, size=(int(count * 1.5) + 100, 3)))
    status = symkin.sweep(kernel, drawn, points, workers=1).status
    good = drawn[status == 0]
    assert good.shape[0] >= count, "draw more"
    return np.ascontiguousarray(good[:count]), int((status[: np.searchsorted(
        np.cumsum(status == 0), count) + 1] != 0).sum())


def best(function: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.process_time()
        function()
        times.append(time.process_time() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sets", type=int, default=1000)
    parser.add_argument("--points", type=int, default=31)
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--dask-sets", type=int, default=20000)
    parser.add_argument("--no-dask", action="store_true")
    args = parser.parse_args()

    system = symkin.derive(ROOT / "examples" / "crank_slider.yaml")
    kernel = symkin.compile(system, backend="c")
    t = np.linspace(0.0, 1.5, args.points)
    params, skipped = designs(kernel, args.sets, t)
    print(f"crank-slider, {args.sets} parameter sets x {t.size} points (drawn within ±10 %; "
          f"{skipped} draws that cannot be solved over the grid were skipped)")
    with tempfile.TemporaryDirectory() as folder:
        c_loop = build_c_loop(system, Path(folder))
        shape = (args.sets, t.size, len(kernel.coordinates))

        def run_c() -> None:
            q, dq, ddq = (np.empty(shape) for _ in range(3))
            status = np.empty(args.sets, dtype=np.intc)
            solved = c_loop(args.sets, params.ctypes.data, t.size, t.ctypes.data, q.ctypes.data,
                            dq.ctypes.data, ddq.ctypes.data, status.ctypes.data)
            assert solved == args.sets

        def run_sweep() -> None:
            assert symkin.sweep(kernel, params, t).ok.all()

        def run_loop() -> None:
            for p in params:
                symkin.solve(kernel, t=t, params=p)

        rounds = {"C loop": [], "sweep": []}
        for _ in range(args.repeat):
            rounds["C loop"].append(best(run_c, 1))
            rounds["sweep"].append(best(run_sweep, 1))
        c_time, sweep_time = min(rounds["C loop"]), min(rounds["sweep"])
        loop_time = best(run_loop, max(3, args.repeat // 5))
        print(f"  one C loop over <prefix>_solve_grid   {c_time * 1e3:8.2f} ms")
        print(f"  symkin.sweep (public API)             {sweep_time * 1e3:8.2f} ms   "
              f"{sweep_time / c_time:.2f}x the C loop")
        print(f"  Python loop over symkin.solve         {loop_time * 1e3:8.2f} ms   "
              f"{loop_time / c_time:.2f}x the C loop")
        per_set = c_time / args.sets
        overhead = loop_time / args.sets - per_set
        print(f"  symkin.solve per call: {loop_time / args.sets * 1e6:.1f} us, of which "
              f"{overhead * 1e6:.1f} us outside the C solver ({per_set * 1e6:.1f} us a set)")
        one = np.array([0.0])
        print(f"  symkin.solve on a 1-point grid: "
              f"{best(lambda: symkin.solve(kernel, t=one), 2000) * 1e6:.1f} us")
    if not args.no_dask:
        parallel(kernel, t, args.dask_sets)


def parallel(kernel, t: np.ndarray, count: int) -> None:
    """Throughput of local processes and a 2-worker Dask LocalCluster (wall time, after one
    warm-up sweep so that every worker has loaded the kernel)."""
    from distributed import Client, LocalCluster

    params, _ = designs(kernel, count, t, seed=1)

    def wall(function: Callable[[], object]) -> float:
        function()  # warm-up: workers start and load the kernel
        start = time.perf_counter()
        function()
        return time.perf_counter() - start

    here = wall(lambda: symkin.sweep(kernel, params, t, workers=1))
    print(f"{count} sets x {t.size} points, wall time:")
    print(f"  this process                          {here * 1e3:8.1f} ms   "
          f"{count / here:9.0f} sets/s")
    local = wall(lambda: symkin.sweep(kernel, params, t, workers=2))
    print(f"  workers=2 (local processes)           {local * 1e3:8.1f} ms   "
          f"{count / local:9.0f} sets/s (process start-up included)")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        remote = wall(lambda: symkin.sweep(kernel, params, t, client=client))
    print(f"  Dask LocalCluster, 2 workers          {remote * 1e3:8.1f} ms   "
          f"{count / remote:9.0f} sets/s")


if __name__ == "__main__":
    main()
