"""Failing designs at C speed: symkin.sweep of crank-slider variants of which some reach a limit
position, against one C loop over the same generated solver and the same sets, in the same run.

    python3 bench/sweep_failing.py [--sets 1000] [--failing 16] [--points 31] [--repeat 20]

The sets are drawn within ±5 % of the textbook design (seeded); --failing of them reach their
limit position inside the grid (the closed form cos t^2 = (c - b) / a, checked against the
sweep's status), the others solve. The C loop (bench/sweep_loop.c, built as in bench/sweep.py)
stops a set at its first failing point, as a hand-written C sweep would. Best of --repeat
interleaved rounds, CPU time of this process. Also printed: the same sweep with every failed
set re-run through symkin.solve (the path before sweeps.stops), for comparison.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

from sweep import best, build_c_loop  # noqa: E402

import symkin  # noqa: E402
from symkin.sweeps import batch  # noqa: E402


def limit_time(p: np.ndarray) -> float:
    a, b, c = p
    ratio = (c - b) / a
    return float(np.sqrt(np.arccos(ratio))) if -1.0 <= ratio <= 1.0 else np.inf


def designs(kernel, sets: int, failing: int, t1: float, seed: int = 0) -> np.ndarray:
    """sets designs within ±5 %: the first ``failing`` drawn that reach a limit before t1
    and the first sets - failing that do not, shuffled together (seeded)."""
    rng = np.random.default_rng(seed)
    drawn = kernel.p_values * (1 + rng.uniform(-0.05, 0.05, size=(40 * sets, 3)))
    reach = np.array([limit_time(p) <= t1 for p in drawn])
    chosen = np.concatenate([drawn[reach][:failing], drawn[~reach][:sets - failing]])
    assert chosen.shape[0] == sets, "draw more"
    return np.ascontiguousarray(chosen[rng.permutation(sets)])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sets", type=int, default=1000)
    parser.add_argument("--failing", type=int, default=16)
    parser.add_argument("--points", type=int, default=31)
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()

    system = symkin.derive(HERE.parent / "examples" / "crank_slider.yaml")
    kernel = symkin.compile(system, backend="c")
    t = np.linspace(0.0, 1.5, args.points)
    params = designs(kernel, args.sets, args.failing, float(t[-1]))
    result = symkin.sweep(kernel, params, t, workers=1)
    failed = int((result.status != 0).sum())
    assert failed == args.failing and set(result.reasons) <= {"", "limit position"}
    print(f"crank-slider, {args.sets} parameter sets (±5 %) x {t.size} points, {failed} reach "
          "a limit position")
    with tempfile.TemporaryDirectory() as folder:
        c_loop = build_c_loop(system, Path(folder))
        shape = (args.sets, t.size, len(kernel.coordinates))

        def run_c() -> None:
            q, dq, ddq = (np.empty(shape) for _ in range(3))
            status = np.empty(args.sets, dtype=np.intc)
            solved = c_loop(args.sets, params.ctypes.data, t.size, t.ctypes.data, q.ctypes.data,
                            dq.ctypes.data, ddq.ctypes.data, status.ctypes.data)
            assert solved == args.sets - args.failing

        def run_sweep() -> None:
            symkin.sweep(kernel, params, t, workers=1)

        rounds: dict[str, list[float]] = {"C loop": [], "sweep": []}
        for _ in range(args.repeat):
            rounds["C loop"].append(best(run_c, 1))
            rounds["sweep"].append(best(run_sweep, 1))
        c_time, sweep_time = min(rounds["C loop"]), min(rounds["sweep"])
        print(f"  one C loop over <prefix>_solve_grid   {c_time * 1e3:8.2f} ms")
        print(f"  symkin.sweep (public API)             {sweep_time * 1e3:8.2f} ms   "
              f"{sweep_time / c_time:.2f}x the C loop")
        rerun = batch.edge_stops
        # every failed set re-run, as before sweeps.stops
        batch.edge_stops = lambda *arguments: [None] * len(arguments[4])
        try:
            old = best(run_sweep, max(2, args.repeat // 10))
        finally:
            batch.edge_stops = rerun
        print(f"  the same, failed sets re-run          {old * 1e3:8.2f} ms   "
              f"{old / c_time:.2f}x the C loop")


if __name__ == "__main__":
    main()
