"""Scale-free at C speed: the crank-slider drawn at 1, 1000 (millimetres) and 1e-3 times its
size, solved by symkin.solve on the C backend, microseconds per time step.

    python3 bench/scale_free.py [--points 20001] [--repeat 10]

A mechanism whose length scale lies outside 0.01..100 is solved in the unit 10^k that brings it
near 1 (runtime.solving.units); the generated C grid loop itself decides in that unit (its options'
``unit``), so a millimetre drawing runs at the speed of one in metres. For comparison, the same
runs through the Python grid loop over the generated functions (what a scaled run took
before), on a grid 100 times shorter. Best of --repeat, CPU time of this process.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402

TEXT = """
name: crank_slider_scale
parameters: {{a: {a!r}, b: {b!r}, c: {c!r}}}
bodies:
  crank:  {{q0: [0, 0, 0], points: {{tip: [a, 0]}}}}
  rod:    {{q0: [0, 0, 0], points: {{P: [b, 0]}}}}
  slider: {{q0: [0, 0, 0]}}
joints:
  - {{type: revolute,  i: ground, j: crank,  sA: [0, 0], sB: [0, 0]}}
  - {{type: revolute,  i: crank,  j: rod,    sA: tip,    sB: [0, 0]}}
  - {{type: revolute,  i: rod,    j: slider, sA: [b, 0], sB: [0, 0]}}
  - {{type: prismatic, i: slider, j: ground, sA: [0, 0], sB: [0, c], v: [0, 1], phi0: 0}}
drivers:
  - {{type: angle, i: crank, j: ground, theta: "t**2 + pi/2"}}
time: {{t0: 0, t1: 1.5, dt: 0.05}}
"""


def best(run: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        began = time.process_time()
        run()
        times.append(time.process_time() - began)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=20001)
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args()
    t = np.linspace(0.0, 1.5, args.points)
    short = np.linspace(0.0, 1.5, max(31, args.points // 100))
    print(f"crank-slider, symkin.solve on the C backend, {t.size} points (us/step)")
    with tempfile.TemporaryDirectory() as folder:
        for scale in (1.0, 1e3, 1e-3):
            path = Path(folder) / "m.yaml"
            path.write_text(TEXT.format(a=scale, b=5 * scale, c=4 * scale))
            kernel = symkin.compile(symkin.derive(symkin.load(path)), backend="c")
            symkin.solve(kernel, t=t)
            in_c = best(partial(symkin.solve, kernel, t=t), args.repeat) / t.size
            in_python = best(partial(symkin.solve, kernel, t=short, use_c_solver=False),
                             max(2, args.repeat // 5)) / short.size
            print(f"  x {scale:<8g} generated C loop {in_c * 1e6:7.3f}   "
                  f"Python loop {in_python * 1e6:8.2f}")


if __name__ == "__main__":
    main()
