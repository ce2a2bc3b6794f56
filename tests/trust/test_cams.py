"""Cams: a cusp is found where c'(s) reverses between two samples, not only where a sample
lands on |c'| = 0.

Reference: a flat-faced follower's disk cam drawn from the lift law L(s) = h (1 - cos 2s) / 2
as the envelope of the face (support function p = r_b + L): its radius of curvature is
p + p'' = r_b + h/2 + 3h/2 cos 2s, so with r_b = 1, h = 2 the first cusp is at
s = acos(-2/3) / 2; with h = 0.5 there is none, and the face then sits at x = p(t) when the
cam has turned by -t (the support function in the direction of the global x axis), touching
at s = t. The reported curvature_radius is that signed p + p'', negative past a cusp.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import yaml

import symkin
from symkin.errors import MechanismError
from symkin.pairs.planar.cam import SAMPLES
from symkin.spec.validate import from_dict
from symkin.symbolic.outputs import with_mechanism_outputs

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


@functools.cache
def _without_cusp(h: float) -> tuple[symkin.System, symkin.Trajectory]:
    """The file with lift h derived, compiled (NumPy) and run once for the tests here."""
    system = symkin.derive(from_dict(_document(h)))
    return system, symkin.solve(symkin.compile(system, backend="numpy"))


def test_the_same_law_without_a_cusp_runs_on_its_support_function() -> None:
    rb, h = 1.0, 0.5
    _, result = _without_cusp(h)
    x = result.q[:, result.coordinates.index("follower.x")]
    expected = rb + h * (1 - np.cos(2 * result.t)) / 2
    assert np.abs(x - expected).max() < 1e-9


@dataclass(frozen=True)
class _Configurations:
    """What the outputs are evaluated on: a Trajectory's t, q, dq and params."""

    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    params: np.ndarray
    outputs: tuple = ()


def _support_radius(rb: float, h: float, s: np.ndarray) -> np.ndarray:
    """p + p'' of p = r_b + h (1 - cos 2s) / 2."""
    return rb + h / 2 + 1.5 * h * np.cos(2 * s)


def test_a_flat_faced_cams_curvature_radius_is_p_plus_p_second_on_a_run() -> None:
    rb, h = 1.0, 0.5
    result = symkin.with_outputs(*_without_cusp(h))
    s = result.q[:, result.coordinates.index("k1.s")]
    assert np.abs(s - result.t).max() < 1e-9
    radius = dict(result.outputs)["k1.curvature_radius"]
    assert np.abs(radius - _support_radius(rb, h, result.t)).max() < 1e-9


def test_the_curvature_radius_keeps_its_sign_through_a_cusp() -> None:
    """The file is accepted with h = 0.5; its outputs are evaluated with h = 2 at the exact
    configurations that touch at s (cam turned by -s, face at x = p(s)): beyond the cusp,
    where p + p'' < 0, the radius is negative, not |p + p''|."""
    rb, h = 1.0, 2.0
    mech = from_dict(_document(0.5))
    s = np.linspace(0.0, math.pi, 41)
    names = [f"{body}.{c}" for body in ("cam", "follower") for c in ("x", "y", "phi")]
    names.append("k1.s")
    columns = {"cam.phi": -s, "follower.x": rb + h * (1 - np.cos(2 * s)) / 2, "k1.s": s}
    q = np.column_stack([columns.get(name, 0 * s) for name in names])
    run = _Configurations(t=s, q=q, dq=np.zeros_like(q), params=np.array([rb, h]))
    radius = dict(with_mechanism_outputs(mech, run).outputs)["k1.curvature_radius"]
    expected = _support_radius(rb, h, s)
    assert (expected < -0.5).any()
    assert np.abs(radius - expected).max() < 1e-9
