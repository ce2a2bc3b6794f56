"""Bad spatial input is refused with a located message (exit 2 on the CLI), never a
traceback; a planar file is unchanged by the spatial family."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

import symkin
from symkin import cli
from symkin.errors import MechanismError

ROOT = Path(__file__).resolve().parents[2]
RSSR = yaml.safe_load((ROOT / "examples" / "rssr.yaml").read_text())


def _universal_askew(d):
    d["joints"][1] = {"type": "universal", "name": "rocker_pivot", "i": "ground",
                      "j": "rocker", "at": "B0", "axes": [[1, 0, 0], [1, 1, 0]]}


CASES = {
    "unknown_point": (lambda d: d["joints"][0].update(at="Q"), "joints[0].at",
                      "has a point named 'Q'"),
    "zero_axis": (lambda d: d["joints"][0].update(axis=[0, 0, 0]), "joints[0].axis",
                  "the axis is zero"),
    "two_vector_point": (lambda d: d["bodies"]["crank"]["points"].update(A=[0.1, 0]),
                         "bodies.crank.points.A", "expected a vector [x, y, z]"),
    "two_vector_axis": (lambda d: d["joints"][0].update(axis=[0, 1]), "joints[0].axis",
                        "expected a vector [x, y, z]"),
    "unknown_space": (lambda d: d.update(space="4d"), "space", "unknown space '4d'"),
    "angle_on_a_rod": (lambda d: d["drivers"][0].update(joint="coupler"), "drivers[0].joint",
                       "has no axis to drive"),
    "angle_on_no_joint": (lambda d: d["drivers"][0].update(joint="nope"), "drivers[0].joint",
                          "no joint named 'nope'"),
    "universal_askew": (_universal_askew, "joints[1].axes", "not perpendicular"),
    "planar_type": (lambda d: d["joints"][0].update(type="pin_slot"), "joints[0].type",
                    "'pin_slot' is not a type of a space: 3d file"),
    "planar_coordinate": (lambda d: d["drivers"].__setitem__(
        0, {"type": "custom", "equations": ["crank.phi - t"]}), "drivers[0].equations[0]",
        "use body.x, body.y, body.z, body.e0"),
    "parameter_named_E": (lambda d: d["parameters"].update(E=1), "parameters.E",
                          "'E' is a constant"),
    "frame_angle": (lambda d: d["bodies"]["crank"].update(frame={"origin": "A", "angle": 1}),
                    "bodies.crank.frame", "give only its origin"),
    "rod_of_no_length": (lambda d: d["joints"][2].update(length=0), "joints[2].length",
                         "is not positive"),
    "huge_time_step_count": (lambda d: d["time"].update(dt=1e-12), "time.dt",
                             "more than"),
}


@pytest.mark.parametrize("case", CASES)
def test_bad_spatial_input_is_refused_where_it_is(case: str) -> None:
    edit, where, said = CASES[case]
    data = copy.deepcopy(RSSR)
    edit(data)
    with pytest.raises(MechanismError) as caught:
        symkin.from_dict(data)
    assert f"at {where}:" in str(caught.value)
    assert said in str(caught.value)


def test_the_cli_exits_2_with_the_line(tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    data = copy.deepcopy(RSSR)
    data["joints"][0]["axis"] = [0, 0, 0]
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    code = cli.main(["run", str(path)])  # in this process; a real one's exit is tests/cli's
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err
    assert f"{path}:" in err and "the axis is zero" in err


def test_animate_of_a_spatial_file_is_drawn(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    """Once refused (exit 2); now an isometric GIF (tests/present/test_view3d.py checks it).
    Eleven frames (--dt 0.1) draw it as well as the file's 101."""
    code = cli.main(["run", str(ROOT / "examples" / "rssr.yaml"), "--backend", "numpy",
                     "--dt", "0.1", "--animate", str(tmp_path / "a.gif")])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "a.gif").stat().st_size > 0


def test_a_planar_file_with_space_2d_is_the_planar_file() -> None:
    data = yaml.safe_load((ROOT / "examples" / "crank_slider.yaml").read_text())
    plain = symkin.from_dict(data)
    marked = symkin.from_dict({**data, "space": "2d"})
    assert not marked.is_spatial
    assert marked.spec_hash() == plain.spec_hash()


def test_a_second_driver_is_judged_by_the_rank_and_flagged_where_it_conflicts() -> None:
    """More driving equations than freedoms is no longer refused by the count (joints may
    repeat each other): the rank at t0 removes rows (joint rows before drivers), and where the
    second driver conflicts with the first along the motion the removed rows break and the
    points are flagged -- never a silently wrong motion."""
    data = copy.deepcopy(RSSR)
    data["drivers"].append({"type": "angle", "joint": "rocker_pivot", "theta": "t"})
    system = symkin.derive(symkin.from_dict(data))
    assert system.removed and all(r.row.section == "joints" for r in system.removed)
    trajectory = symkin.solve(symkin.compile(system, backend="numpy"))
    assert trajectory.flagged[1:].all()
    assert np.abs(trajectory.removed_residual[1:]).max() > 1e-3
