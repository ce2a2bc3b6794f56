"""Lowering time of the piecewise cam example (examples/cam_cycloidal.yaml): its profile, a
593-character Piecewise per coordinate, recurs with its derivatives in many rows of Phi_q and
Gamma, which made SymPy's rebuilding of Piecewise nodes the bulk of its generation.

    python3 bench/cam_lowering.py            # derive once, then lower for NumPy and for C

Prints CPU seconds per stage (time.process_time: other work on the machine disturbs it less
than wall time).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import symkin
from symkin import backends
from symkin.codegen import lower

ROOT = Path(__file__).resolve().parent.parent


def _timed(action: Callable[[], Any]) -> tuple[Any, float]:
    start = time.process_time()
    result = action()
    return result, time.process_time() - start


def main() -> None:
    system, seconds = _timed(lambda: symkin.derive(ROOT / "examples" / "cam_cycloidal.yaml"))
    print(f"derive          {seconds:7.1f} s")
    for backend in ("numpy", "c"):
        target = backends.get(backend)
        _, seconds = _timed(lambda: lower.lower(system, target))  # noqa: B023 (called now)
        print(f"lower ({backend:5s})   {seconds:7.1f} s")


if __name__ == "__main__":
    main()
