"""Every assembly of Dietmaier's general 6-6 Stewart-Gough platform: symkin.scan finds 40.

A general 6-6 platform has 40 complex assemblies at given leg lengths (Raghavan 1993; Ronga
and Vust; Lazard; Mourrain), so 40 real ones are the most there can be, and Dietmaier (1998)
found leg lengths at which all 40 are real. Here the published geometry and lengths (six
digits) are typed in again, independently of tests/assemblies/dietmaier.yaml (checked
against them), and every assembly the scan reports is checked with them in closed form: each
leg's length |x + R(e) b_i - a_i| equals the published one. Forty distinct poses that close
every leg are all the assemblies there are, with no independent count needed: the bound
makes the count complete.

At six digits the instance is near singular (CuikSuite's documentation notes points about
1e-8 from being solutions along a curve): four of the 40 lie within a condition of about
1e5..1e6 of where branches meet, and the scan marks them so.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from motion_support import kernel as built

from symkin.runtime.scanning.scan import scan
from tests.assemblies.test_every_assembly import _rotation

HERE = Path(__file__).resolve().parent

BASE = np.array([[0, 0, 0], [1.107915, 0, 0], [0.549094, 0.756063, 0],
                 [0.735077, -0.223935, 0.525991], [0.514188, -0.526063, -0.368418],
                 [0.590473, 0.094733, -0.205018]])
PLATFORM = np.array([[0, 0, 0], [0.542805, 0, 0], [0.956919, -0.528915, 0],
                     [0.665885, -0.353482, 1.402538], [0.478359, 1.158742, 0.107672],
                     [-0.137087, -0.235121, 0.353913]])  # in the platform's frame
LEGS = np.array([1, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071])


def _poses(found) -> list[tuple[np.ndarray, np.ndarray]]:
    names = list(found.coordinates)
    r = [names.index(f"platform.{c}") for c in "xyz"]
    e = [names.index(f"platform.e{k}") for k in range(4)]
    return [(_rotation(branch.q[e]), branch.q[r]) for branch in found.branches]


def test_the_file_holds_the_published_geometry() -> None:
    spec = yaml.safe_load((HERE / "dietmaier.yaml").read_text())
    base = spec["bodies"]["ground"]["points"]
    body = spec["bodies"]["platform"]
    origin = np.array(body["frame"]["origin"], dtype=float)
    for k in range(6):
        assert base[f"A{k + 1}"] == pytest.approx(BASE[k].tolist(), abs=0)
        drawn = np.array(body["points"][f"B{k + 1}"], dtype=float)
        assert drawn - origin == pytest.approx(PLATFORM[k], abs=1e-15)


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_scan_finds_the_forty_real_assemblies(backend: str) -> None:
    kernel = built(HERE / "dietmaier.yaml", backend)
    found = scan(kernel, inputs=dict(zip(kernel.input_names, LEGS)))
    poses = _poses(found)
    assert len(poses) == 40
    for rotation, origin in poses:  # to Newton's tolerance on Phi (tol_phi, 1e-10)
        assert np.abs(rotation.T @ rotation - np.eye(3)).max() < 1e-10
        lengths = np.linalg.norm(PLATFORM @ rotation.T + origin - BASE, axis=1)
        assert np.abs(lengths - LEGS).max() < 1e-10
    # forty different poses, not one found twice (seen: the closest two 0.155 apart)
    closest = min(max(np.abs(ra - rb).max(), np.abs(ta - tb).max())
                  for a, (ra, ta) in enumerate(poses) for rb, tb in poses[a + 1:])
    assert closest > 1e-2
    assert sum(branch.near_singular for branch in found.branches) == 4
