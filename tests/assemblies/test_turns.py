"""Assemblies at inputs that have turned many times: an encoder that counts turns drives a
crank to 30 or 1e6 rad, and the assemblies there are those at the same angle less whole turns.
The search's starts spread each angle over the turn of the assembly found first; from
[-pi, pi), as before, Newton had to travel the turns in capped steps and the scan found one
assembly of the crank-slider's two from 30 rad on (of the 3-RRR's, from three turns on)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.runtime.scanning.assemblies import Shape

ROOT = Path(__file__).resolve().parents[2]


def _configurations(report, shape: Shape) -> list[np.ndarray]:
    return sorted((shape.canonical(branch.q) for branch in report.branches),
                  key=lambda q: tuple(np.round(q, 6)))


@pytest.mark.parametrize("name, inputs", [("crank_slider_input", (1.2,)),
                                          ("three_rrr_fk", (0.1, 0.2, -0.1))])
def test_whole_turns_of_the_inputs_leave_the_assemblies_as_they_are(name: str, inputs) -> None:
    kernel = compiled(ROOT / "examples" / f"{name}.yaml", "numpy")  # from its goldens
    shape = Shape(tuple(kernel.coordinates))
    base = _configurations(symkin.scan(kernel, inputs=list(inputs)), shape)
    assert len(base) >= 2
    for turns in (5, 160000):  # 31 rad, and an encoder's 1e6 rad
        shifted = [u + 2 * math.pi * turns for u in inputs]
        found = _configurations(symkin.scan(kernel, inputs=shifted), shape)
        assert len(found) == len(base), turns
        for a, b in zip(found, base):
            # the same configurations, to the rounding of angles of 1e6 rad
            assert np.abs(shape.difference(a, b)).max() <= 1e-9 * (1 + 2 * math.pi * turns)
