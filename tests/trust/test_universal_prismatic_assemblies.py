"""Issue 41's rule for scans, carried to the universal and the spatial prismatic joints:
assemblies are distinct configurations of the bodies, and a solution of the rows that is no
assembly of the joint is not one.

- A universal joint's row (the cross's arm in i perpendicular to its arm in j) holds exactly
  on the Hooke joint's configurations (turning about the two arms reaches every one of them),
  so it adds no spurious assembly. The Cardan shaft's two assemblies are genuine: the output
  shaft as drawn and turned half a turn about its own axis (the cross is two-fold symmetric:
  tan(theta_out) = tan(theta_in) / cos(beta) fixes the output angle modulo pi only).
- A spatial prismatic joint's rows also held with the slider turned half a turn about the
  axis or across it (16 assemblies of the spatial slider-crank were 4 genuine ones, each four
  times): its senses now count only the slider as drawn.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
BETA = np.pi / 6  # examples/cardan.yaml


def _branches(name: str) -> tuple[tuple[str, ...], list[np.ndarray]]:
    kernel = compiled(EXAMPLES / f"{name}.yaml", "numpy")
    # the assemblies at t = 0; the motion from the taken one (not looked at) one step long
    report = symkin.scan(kernel, t=np.array([0.0, 0.01]))
    return report.coordinates, [branch.q for branch in report.branches]


def _euler(coordinates: tuple[str, ...], q: np.ndarray, body: str) -> np.ndarray:
    return np.array([q[coordinates.index(f"{body}.e{k}")] for k in range(4)])


def test_the_cardan_has_two_genuine_assemblies_half_a_turn_apart() -> None:
    coordinates, found = _branches("cardan")
    assert len(found) == 2
    drawn, turned = (_euler(coordinates, q, "shaft2") for q in found)
    assert drawn == pytest.approx([1, 0, 0, 0], abs=1e-9)
    # half a turn (e0 = 0) about shaft 2's own axis, (cos beta, sin beta, 0)
    axis = np.array([np.cos(BETA), np.sin(BETA), 0.0])
    assert turned[0] == pytest.approx(0, abs=1e-9)
    assert abs(turned[1:] @ axis) == pytest.approx(1, abs=1e-9)
    # the input shaft is where the driver puts it in both
    for q in found:
        assert _euler(coordinates, q, "shaft1") == pytest.approx([1, 0, 0, 0], abs=1e-9)


def test_the_spatial_slider_crank_has_four_assemblies_with_its_slider_as_drawn() -> None:
    coordinates, found = _branches("spatial_slider_crank")
    assert len(found) == 4  # was 16: each also with the slider turned half a turn, 3 ways
    slider_x = sorted(round(float(q[coordinates.index("slider.x")]), 9) for q in found)
    b0 = np.sqrt(0.4**2 - 0.18**2 - 0.12**2)  # the slider's x in closed form
    assert slider_x == pytest.approx([-b0, -b0, b0, b0], abs=1e-9)
    for q in found:
        assert _euler(coordinates, q, "slider") == pytest.approx([1, 0, 0, 0], abs=1e-9)
