"""Benchmark: the textbook crank-slider on the grid dt = 1.5/20000, both backends, µs per step.

Run from the repository root:  python3 bench/run_textbook.py [--repeat 5]
Compilation happens before timing (cached by content hash); each figure is the best of the
repeats of one whole ``symkin.solve`` (assembly at t0 included).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import symkin
from symkin.runtime import driver

ROOT = Path(__file__).resolve().parent.parent
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"


def best_time(kernel, times: np.ndarray, repeat: int, use_c_solver: bool = True) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        driver.solve(kernel, t=times, use_c_solver=use_c_solver)
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    system = symkin.derive(TEXTBOOK)
    times = driver.grid(0.0, 1.5, 1.5 / 20000)
    steps = times.size
    cases = [
        ("numpy kernel, Python driver", symkin.compile(system, backend="numpy"), True),
        ("C kernel, C solver (one call)", symkin.compile(system, backend="c"), True),
        ("C kernel (sparse LU), C solver", symkin.compile(system, backend="c", linalg="sparse"),
         True),
        ("C kernel, Python driver", symkin.compile(system, backend="c"), False),
    ]
    print(f"textbook crank-slider, {steps} time points (dt = 1.5/20000)")
    for label, kernel, in_c in cases:
        seconds = best_time(kernel, times, args.repeat, in_c)
        print(f"  {label:34s} {seconds * 1e6 / steps:9.2f} µs/step   ({seconds:.3f} s total)")


if __name__ == "__main__":
    main()
