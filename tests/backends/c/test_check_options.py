"""<prefix>_check_options and the status BAD_OPTIONS: every solve of the generated C checks its
options first and refuses, with nothing solved and the state as it was, an options struct that
cannot work — above all a zero-filled one (default_options not called), which before ended in
NO_CONVERGENCE or SINGULAR and sent an embedded engineer looking at the mechanism. The rules
are contract.options.RULES, kept by Options in Python too; a float kernel that rounds a valid
Python value to 0 or inf is refused in Python by name."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

import symkin
from symkin.contract.options import C_FIELDS, Options
from symkin.errors import UsageError

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")

BAD_OPTIONS = 4
BAD_VALUES = {"tol_phi": [0.0, -1e-10, math.nan, math.inf], "tol_dq": [0.0, math.nan],
              "max_iterations": [-1], "min_pivot_ratio": [-1e-12, 1.5, math.nan],
              "max_cond": [0.0, math.nan], "tighten_cond": [-1.0], "target_q": [0.0],
              "target_dq": [math.nan], "target_ddq": [-1e-6],
              "unit": [0.0, -1000.0, math.inf, math.nan]}


@pytest.fixture(scope="module")
def kernel(crank_slider_system):
    return symkin.compile(crank_slider_system, backend="c")


class _Call:
    """The structs of one solve_step call, set up as the C README says."""

    def __init__(self, kernel) -> None:
        self.ffi, self.lib, self.name = kernel.ffi, kernel.lib, kernel.name
        self.options = self.ffi.new(f"{self.name}_options *")
        self._fn("default_options")(self.options)
        self.state = self.ffi.new(f"{self.name}_state *")
        self.state.q[0:kernel.nq] = [float(v) for v in kernel.q0]
        self.work = self.ffi.new(f"{self.name}_workspace *")
        self.report = self.ffi.new(f"{self.name}_report *")
        self.p = self.ffi.new(f"{self.name}_real[]", [float(v) for v in kernel.p_values])
        self.nq = kernel.nq

    def _fn(self, what: str):
        return getattr(self.lib, f"{self.name}_{what}")

    def check(self) -> int:
        return int(self._fn("check_options")(self.options))

    def step(self, t: float) -> int:
        return int(self._fn("solve_step")(self.options, self.p, t, self.state, self.work,
                                          self.report))

    def q(self) -> np.ndarray:
        return np.array(self.ffi.unpack(self.state.q, self.nq))


def test_the_defaults_pass_and_the_header_order_is_the_contracts(kernel) -> None:
    call = _Call(kernel)
    assert call.check() == 0
    assert list(dict(call.ffi.typeof(call.options[0]).fields)) == list(C_FIELDS)
    assert int(getattr(call.lib, f"{call.name.upper()}_BAD_OPTIONS")) == BAD_OPTIONS


@pytest.mark.parametrize(("field", "value"),
                         [(f, v) for f, values in BAD_VALUES.items() for v in values])
def test_a_bad_field_is_named_and_the_step_refused_with_the_state_kept(
        kernel, field: str, value: float) -> None:
    call = _Call(kernel)
    setattr(call.options, field, int(value) if field == "max_iterations" else value)
    assert call.check() == C_FIELDS.index(field) + 1
    call.report.iterations, call.report.residual = 12345, 777.0  # a caller's stale report
    before = call.q()
    assert call.step(0.1) == BAD_OPTIONS
    assert call.report.status == BAD_OPTIONS and call.report.t == 0.1
    assert call.report.iterations == 0 and math.isnan(call.report.residual)
    assert np.array_equal(call.q(), before) and call.state.started == 0


def test_a_zero_filled_struct_is_refused_at_its_first_field(kernel) -> None:
    call = _Call(kernel)
    call.options = call.ffi.new(f"{call.name}_options *")  # cffi zero-fills it
    assert call.check() == 1 and call.step(0.0) == BAD_OPTIONS
    call._fn("default_options")(call.options)  # and with the defaults the same call solves
    assert call.step(0.0) == 0


def test_no_limit_and_no_iteration_are_allowed(kernel) -> None:
    call = _Call(kernel)
    for field in ("tol_dq", "max_cond", "tighten_cond", "target_q", "target_dq", "target_ddq"):
        setattr(call.options, field, math.inf)
    call.options.min_pivot_ratio = 0.0
    call.options.max_iterations = 0
    assert call.check() == 0
    assert call.step(0.0) in (0, 1)  # converged at q0 or not: solved, not refused


def test_the_grid_loop_stops_at_its_first_point(kernel) -> None:
    call = _Call(kernel)
    call.options.unit = 0.0
    t = call.ffi.new(f"{call.name}_real[]", [0.0, 0.1, 0.2])
    solved = call._fn("solve_grid")(call.options, call.p, 3, t, call.state, call.ffi.NULL,
                                    call.ffi.NULL, call.ffi.NULL, call.work, call.report)
    assert solved == 0 and call.report.status == BAD_OPTIONS


def test_a_value_a_float_kernel_rounds_away_is_refused_by_name(crank_slider_system) -> None:
    single = symkin.compile(crank_slider_system, backend="c", real="float")
    with pytest.raises(UsageError, match=r"tol_phi = 1e-50 is 0\.0 in the kernel's real type"):
        symkin.solve(single, t=[0.0, 0.1], options=Options(tol_phi=1e-50))


def test_the_edge_treatment_stops_at_once_with_the_state_kept(kernel) -> None:
    call = _Call(kernel)
    assert call.step(0.0) == 0
    before = call.q()
    call.options.max_cond = math.nan
    edge = call.ffi.new(f"{call.name}_edge_report *")
    outcome = call._fn("solve_edge")(call.options, call.p, 0.1, 1e-9, 1e-9, 21.0, call.state,
                                     call.work, call.report, edge)
    assert outcome == int(getattr(call.lib, f"{call.name.upper()}_EDGE_STOPPED"))
    assert edge.outcome == outcome and edge.failed == 0 and edge.cond == 21.0
    assert call.report.status == BAD_OPTIONS and np.array_equal(call.q(), before)
