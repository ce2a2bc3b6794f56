"""Figures for the edges: singular configurations, limit positions, assembly, on both backends.

    python3 bench/edges.py

For each case: the outcome, the largest error at unflagged points against the closed form
(q, dq, ddq), and the number of flagged points. The mechanisms are those of the tests
(tests/mechanisms/); the closed forms are derived in tests/runtime/test_edges_singular.py and
tests/runtime/test_edges_limits_assembly.py and repeated here so that the script stands alone.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import symkin  # noqa: E402
from symkin.runtime import driver  # noqa: E402

MECHANISMS = ROOT / "tests" / "mechanisms"


def chain_reference(t: np.ndarray, n: int) -> tuple[np.ndarray, ...]:
    theta = 0.5 - t
    zero, one = np.zeros_like(theta), np.ones_like(theta)
    q, dq, ddq = [], [], []
    for i in range(n + 1):
        q += [i * one, zero, theta]
        dq += [zero, zero, -one]
        ddq += [zero, zero, zero]
    for i in range(n):
        c, s = np.cos(theta), np.sin(theta)
        q += [i + c, s, zero]
        dq += [s, -c, zero]
        ddq += [-c, -s, zero]
    return tuple(np.stack(x, 1) for x in (q, dq, ddq))


def unflagged(trajectory, reference) -> str:
    """Max errors of q, dq, ddq at the unflagged points, then (in brackets) at the flagged."""
    said = []
    for keep in (~trajectory.flagged, trajectory.flagged):
        errors = [np.abs(got[keep] - want[keep]).max() if keep.any() else 0.0
                  for got, want in zip((trajectory.q, trajectory.dq, trajectory.d2q), reference)]
        said.append("q {:.1e}  dq {:.1e}  ddq {:.1e}".format(*errors))
    return f"{said[0]} (flagged points: {said[1]})"


def kernel(name: str, backend: str):
    built = symkin.compile(symkin.derive(MECHANISMS / f"{name}.yaml"), backend=backend)
    assert built.backend == backend
    return built


def main() -> None:
    for backend in ("numpy", "c"):
        print(f"== {backend} backend")
        chain = kernel("parallelogram_chain", backend)
        for offset in (0.0, 1e-4, 1e-6, 1e-8, 1e-10, -2e-4):
            times = 0.5 - offset + 0.05 * np.arange(-10, 10 + (offset == 0))
            run = driver.solve(chain, t=times)
            print(f"chain of 10, grid point theta = {offset:8.1e}: {run.t.size}/{times.size} "
                  f"points, {int(run.flagged.sum())} flagged; unflagged max error "
                  f"{unflagged(run, chain_reference(run.t, 10))}; singular passed "
                  f"{[(round(s[0], 9), s[1]) for s in run.singular]}")
        one = kernel("parallelogram", backend)
        run = driver.solve(one)
        print(f"parallelogram change point: {run.t.size} points, {int(run.flagged.sum())} "
              f"flagged; unflagged max error {unflagged(run, chain_reference(run.t, 1))}")
        for name, exact in (("non_grashof", math.acos(-0.25)), ("dead_centre", 0.5)):
            try:
                driver.solve(kernel(name, backend))
            except driver.SolveFailure as failure:
                print(f"{name}: {failure.reason} at t = {failure.reached:.12f}, error of the "
                      f"limit time {abs(failure.reached - exact):.1e}; "
                      f"{failure.trajectory.t.size} rows written, "
                      f"{int(failure.trajectory.flagged.sum())} flagged")
        guess = np.zeros(15)
        guess[2::3] = math.pi
        six = driver.solve(kernel("watt_six_bar_rough", backend), q0=guess)
        print(f"six-bar from q0 = all bodies at the origin turned by pi: assembled, "
              f"{six.t.size} points, {int(six.flagged.sum())} flagged")
        slide = driver.solve(kernel("slide_driven", backend), q0=np.zeros(9), t=[0.0, 0.03])
        print(f"slide-driven crank-slider, guess on the slider axis (Phi_q singular there): "
              f"crank angle error {abs(abs(slide.q[0, 2]) - math.acos(1 / 6)):.1e}")


if __name__ == "__main__":
    main()
