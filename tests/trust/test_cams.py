"""Cams: a cusp is found where c'(s) reverses between two samples, not only where a sample
lands on |c'| = 0.

Reference: a flat-faced follower's disk cam drawn from the lift law L(s) = h (1 - cos 2s) / 2
as the envelope of the face (support function p = r_b + L): its radius of curvature is
p + p'' = r_b + h/2 + 3h/2 cos 2s, so with r_b = 1, h = 2 the first cusp is at
s = acos(-2/3) / 2; with h = 0.5 there is none, and the face then sits at x = p(t) when the
cam has turned by -t (the support function in the direction of the global x axis).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

import symkin
from symkin.errors import MechanismError
from symkin.pairs.planar.cam import SAMPLES
from symkin.spec.validate import from_dict

HERE = Path(__file__).resolve().parent


def _document(h: float) -> dict:
    document = yaml.safe_load((HERE / "flat_cam_cusp.yaml").read_text(encoding="utf-8"))
    document["parameters"]["h"] = h
    return document


def test_a_cusp_between_samples_is_refused_where_it_is() -> None:
    with pytest.raises(MechanismError, match="cusp") as caught:
        from_dict(_document(2.0))
    at = float(re.search(r"at s = (-?\d+(?:\.\d+)?)", str(caught.value)).group(1))
    assert abs(at - math.acos(-2 / 3) / 2) <= 2 * math.pi / SAMPLES


def test_the_same_law_without_a_cusp_runs_on_its_support_function() -> None:
    rb, h = 1.0, 0.5
    system = symkin.derive(from_dict(_document(h)))
    result = symkin.solve(symkin.compile(system, backend="numpy"))
    x = result.q[:, result.coordinates.index("follower.x")]
    expected = rb + h * (1 - np.cos(2 * result.t)) / 2
    assert np.abs(x - expected).max() < 1e-9
