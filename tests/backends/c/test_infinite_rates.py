"""The generated C step ends with NOT_FINITE where the rates or the accelerations are infinite
(not NaN): the passes over dq and ddq find a NaN by the sum of |.| and an infinity by the
largest entry, one addition an entry.

Reference: a crank turning about its own origin (a revolute to the ground there and an angle
driver) with theta = sqrt(t) + 1 (theta' = 1 / (2 sqrt t): infinite at t = 0) and with
theta = t^(3/2) + 1 (theta' = 0 but theta'' = 3 / (4 sqrt t): infinite at t = 0), both
assembled at t = 0 where Phi is finite. The crank's x and y do not move, so the rates and the
accelerations are (0, 0, inf) or (0, 0, -inf) exactly: infinite and no NaN, the case the sum
alone would miss (a crank-slider mixes the infinity into a NaN). The same step at t = 1 is
solved (finite rates).
"""

from __future__ import annotations

import math
from typing import Any

import pytest
import yaml

import symkin
from symkin.spec import validate

NOT_FINITE_NAME = "NOT_FINITE"


def _kernel(theta: str) -> Any:
    data = yaml.safe_load("""
name: turning
bodies: {crank: {q0: [0, 0, 1]}}
joints: [{type: revolute, i: ground, j: crank, sA: [0, 0], sB: [0, 0]}]
drivers: [{type: angle, i: crank, j: ground}]
time: {t0: 0, t1: 1, dt: 0.5}
""")
    data["drivers"][0]["theta"] = theta
    return symkin.compile(symkin.derive(validate.from_dict(data)), backend="c")


@pytest.fixture(scope="module", params=["sqrt(t) + 1", "t**(3/2) + 1"])
def kernel(request: pytest.FixtureRequest) -> Any:
    return _kernel(request.param)


def _step(kernel: Any, t: float) -> tuple[int, list[float], list[float]]:
    ffi, lib, name, n = kernel.ffi, kernel.lib, kernel.name, len(kernel.coordinates)
    options, state = ffi.new(f"{name}_options *"), ffi.new(f"{name}_state *")
    work, report = ffi.new(f"{name}_workspace *"), ffi.new(f"{name}_report *")
    getattr(lib, f"{name}_default_options")(options)
    p = ffi.new(f"{name}_real[]", list(kernel.p_values))
    state.q[0:n] = list(kernel.q0)
    state.started = 0
    status = getattr(lib, f"{name}_solve_step")(options, p, t, state, work, report)
    return status, ffi.unpack(state.dq, n), ffi.unpack(state.ddq, n)


def test_infinite_rates_or_accelerations_end_the_step(kernel: Any) -> None:
    not_finite = getattr(kernel.lib, f"{kernel.name.upper()}_{NOT_FINITE_NAME}")
    status, dq, ddq = _step(kernel, 0.0)
    assert status == not_finite
    # what the passes saw: an infinite entry and no NaN (dq, or ddq where dq is finite)
    solved = dq if any(math.isinf(v) for v in dq) else ddq
    assert solved[:2] == [0.0, 0.0] and math.isinf(solved[2])
    status, dq, ddq = _step(kernel, 1.0)
    assert status == 0
    assert all(math.isfinite(v) for v in dq + ddq)
