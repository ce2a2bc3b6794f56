"""Inputs found by fuzzing that once gave a traceback instead of a result or a located message.

Huge coordinates (1e200, 1e300): a sum of squares of Python floats raises OverflowError where
a product only overflows to inf; the checks that two points are apart or a direction non-zero
now use hypot/dist, which scale.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import symkin
from symkin import cli
from symkin.errors import MechanismError
from symkin.spec.validate import from_dict, load

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _pendulum3d(axis: list[float], point: list[float]) -> dict:
    return {"name": "pendulum3d", "space": "3d", "layout": "drawn",
            "bodies": {"crank": {"points": {"O": [0, 0, 0], "A": point}}},
            "joints": [{"type": "revolute", "name": "pivot", "i": "ground", "j": "crank",
                        "at": "O", "axis": axis}],
            "drivers": [{"type": "angle", "joint": "pivot", "theta": "t"}],
            "time": {"t0": 0, "t1": 1, "dt": 0.1}}


def test_a_spatial_rod_of_huge_length_loads() -> None:
    # rssr's distance rod with the rocker 1e300 long: was OverflowError in the apart check
    mech = load(EXAMPLES / "rssr.yaml", {"c": "1e300"})
    assert symkin.derive(mech).p_values[list(mech.parameters).index("c")] == 1e300


def test_a_huge_drawn_axis_is_a_direction() -> None:
    # the axis [1e200, 0, 0] is the x axis; its length squared overflowed
    mech = from_dict(_pendulum3d([1e200, 0, 0], [0, 1, 0]))
    system = symkin.derive(mech)
    assert len(system.rows) == len(system.q)


def test_a_zero_drawn_axis_is_still_refused() -> None:
    with pytest.raises(MechanismError, match="the axis is zero"):
        from_dict(_pendulum3d([0, 0, 0], [0, 1, 0]))


def test_show_with_a_huge_set_value_exits_0(capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["show", str(EXAMPLES / "rssr.yaml"), "--set", "c=1e300"]) == 0
    assert "Traceback" not in capsys.readouterr().err
