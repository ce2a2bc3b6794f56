"""Exact numbers reach NumPy as doubles: a long decimal or a huge integer in a file (read
exactly, as a rational) used to end in NumPy's "no callable sqrt method" wherever derived
expressions were lambdified.

The reference is the Cardan joint's closed form, tan th2 = tan th1 / cos(beta), derived by
hand in tests/spatial/test_spatial_examples.py's manner: the files here write the output axis
(cos 30 deg, sin 30 deg) as a 17-digit decimal and as integers near 1e18.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from codegen_support import compiled

import symkin
from symkin import cli
from symkin.runtime.outputs.spatial import rotation
from symkin.spec import constants

HERE = Path(__file__).resolve().parent
FILES = ["cardan_long_decimals.yaml", "cardan_huge_axis.yaml"]


@pytest.mark.parametrize("name", FILES)
def test_show_of_an_axis_written_exactly_runs(name: str,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["show", str(HERE / name)]) == 0
    assert "removed as redundant" in capsys.readouterr().out


@pytest.mark.parametrize("name", FILES)
def test_the_cardan_written_exactly_follows_its_closed_form(name: str) -> None:
    assert_cardan(symkin.solve(compiled(HERE / name, "numpy")))


def assert_cardan(result: symkin.Trajectory) -> None:
    """The output shaft of examples/cardan.yaml's joint (beta = 30 deg) turned by th2,
    tan th2 = tan th1 / cos(beta), on the branch continuous with th1 = 2 pi t."""
    beta = math.pi / 6
    th1 = 2 * np.pi * result.t
    th2 = np.arctan2(np.sin(th1), np.cos(th1) * np.cos(beta))
    q, _, _ = result.body("shaft2")
    arm = rotation(q[:, 3:]) @ np.array([0, 0, 1.0])
    axis = np.array([np.cos(beta), np.sin(beta), 0.0])
    expected = (np.cos(th2)[:, None] * np.array([0, 0, 1.0])
                + np.sin(th2)[:, None] * np.cross(axis, [0, 0, 1.0]))
    assert np.abs(arm - expected).max() < 1e-10


def test_lambdify_floats_evaluates_a_square_root_wider_than_64_bits() -> None:
    x = sp.Symbol("x")
    big = 2**70 + 1
    f = constants.lambdify_floats([x], [sp.sqrt(big) * x, sp.Rational(10**20 + 1, 10**20)])
    values = f(np.array([1.0, 2.0]))
    assert np.allclose(values[0], math.sqrt(float(big)) * np.array([1.0, 2.0]), rtol=1e-15)
    assert values[1] == 1.0 + 1e-20
