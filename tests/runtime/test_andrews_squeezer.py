"""Andrews' squeezing mechanism (Hairer & Wanner, Solving ODE II, VII.7), with its published
point names O, A ... H (E included), on both backends.

The reference is independent of symkin: the benchmark's own six loop-closure equations
g1..g6 in its seven relative angles (beta, Theta, gamma, Phi, delta, Omega, epsilon), and its
published consistent initial angles.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from codegen_support import ROOT, derived

import symkin

# The benchmark's consistent initial angles (Hairer & Wanner's test problem "andrews").
PUBLISHED_START = {
    "beta": -0.0617138900142764496358948458001, "Theta": 0.0,
    "gamma": 0.455279819163070380255912382449, "Phi": 0.222668390165885884674473185609,
    "delta": 0.487364979543842550225598953530, "Omega": -0.222668390165885884674473185609,
    "epsilon": 1.23054744454982119249735015568,
}
XA, YA, XB, YB = -0.06934, -0.00227, -0.03635, 0.03273
RR, D, SS, E, ZT, ZF, U = 7e-3, 28e-3, 35e-3, 2e-2, 4e-2, 2e-2, 4e-2


def loop_closure(a: dict[str, float]) -> np.ndarray:
    """g1..g6 of the benchmark, written out as published (not from symkin's constraints)."""
    b, th, ga, ph, de, om, ep = (a[k] for k in ("beta", "Theta", "gamma", "Phi", "delta",
                                                  "Omega", "epsilon"))
    ex = RR * math.cos(b) - D * math.cos(b + th)  # point E from O through F
    ey = RR * math.sin(b) - D * math.sin(b + th)
    return np.array([
        ex - SS * math.sin(ga) - XB,
        ey + SS * math.cos(ga) - YB,
        ex - E * math.sin(ph + de) - ZT * math.cos(de) - XA,
        ey + E * math.cos(ph + de) - ZT * math.sin(de) - YA,
        ex - ZF * math.cos(om + ep) - U * math.sin(ep) - XA,
        ey - ZF * math.sin(om + ep) + U * math.cos(ep) - YA,
    ])


def benchmark_angles(phi: dict[str, float]) -> dict[str, float]:
    """The benchmark's relative angles from symkin's absolute body angles."""
    return {"beta": phi["crank"], "Theta": phi["rod"] - phi["crank"], "gamma": phi["link3"],
            "Phi": phi["link4"] - phi["link5"], "delta": phi["link5"],
            "Omega": phi["link6"] - phi["link7"], "epsilon": phi["link7"]}


@pytest.fixture(scope="module")
def mechanism():
    return derived(ROOT / "examples" / "andrews_squeezer.yaml")  # once per test run


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_andrews_squeezer_closes_its_published_loops(mechanism,
                                                     backend: str) -> None:
    kernel = symkin.compile(mechanism, backend=backend)
    assert kernel.backend == backend
    trajectory = symkin.solve(kernel)
    names = list(kernel.coordinates)
    bodies = ("crank", "rod", "link3", "link4", "link5", "link6", "link7")
    columns = {body: names.index(f"{body}.phi") for body in bodies}
    start = benchmark_angles({body: trajectory.q[0, k] for body, k in columns.items()})
    for name, value in PUBLISHED_START.items():
        assert start[name] == pytest.approx(value, abs=1e-12), name
    for k in range(trajectory.t.size):
        angles = benchmark_angles({body: trajectory.q[k, c] for body, c in columns.items()})
        assert np.abs(loop_closure(angles)).max() < 1e-13
        # Velocities: d/dt g = (dg/dangles) . angle rates = 0, dg/dangles by central differences.
        rates = benchmark_angles({body: trajectory.dq[k, c] for body, c in columns.items()})
        derivative = np.zeros(6)
        for name, rate in rates.items():
            up, down = dict(angles), dict(angles)
            up[name] += 1e-6
            down[name] -= 1e-6
            derivative += (loop_closure(up) - loop_closure(down)) / 2e-6 * rate
        assert np.abs(derivative).max() < 1e-9 * max(1.0, max(map(abs, rates.values())))
    # E is named on four links and A on two: each link puts its E (its A) in the same place,
    # and A is the fixed point (xa, ya) of the benchmark.
    for name, links in (("E", ("rod", "link3", "link4", "link6")), ("A", ("link5", "link7"))):
        positions = [trajectory.point(link, name)[0] for link in links]
        for other in positions[1:]:
            assert np.abs(other - positions[0]).max() < 1e-13
    assert np.abs(trajectory.point("link7", "A")[0] - [XA, YA]).max() < 1e-15
