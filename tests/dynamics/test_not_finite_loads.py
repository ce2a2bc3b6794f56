"""A load that is infinite or undefined at a row (a force -F0/(t - 0.5) at t = 0.5) gives
efforts and reactions that are not finite there: the row is flagged and a warning names
them, on both backends; the other rows are unflagged and finite."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from symkin import cli

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def pole(tmp_path_factory) -> Path:
    text = (ROOT / "examples" / "crank_slider_load.yaml").read_text()
    assert 'f: ["-F0", 0]' in text
    path = tmp_path_factory.mktemp("pole") / "pole.yaml"
    path.write_text(text.replace('f: ["-F0", 0]', 'f: ["-F0/(t-0.5)", 0]'))
    return path


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_a_row_with_infinite_loads_is_flagged_and_named(pole, tmp_path, capsys, backend):
    out = tmp_path / "out.npz"
    status = cli.main(["run", str(pole), "--backend", backend, "-o", str(out)])
    err = capsys.readouterr().err
    assert status == 0, err
    assert "1 point flagged at t = 0.5: efforts or reactions are not finite" in err, err
    assert "motor.effort" in err and "B.Fx" in err
    data = np.load(out)
    t, flagged = data["t"], data["flagged"]
    at = np.flatnonzero(np.isclose(t, 0.5))
    assert at.size == 1 and flagged[at[0]]
    others = np.ones(t.size, dtype=bool)
    others[at] = False
    assert not flagged[others].any()
    assert not np.isfinite(data["effort"][at[0]]).all()
    assert np.isfinite(data["effort"][others]).all()
    assert np.isfinite(data["reaction"][others]).all()
    # Newton's second law for the slider along x at the finite rows: the rod's pull (joint
    # B, rod on slider), the load -F0/(t - 0.5), minus what the slider exerts on the ground
    # (joint slide) equal m3 times its acceleration
    joints = list(data["joint_names"])
    b, slide = data["reaction"][:, joints.index("B")], data["reaction"][:, joints.index("slide")]
    x = list(data["coordinates"]).index("slider.x")
    with np.errstate(divide="ignore"):
        load = -100.0 / (t - 0.5)
    balance = b[:, 0] + load - slide[:, 0] - 3.0 * data["d2q"][:, x]
    assert np.abs(balance[others]).max() < 1e-9 * np.abs(load[others]).max()
