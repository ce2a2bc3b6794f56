"""A Python loop of ``symkin.solve`` calls against one C batch of the same parameter sets.

    python3 bench/loop_vs_batch.py [--sets 1000] [--repeat 5]

The crank-slider's C kernel on a 31-point grid over 0..1.5, --sets parameter sets (b from 5
to 5.5, the others nominal): ``symkin.solve`` once per set in a Python loop, and
``symkin.sweep(kernel, params, t, workers=1)`` (one process: every set in the generated C
batch). CPU time of this process, best of --repeat interleaved rounds; the ratio is
loop / batch.
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


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    kernel = symkin.compile(symkin.derive(symkin.load(ROOT / "examples" / "crank_slider.yaml")),
                            backend="c")
    t = np.linspace(0.0, 1.5, 31)
    params = np.tile(np.array(kernel.p_values, dtype=float), (args.sets, 1))
    params[:, list(kernel.parameter_names).index("b")] = np.linspace(5.0, 5.5, args.sets)

    def loop() -> None:
        for row in params:
            symkin.solve(kernel, t=t, params=row)

    def batch() -> None:
        symkin.sweep(kernel, params, t, workers=1)

    best = {"loop": np.inf, "batch": np.inf}
    for _ in range(args.repeat):
        for name, run in (("loop", loop), ("batch", batch)):
            start = time.process_time()
            run()
            best[name] = min(best[name], time.process_time() - start)
    print(f"{args.sets} sets, 31 points: Python loop {best['loop'] * 1e3:.1f} ms, C batch "
          f"{best['batch'] * 1e3:.1f} ms, ratio {best['loop'] / best['batch']:.2f} "
          f"(CPU time, best of {args.repeat})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
