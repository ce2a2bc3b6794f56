"""Scans count assemblies, not solutions of Phi = 0: a spatial revolute's two rows hold with
its axis reversed too, and a spatial angle driver's row with the crank half a turn away; the
generated ``senses`` (an axes' cosine, cos(theta - psi)) tell them apart.

References, derived here:
- RSSR (examples/rssr.yaml) at t = 0: the crank's point A = (a, 0, 0) with a = 0.1, the
  rocker's B = B0 + c (0, cos psi, sin psi) with B0 = (0.5, 0, 0.4), c = 0.4 and the rod's
  length from the drawing, L^2 = 0.48: |B - A|^2 = 0.48 + 0.32 sin psi, so sin psi = 0 and
  psi = 0 or pi: 2 assemblies (the rocker's Euler parameters (cos psi/2, sin psi/2, 0, 0)).
- A spherical four-bar: with the crank set, the coupler's far axis lies on two circles of the
  unit sphere (about the crank's distal axis and about the rocker's fixed axis): 2
  assemblies away from the limits.
- A planar four-bar away from its crank's limits: the rocker pin lies on two circles in the
  plane, which meet twice: 2 assemblies.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.cli.scan import text
from symkin.runtime.driver import SolveFailure
from symkin.runtime.scanning.scan import Branch, ScanReport, distinguishing, scan

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parents[1] / "examples"
# The branches are the assemblies at t[0] (0 in every file here); the motion a scan then
# follows from the taken one is not what these tests count, so it is followed one step only.
AT_T0 = np.array([0.0, 0.01])


@pytest.fixture(scope="module")
def rssr():
    return compiled(EXAMPLES / "rssr.yaml", "numpy")


@pytest.fixture(scope="module")
def rssr_c():
    return compiled(EXAMPLES / "rssr.yaml", "c")


def _block(kernel, body: str) -> list[int]:
    return [kernel.coordinates.index(f"{body}.e{k}") for k in range(4)]


def test_rssr_has_two_assemblies_the_rocker_at_0_and_pi(rssr) -> None:
    report = scan(rssr, t=AT_T0)
    assert len(report.branches) == 2
    rocker, crank = _block(rssr, "rocker"), _block(rssr, "crank")
    halves = sorted(abs(float(branch.q[rocker][1])) for branch in report.branches)
    assert halves == pytest.approx([0.0, 1.0], abs=1e-9)  # sin(psi / 2), psi = 0 and pi
    for branch in report.branches:
        # the crank at theta(0) = 0, not half a turn away: e = +-(1, 0, 0, 0)
        assert abs(float(branch.q[crank][0])) == pytest.approx(1.0, abs=1e-9)
        assert rssr.sense_values(branch.q, 0.0) == pytest.approx([1, 1, 1], abs=1e-9)


def _crank_turned_by_pi(kernel) -> np.ndarray:
    """A q0 that solves Phi = 0 with the crank turned by pi (its driver's row holds there;
    A = (-a, 0, 0), so |B - A|^2 = 0.68 + 0.32 sin psi = 0.48 puts the rocker at
    sin psi = -0.625)."""
    q0 = np.array(kernel.q0, dtype=float)
    q0[_block(kernel, "crank")] = [0.0, 0.0, 0.0, 1.0]
    psi = math.asin(-0.625)
    q0[_block(kernel, "rocker")] = [math.cos(psi / 2), math.sin(psi / 2), 0.0, 0.0]
    return q0


def test_no_run_from_the_crank_half_a_turn_away(rssr, rssr_c) -> None:
    q0 = _crank_turned_by_pi(rssr)
    assert np.abs(rssr.phi(q0, 0.0)).max() < 1e-12  # a solution of Phi = 0 ...
    assert rssr.sense_values(q0, 0.0)[2] == pytest.approx(-1.0)  # ... half a turn away
    for kernel in (rssr, rssr_c):
        with pytest.raises(SolveFailure, match="half a turn") as caught:
            symkin.solve(kernel, q0=q0)
        assert caught.value.reason == "no assembly"
        assert caught.value.rows == ("drivers[0] angle ground-crank (sense)",)
        assert caught.value.trajectory.t.size == 0
    assert symkin.solve(rssr).q.shape[0] == 101  # from the file's q0 it runs


def test_the_c_kernels_senses_are_the_numpy_kernels(rssr, rssr_c) -> None:
    c = rssr_c
    assert c.senses == rssr.senses and len(c.senses) == 3
    rng = np.random.default_rng(41)
    for _ in range(5):
        q = rng.normal(size=len(rssr.coordinates))
        t = float(rng.uniform())
        assert c.sense_values(q, t) == pytest.approx(rssr.sense_values(q, t), abs=1e-12)


def test_a_spherical_four_bar_has_two_assemblies_printed_apart() -> None:
    kernel = compiled(HERE / "spherical_four_bar.yaml", "numpy")
    report = scan(kernel, t=AT_T0)
    assert len(report.branches) == 2
    lines = [line.split(";")[0].split(":", 1)[1]
             for line in text(report, "s", "g").splitlines() if re.match(r"  \d+", line)]
    assert len(lines) == 2 and lines[0] != lines[1]


def test_a_planar_four_bar_has_two_assemblies() -> None:
    kernel = compiled(EXAMPLES / "four_bar.yaml", "numpy")
    assert len(scan(kernel, t=AT_T0).branches) == 2


def test_the_coordinates_shown_tell_every_two_branches_apart() -> None:
    """Three branches: the two coordinates that spread most (a, b) leave branches 0 and 1
    alike; a third (c) is added, which tells them apart."""
    qs = [[0.0, 0.0, 0.1], [0.0, 0.0, 0.2], [5.0, 4.0, 0.1]]
    report = ScanReport(("a", "b", "c"), 0.0, 1.0,
                        tuple(Branch(np.array(q), 1.0, k == 0) for k, q in enumerate(qs)), ())
    shown = distinguishing(report)
    assert shown == [0, 1, 2]
    assert len({tuple(q[c] for c in shown) for q in qs}) == 3


def test_distinct_branches_alike_in_every_coordinate_as_printed_add_nothing() -> None:
    report = ScanReport(("a", "b"), 0.0, 1.0,
                        (Branch(np.array([1.0, 0.0]), 1.0, True),
                         Branch(np.array([2.0, 1e-300]), 1.0, False),
                         Branch(np.array([2.0, -1e-300]), 1.0, False)), ())
    assert distinguishing(report) == [0]
    assert math.isfinite(report.branches[1].q[1])
