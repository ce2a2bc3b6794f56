"""Time of `symkin.scan` looking for every assembly of a Stewart platform at given leg lengths.

    python3 bench/scan_assemblies.py [--mechanism examples/stewart_fk.yaml] [--legs 1 1 1 1 1 1]

Compiles the mechanism with the C and the NumPy backend (not timed) and times one scan with
each: wall and CPU seconds, the number of assemblies found and how many near a singular
configuration. The example at all legs 1.0 has 8 real assemblies (counted independently in
tests/assemblies/test_six_six.py).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402
from symkin.runtime.scanning.scan import scan  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mechanism", default=str(ROOT / "examples" / "stewart_fk.yaml"))
    parser.add_argument("--legs", type=float, nargs="+", default=[1.0] * 6)
    args = parser.parse_args()
    system = symkin.derive(args.mechanism)
    for backend in ("c", "numpy"):
        kernel = symkin.compile(system, backend=backend)
        wall, cpu = time.perf_counter(), time.process_time()
        report = scan(kernel, inputs=args.legs)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        near = sum(branch.near_singular for branch in report.branches)
        print(f"{backend:5s}: {len(report.branches)} assemblies ({near} near singular), "
              f"{wall:.2f} s wall, {cpu:.2f} s CPU")


if __name__ == "__main__":
    main()
