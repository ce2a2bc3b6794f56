"""The gear and rack pairs (symkin/pairs/planar/gear.py, rack.py) against closed forms derived
here: Willis' formula for a planetary set with one planet, and the rack's displacement
-r (phi_i - phi_j) driving a four-bar-like linkage solved by circle intersection; both
backends, the C one compiled and run. Then their meaning (offset, side, carrier), the drawn
layout, and bad input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from codegen_support import derived
from driver_support import BACKENDS, kernel_for

import symkin
from symkin.errors import MechanismError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
RS, RP, W = 1.0, 0.5, 2.0


@pytest.fixture(scope="module")
def planetary():
    return derived(EXAMPLES / "planetary.yaml")  # the run's shared derivation


@pytest.mark.parametrize("backend", BACKENDS)
def test_planetary_set_follows_willis(planetary, backend: str) -> None:
    """Ring fixed (ground), sun driven at W: relative to the arm, (w_s - w_a) / (0 - w_a) =
    -R / S with R = S + 2P, so w_a = W S / (2 S + 2 P); the planet turns relative to the arm
    by -(S / P)(w_s - w_a). Positions within 1e-9, velocities 1e-8, accelerations 1e-6."""
    kernel = kernel_for(planetary, backend)
    assert kernel.backend == backend
    run = symkin.solve(kernel)
    w_arm = W * RS / (2 * RS + 2 * RP)
    w_planet = w_arm - RS / RP * (W - w_arm)
    column = {name: planetary.coordinates.index(name) for name in planetary.coordinates}
    for body, rate in (("sun", W), ("arm", w_arm), ("planet", w_planet)):
        k = column[f"{body}.phi"]
        assert np.abs(run.q[:, k] - rate * run.t).max() < 1e-9, body
        assert np.abs(run.dq[:, k] - rate).max() < 1e-8, body
        assert np.abs(run.d2q[:, k]).max() < 1e-6, body
    # the planet's centre on the arm, at S + P from the centre
    centre = run.q[:, [column["planet.x"], column["planet.y"]]]
    expected = (RS + RP) * np.stack([np.cos(w_arm * run.t), np.sin(w_arm * run.t)], 1)
    assert np.abs(centre - expected).max() < 1e-9
    assert not run.flagged.any()


def test_gear_rows_and_counts(planetary) -> None:
    rows = [str(row) for row in planetary.rows if row.type == "gear"]
    assert rows == ["joints[3] mesh_sun gear sun-planet-arm (rolling)",
                    "joints[4] mesh_ring gear planet-ground-arm (rolling)"]
    assert planetary.dof == 1


def _three_planets() -> dict:
    """Three planets 120 degrees apart: the meshings of two are redundant."""
    bodies = {"sun": {"q0": [0, 0, 0]}, "arm": {"q0": [0, 0, 0], "points": {}}}
    joints = [{"type": "revolute", "i": "ground", "j": "sun", "sA": [0, 0], "sB": [0, 0]},
              {"type": "revolute", "i": "ground", "j": "arm", "sA": [0, 0], "sB": [0, 0]}]
    for k in range(3):
        angle = 2 * math.pi * k / 3
        hub = [(RS + RP) * math.cos(angle), (RS + RP) * math.sin(angle)]
        bodies["arm"]["points"][f"h{k}"] = hub
        bodies[f"p{k}"] = {"q0": [*hub, 0]}
        joints += [{"type": "revolute", "i": "arm", "j": f"p{k}", "sA": f"h{k}",
                    "sB": [0, 0]},
                   {"type": "gear", "name": f"s{k}", "i": "sun", "j": f"p{k}",
                    "radii": [RS, RP], "carrier": "arm"},
                   {"type": "gear", "name": f"r{k}", "i": f"p{k}", "j": "ground",
                    "radii": [RP, RS + 2 * RP], "carrier": "arm", "internal": True}]
    return {"name": "three_planets", "parameters": {}, "bodies": bodies, "joints": joints,
            "drivers": [{"type": "angle", "i": "sun", "j": "ground", "theta": "2*t"}],
            "time": {"t0": 0, "t1": 1, "dt": 0.1}}


def test_three_planets_are_accepted_and_follow_willis() -> None:
    system = symkin.derive(symkin.from_dict(_three_planets()))
    run = symkin.solve(kernel_for(system, "numpy"))
    k = system.coordinates.index("arm.phi")
    assert np.abs(run.q[:, k] - 2 * RS / (2 * RS + 2 * RP) * run.t).max() < 1e-9


def _gears(**gear) -> dict:
    return {"name": "pair", "parameters": {"r1": 1.0, "r2": 2.0},
            "bodies": {"a": {"q0": [0, 0, 0.3]}, "b": {"q0": [3, 0, -0.1]}},
            "joints": [{"type": "revolute", "i": "ground", "j": "a", "sA": [0, 0],
                        "sB": [0, 0]},
                       {"type": "revolute", "i": "ground", "j": "b", "sA": [3, 0],
                        "sB": [0, 0]},
                       {"type": "gear", "name": "g", "i": "a", "j": "b",
                        "radii": ["r1", "r2"], **gear}],
            "drivers": [{"type": "angle", "i": "a", "j": "ground", "theta": "0.3 + t"}],
            "time": {"t0": 0, "t1": 1, "dt": 0.25}}


def test_gear_offset_defaults_to_q0_and_may_be_given() -> None:
    """External pair on the ground: r1 (phi_a - 0.3) = -r2 (phi_b + 0.1) by default; with
    offset: r1 phi_a + r2 phi_b = offset."""
    run = symkin.solve(kernel_for(symkin.derive(symkin.from_dict(_gears())), "numpy"))
    assert np.abs(run.q[:, 5] - (-0.1 - 1.0 / 2.0 * run.t)).max() < 1e-12
    given = symkin.from_dict(_gears(offset=1.0))
    run = symkin.solve(kernel_for(symkin.derive(given), "numpy"))
    assert np.abs(1.0 * run.q[:, 2] + 2.0 * run.q[:, 5] - 1.0).max() < 1e-12


@pytest.mark.parametrize(("gear", "said"), [
    ({"radii": [0, 2]}, "pitch radius 0 is not positive"),
    ({"carrier": "a"}, "the carrier 'a' is one of the two gears"),
    ({"internal": True, "radii": [2, 1]}, "must be larger than the pinion"),
    ({"carrier": "nobody"}, "unknown body 'nobody'"),
    ({"j": "a"}, "meshes body 'a' with itself"),
])
def test_bad_gears_are_refused_where_they_are(gear: dict, said: str) -> None:
    data = _gears()
    data["joints"][2] = {**data["joints"][2], **gear}
    with pytest.raises(MechanismError, match=said) as error:
        symkin.from_dict(data)
    assert "joints[2]" in str(error.value)


# ----- rack and pinion -------------------------------------------------------------------

R_, L_, C_, DX, DY, P_ = 0.5, 2.0, 1.0, 1.5, 1.5, 0.5


@pytest.fixture(scope="module")
def rack_linkage():
    return derived(EXAMPLES / "rack_linkage.yaml")


def _rocker_tip(pin: np.ndarray, near: np.ndarray) -> np.ndarray:
    """The rocker's tip: |tip - pin| = L and |tip - D| = c, on the branch nearest ``near``."""
    d = np.array([DX, DY]) - pin
    span = np.linalg.norm(d, axis=1, keepdims=True)
    along = (span**2 + L_**2 - C_**2) / (2 * span)
    height = np.sqrt(L_**2 - along**2)
    normal = np.stack([-d[:, 1], d[:, 0]], 1) / span
    options = [pin + along * d / span + sign * height * normal for sign in (1, -1)]
    pick = np.argmin([np.linalg.norm(o[0] - near) for o in options])
    return options[pick]


@pytest.mark.parametrize("backend", BACKENDS)
def test_rack_moves_by_minus_r_delta_phi_and_drives_the_linkage(rack_linkage,
                                                                  backend: str) -> None:
    """The pinion turns theta = 0.6 sin t about a fixed centre a radius above the rack: its
    centre's displacement along the rack is -r theta, so the rack moves by +r theta; the
    rocker's tip follows the circle intersection from the rack's pin."""
    run = symkin.solve(kernel_for(rack_linkage, backend))
    column = rack_linkage.coordinates.index
    theta = 0.6 * np.sin(run.t)
    rack = run.q[:, column("rack.x")]
    assert np.abs((0 - rack) - (-R_ * theta)).max() < 1e-9
    assert np.abs(run.dq[:, column("rack.x")] - R_ * 0.6 * np.cos(run.t)).max() < 1e-8
    assert np.abs(run.d2q[:, column("rack.x")] + R_ * 0.6 * np.sin(run.t)).max() < 1e-6
    pin = np.stack([rack + P_, np.zeros_like(rack)], 1)
    tip, _, _ = run.point("rocker", "tip")
    assert np.abs(tip - _rocker_tip(pin, tip[0])).max() < 1e-9
    assert not run.flagged.any()


def _rack(**rack) -> dict:
    return {"name": "rp", "parameters": {"r": 0.5},
            "bodies": {"pinion": {"q0": [0, "r", 0]}, "rack": {"q0": [0, 0, 0]}},
            "joints": [{"type": "revolute", "i": "ground", "j": "pinion", "sA": [0, "r"],
                        "sB": [0, 0]},
                       {"type": "prismatic", "i": "rack", "j": "ground", "sA": [0, 0],
                        "sB": [0, 0], "v": [0, 1]},
                       {"type": "rack", "name": "m", "i": "pinion", "j": "rack",
                        "radius": "r", "axis": [1, 0], **rack}],
            "drivers": [{"type": "angle", "i": "pinion", "j": "ground", "theta": "t"}],
            "time": {"t0": 0, "t1": 1, "dt": 0.25}}


def test_rack_side_decides_the_sign() -> None:
    """Pinion above the rack (on the axis's left): rack x = +r theta; below it (on the
    right), turning the same way rolls the rack the other way: rack x = -r theta."""
    above = symkin.solve(kernel_for(symkin.derive(symkin.from_dict(_rack())), "numpy"))
    assert np.abs(above.q[:, 3] - 0.5 * above.t).max() < 1e-12
    data = _rack()
    data["bodies"]["pinion"]["q0"] = [0, "-r", 0]
    data["joints"][0]["sA"] = [0, "-r"]
    below = symkin.solve(kernel_for(symkin.derive(symkin.from_dict(data)), "numpy"))
    assert np.abs(below.q[:, 3] + 0.5 * below.t).max() < 1e-12


def test_rack_on_its_axis_line_is_refused() -> None:
    data = _rack()
    data["bodies"]["pinion"]["q0"] = [0, 0, 0]
    with pytest.raises(MechanismError, match="lies on the rack's axis line") as error:
        symkin.from_dict(data)
    assert "joints[2].at" in str(error.value)


def test_drawn_rack_matches_the_local_one() -> None:
    """The same rack drawn: pinion centre C at (0, r) with its frame turned, rack axis along
    the global x; the rack moves by +r theta."""
    drawn = {"name": "rp_drawn", "layout": "drawn", "parameters": {"r": 0.5},
             "bodies": {"ground": {"points": {"O": [0, "r"]}},
                        "pinion": {"frame": {"origin": [0, "r"], "angle": 0.4},
                                   "points": {"C": [0, "r"]}},
                        "rack": {"points": {"E": [0, 0]}}},
             "joints": [{"type": "revolute", "i": "ground", "j": "pinion", "at": "O"},
                        {"type": "prismatic", "i": "rack", "j": "ground", "at": "E",
                         "axis": [1, 0]},
                        {"type": "rack", "name": "m", "i": "pinion", "j": "rack",
                         "radius": "r", "axis": [2, 0], "at": "C"}],
             "drivers": [{"type": "angle", "i": "pinion", "j": "ground", "theta": "0.4 + t"}],
             "time": {"t0": 0, "t1": 1, "dt": 0.25}}
    run = symkin.solve(kernel_for(symkin.derive(symkin.from_dict(drawn)), "numpy"))
    assert np.abs(run.q[:, 3] - 0.5 * run.t).max() < 1e-12
