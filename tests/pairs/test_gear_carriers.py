"""A gear pair's carrier (symkin/pairs/planar/gear.py): at rest or driven, against Willis'
formula derived here; and each way a carrier goes wrong, provoked and named.

The set: a sun S and a ring R (both pinned to the ground at the origin), one planet P pinned
to an arm (the carrier) at S + P from the origin, the arm pinned to the ground at the origin
too. Relative to the arm the set is an ordinary train (Willis):

    (phi_s - phi_a) / (phi_r - phi_a) = -R / S,   phi_p - phi_a = -(S / P)(phi_s - phi_a)

so with the sun driven by phi_s(t) and the arm by phi_a(t) (all angles zero at t = 0)

    phi_r = phi_a (1 + S / R) - phi_s S / R,   phi_p = phi_a (1 + S / P) - phi_s S / P

An arm held at rest (phi_a = 0) makes it a fixed train: phi_r = -phi_s S / R.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
import sympy as sp
from driver_support import BACKENDS, kernel_for

import symkin
from symkin.errors import MechanismError

S, P = 1.0, 0.5
R = S + 2 * P
SUN = "2*t"
ARMS = {"at rest": "0", "driven": "0.5*t + 0.3*t**2"}


def _set(arm: str) -> dict:
    """The free-ring planetary set, sun and arm driven."""
    pivot = {"type": "revolute", "i": "ground", "sA": [0, 0], "sB": [0, 0]}
    return {
        "name": "carried", "parameters": {"S": S, "P": P},
        "bodies": {"sun": {"q0": [0, 0, 0]}, "ring": {"q0": [0, 0, 0]},
                   "arm": {"q0": [0, 0, 0], "points": {"hub": ["S + P", 0]}},
                   "planet": {"q0": [S + P, 0, 0]}},
        "joints": [{**pivot, "j": "sun"}, {**pivot, "j": "ring"}, {**pivot, "j": "arm"},
                   {"type": "revolute", "i": "arm", "j": "planet", "sA": "hub",
                    "sB": [0, 0]},
                   {"type": "gear", "name": "inner", "i": "sun", "j": "planet",
                    "radii": ["S", "P"], "carrier": "arm"},
                   {"type": "gear", "name": "outer", "i": "planet", "j": "ring",
                    "radii": ["P", "S + 2*P"], "carrier": "arm", "internal": True}],
        "drivers": [{"type": "angle", "i": "sun", "j": "ground", "theta": SUN},
                    {"type": "angle", "i": "arm", "j": "ground", "theta": arm}],
        "time": {"t0": 0, "t1": 2, "dt": 0.1},
    }


@pytest.fixture(scope="module", params=list(ARMS))
def carried(request):
    return request.param, symkin.derive(symkin.from_dict(_set(ARMS[request.param])))


@pytest.mark.parametrize("backend", BACKENDS)
def test_carrier_at_rest_or_driven_follows_willis(carried, backend: str) -> None:
    """Ring and planet angles, rates and accelerations from Willis' formula (above) by
    differentiating it here; positions 1e-9, velocities 1e-8, accelerations 1e-6."""
    label, system = carried
    kernel = kernel_for(system, backend)
    assert kernel.backend == backend
    run = symkin.solve(kernel)
    t = sp.Symbol("t")
    sun, arm = sp.sympify(SUN), sp.sympify(ARMS[label])
    expected = {"sun": sun, "arm": arm, "ring": arm * (1 + S / R) - sun * S / R,
                "planet": arm * (1 + S / P) - sun * S / P}
    for body, angle in expected.items():
        k = system.coordinates.index(f"{body}.phi")
        for got, order, tolerance in ((run.q, 0, 1e-9), (run.dq, 1, 1e-8),
                                      (run.d2q, 2, 1e-6)):
            want = sp.lambdify(t, sp.diff(angle, t, order), "numpy")(run.t)
            assert np.abs(got[:, k] - want).max() < tolerance, (label, body, order)
    assert not run.flagged.any()


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_carrier_driven_against_a_fixed_ring_is_flagged_and_named(backend: str) -> None:
    """Sun and arm both driven while the ring is the ground: one freedom, two drivers. At t0
    (all angles zero) the rows agree, so the rank removes one as redundant; along the motion
    it no longer holds (the ring would have to turn): every later point is flagged and the
    warning names the gear row, with |Phi| there; never a silently wrong number."""
    from symkin.cli import run_outputs

    data = _set(ARMS["driven"])
    data["bodies"].pop("ring")
    del data["joints"][1]  # the ring's pivot
    data["joints"][-1]["j"] = "ground"
    system = symkin.derive(symkin.from_dict(data))
    assert [row.row.name for row in system.removed] == ["outer"]
    run = symkin.solve(kernel_for(system, backend))
    assert run.flagged[1:].all() and not run.flagged[0]
    warning = " ".join(run_outputs.flag_warnings(run))
    assert "joints[4] outer gear planet-ground-arm (rolling): |Phi| up to" in warning
    assert "contradict each other" in warning


def _broken(change) -> str:
    data = copy.deepcopy(_set(ARMS["driven"]))
    change(data)
    with pytest.raises(MechanismError) as error:
        symkin.from_dict(data)
    return str(error.value)


def test_a_gear_not_pinned_to_its_carrier_is_refused() -> None:
    """The planet pinned to the ground instead of to the arm: its centre distance from the
    sun is held by nothing the carrier does."""
    def unpin(data: dict) -> None:
        data["joints"][3] = {"type": "revolute", "i": "ground", "j": "planet",
                             "sA": ["S + P", 0], "sB": [0, 0]}
    said = _broken(unpin)
    assert "joints[4].j: the gear 'planet' is not pinned to the carrier 'arm'" in said


def test_pitch_radii_that_do_not_fit_the_centre_distance_are_refused() -> None:
    """External: pivots S + P apart but radii S and 0.6; internal: a ring of radius 2.5."""
    def wrong_planet(data: dict) -> None:
        data["joints"][4]["radii"] = ["S", 0.6]
    said = _broken(wrong_planet)
    assert ("joints[4].radii: the gears' pivots on the carrier 'arm' are 1.5 apart, not "
            "r_i + r_j = 1.6") in said
    def wrong_ring(data: dict) -> None:
        data["joints"][5]["radii"] = ["P", 2.5]
    said = _broken(wrong_ring)
    assert "joints[5].radii" in said and "not r_j - r_i = 2" in said


def test_a_carrier_on_a_shared_ground_pivot_holds_the_sun() -> None:
    """The sun is pinned to the ground, not to the arm, at the very point the arm is: its
    centre is the arm's pivot (accepted); moved off that point, it is refused."""
    symkin.from_dict(_set(ARMS["driven"]))  # accepted as built

    def off_axis(data: dict) -> None:
        data["joints"][0]["sA"] = [0.1, 0]
    assert "the gear 'sun' is not pinned to the carrier 'arm'" in _broken(off_axis)
