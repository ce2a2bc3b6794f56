"""The freedoms of an over-constrained spatial file: the rank over every row a coordinate is
subject to, the Euler parameters' normalisation rows included.

References: a spherical four-bar (four revolutes whose axes meet at one point) and a Cardan
joint each have one degree of freedom (their textbook mobility); the spherical four-bar's
frames all sit at the joints' common point, where leaving out the normalisation rows counted
4. Its motion is checked against what a spherical four-bar keeps: every axis through O, and
the angle between each pair of axes of one body fixed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled, derived

import symkin
from symkin import cli
from symkin.runtime.outputs.spatial import rotation

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parents[1] / "examples"
# each revolute: (body i, body j, its axis as drawn, which is also its local vector in both
# bodies, whose frames are drawn with the global axes)
CHAIN = [("ground", "crank", [0, 0, 1]), ("crank", "coupler", [1, 0, 1]),
         ("coupler", "rocker", [1, 1, 1]), ("rocker", "ground", [0, 1, 1])]


@pytest.mark.parametrize("path", [HERE / "spherical_four_bar.yaml", EXAMPLES / "cardan.yaml"],
                         ids=["spherical_four_bar", "cardan"])
def test_an_over_constrained_spatial_linkage_has_one_freedom(path: Path) -> None:
    assert derived(path).mobility == 1


def test_show_prints_one_freedom(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["show", str(HERE / "spherical_four_bar.yaml")]) == 0
    out = capsys.readouterr().out
    assert "21 coordinates, 21 equations, 1 degree(s) of freedom" in out
    assert "1 by the rank of the joints' and the normalisation rows at t0" in out


def test_the_spherical_four_bar_moves_as_one() -> None:
    """Each body's two joint axes, drawn at t0, stay where its neighbours' are: the crank's
    second axis is the coupler's first, and so on, as the crank turns by 0.5 rad."""
    result = symkin.solve(compiled(HERE / "spherical_four_bar.yaml", "numpy"))
    turned = {name: rotation(result.body(name)[0][:, 3:]) for name in ("crank", "coupler",
                                                                         "rocker")}
    turned["ground"] = np.broadcast_to(np.eye(3), turned["crank"].shape)
    for a, b, axis in CHAIN:
        local = np.array(axis, float) / np.linalg.norm(axis)
        assert np.abs(turned[a] @ local - turned[b] @ local).max() < 1e-10, (a, b)
    crank = turned["crank"] @ np.array([1.0, 0, 0])
    assert np.arctan2(crank[-1, 1], crank[-1, 0]) == pytest.approx(0.5, abs=1e-12)
    rocker_moved = np.abs(turned["rocker"][-1] - turned["rocker"][0]).max()
    assert rocker_moved > 1e-2
