"""The step's two solves (``<prefix>_lu_solve_rates`` and ``_accelerations``), compiled and run
against the plain ``<prefix>_lu_solve`` of the same factors.

They take the rows of Phi_t and Gamma that the generated kernel writes as a literal 0 as 0
without reading them, and the norms of their solution as they write it, skipping the entries
that are +-0 whatever the factors (backends.c.rhs_zeros). Contracts: the solution has the
plain solve's bits (negated for the rates); the max they return is max |x| of that solution
and their sum is sum |x| (NaN exactly when an entry is NaN), also where a factor entry is
infinite, so that no NaN an entry gets from 0 * inf hides from the step's finite test. The
right-hand sides are the kernel's own Phi_t and Gamma at random states; the rows the
generator calls zero are checked +0 there.
"""

from __future__ import annotations

import shutil
from typing import Any

import numpy as np
import pytest
from codegen_support import ROOT, compiled

from symkin.backends.c import rhs_zeros
from symkin.backends.c.lu_code import template_context
from symkin.codegen import lower

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")

# rack_linkage and planetary: entries of a solution that meet a zero row and then a factor
# entry (taken into the norms: an infinite factor makes them NaN)
EXAMPLES = [("crank_slider", {}), ("four_bar", {}), ("rssr", {}), ("spatial_slider_crank", {}),
            ("rack_linkage", {}), ("planetary", {}), ("crank_slider", {"linalg": "dense"})]


@pytest.fixture(scope="module", params=EXAMPLES, ids=lambda e: "-".join([e[0], *e[1].values()]))
def kernel(request: pytest.FixtureRequest) -> Any:
    name, options = request.param
    return compiled(ROOT / "examples" / f"{name}.yaml", "c", **options)


class Solves:
    """The kernel's Phi_q, Phi_t, Gamma and its LU's three solves through cffi."""

    def __init__(self, kernel: Any) -> None:
        self.ffi, self.lib, self.name = kernel.ffi, kernel.lib, kernel.name
        self.n = len(kernel.coordinates)
        self.p = self.ffi.new(f"{self.name}_real[]", list(kernel.p_values) or [0.0])
        self.q0 = np.array(kernel.q0, dtype=float)
        self.lu = self.ffi.new(f"{self.name}_lu *")
        self.nnz = int(getattr(self.lib, f"{self.name.upper()}_NNZ"))
        getattr(self.lib, f"{self.name}_lu_init")(self.lu)

    def call(self, routine: str, *args: Any) -> Any:
        return getattr(self.lib, f"{self.name}_{routine}")(*args)

    def factor(self, q: np.ndarray, t: float) -> None:
        nz = self.ffi.new(f"{self.name}_real[]", self.nnz)
        self.call("phi_q", self.ffi.new(f"{self.name}_real[]", list(q)), t, self.p, nz)
        assert self.call("lu_factor", nz, self.lu) == 0

    def rhs(self, routine: str, q: np.ndarray, dq: np.ndarray, t: float) -> np.ndarray:
        out = self.ffi.new(f"{self.name}_real[]", self.n)
        qc = self.ffi.new(f"{self.name}_real[]", list(q))
        if routine == "phi_t":
            self.call("phi_t", qc, t, self.p, out)
        else:
            self.call("gamma", qc, self.ffi.new(f"{self.name}_real[]", list(dq)), t, self.p, out)
        return np.array(self.ffi.unpack(out, self.n))

    def solve(self, routine: str, b: np.ndarray) -> tuple[np.ndarray, float, float]:
        x = self.ffi.new(f"{self.name}_real[]", list(b))
        total = self.ffi.new(f"{self.name}_real *")
        if routine == "lu_solve":
            self.call(routine, self.lu, x)
            largest = float("nan")
        else:
            largest = self.call(routine, self.lu, x, total)
        return np.array(self.ffi.unpack(x, self.n)), largest, total[0]


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.tobytes() == b.tobytes()


def _check(solves: Solves, b: np.ndarray, routine: str) -> None:
    """One right-hand side: the step's solve against the plain one."""
    plain, _, _ = solves.solve("lu_solve", b)
    x, largest, total = solves.solve(routine, b)
    assert _same_bits(x, -plain if routine == "lu_solve_rates" else plain)
    if np.isnan(plain).any():
        assert np.isnan(total)
        return
    assert not np.isnan(total)
    assert largest == np.max(np.abs(plain))
    np.testing.assert_allclose(total, np.sum(np.abs(plain)), rtol=1e-12, atol=0)


@pytest.fixture(scope="module")
def states(kernel: Any) -> list[tuple[np.ndarray, np.ndarray, float]]:
    rng = np.random.default_rng(38)
    n = len(kernel.coordinates)
    return [(np.array(kernel.q0, dtype=float) + 0.02 * rng.normal(size=n), rng.normal(size=n),
             float(rng.uniform(0, 1))) for _ in range(12)]


def test_the_step_s_solves_give_the_plain_solve_s_bits_and_norms(kernel, states) -> None:
    solves = Solves(kernel)
    for q, dq, t in states:
        solves.factor(q, t)
        _check(solves, solves.rhs("phi_t", q, dq, t), "lu_solve_rates")
        _check(solves, solves.rhs("gamma", q, dq, t), "lu_solve_accelerations")


def test_an_infinite_factor_entry_is_never_hidden(kernel, states) -> None:
    """Every entry of the factors (and every pivot's reciprocal) made infinite in turn: where
    the plain solve's solution has a NaN, the step's solve's sum is NaN."""
    solves = Solves(kernel)
    if not hasattr(solves.lu, "v"):
        pytest.skip("the dense LU has no sparse factors to poison")
    q, dq, t = states[0]
    slots = [("v", e) for e in range(len(solves.lu.v))] + [("inv", k) for k in range(solves.n)]
    for array, slot in slots:
        for sign in (1.0, -1.0):
            solves.factor(q, t)
            getattr(solves.lu, array)[slot] = sign * float("inf")
            _check(solves, solves.rhs("phi_t", q, dq, t), "lu_solve_rates")
            _check(solves, solves.rhs("gamma", q, dq, t), "lu_solve_accelerations")


def test_the_rows_called_zero_are_plus_zero_at_every_state(kernel, states) -> None:
    from codegen_support import system

    from symkin.backends import get as get_backend

    code = lower.lower(system(kernel.name), get_backend("c"), {})
    solves = Solves(kernel)
    rows = {"phi_t": rhs_zeros.zero_rows(code, "phi_t_shared"),
            "gamma": rhs_zeros.zero_rows(code, "gamma_shared")}
    assert rows["phi_t"] and rows["gamma"]  # the examples have some: the test means something
    for q, dq, t in states:
        for routine, zero in rows.items():
            b = solves.rhs(routine, q, dq, t)
            assert all(b[r] == 0 and not np.signbit(b[r]) for r in zero), routine


def test_an_entry_that_meets_a_factor_is_not_known_zero() -> None:
    """rhs_zeros on statements written by hand: x[1] starts 0 and stays 0 through signs and
    another zero, x[2] meets v, x[3] meets inv, x[0] meets a row that is read."""
    part = {"steps": [{"backward": ["x[1] = -x[1];", "x[1] -= x[2];", "x[2] -= v[4] * x[1];",
                                    "x[3] *= inv[3];", "x[1] += x[3];", "x[0] -= x[2];"]}]}
    lu = {"style": "straight", "perm_tables": False, "row_perm": [0, 1, 2, 3], "swaps": [],
          "forward_parts": [], "backward_parts": [part]}
    assert rhs_zeros.known_zeros(lu, [1, 2, 3]) == []  # x[1] meets x[3], which met inv
    part["steps"][0]["backward"].remove("x[1] += x[3];")
    assert rhs_zeros.known_zeros(lu, [1, 2, 3]) == [1]
    assert rhs_zeros.known_zeros(dict(lu, swaps=[[1, 0]]), [1, 2, 3]) == []


def test_a_printed_zero_is_told_from_an_expression() -> None:
    assert [rhs_zeros._plus_zero(text) for text in ("0", "0.0", "0.0F", " 0 ")] == [True] * 4
    assert not any(rhs_zeros._plus_zero(text) for text in ("-0", "-0.0", "10", "0*x", "", "x"))


def test_the_known_zeros_of_the_crank_slider() -> None:
    """The crank-slider's Phi_t is 0 but in the driver's row: its rates' solve finds four
    entries +-0 whatever the factors (the slider's y and angle among them)."""
    from codegen_support import system

    from symkin.backends import get as get_backend

    code = lower.lower(system("crank_slider"), get_backend("c"), {})
    lu = template_context(code.lu_plan, constants=code.constant_nz, prefix=code.name)
    assert rhs_zeros.zero_rows(code, "phi_t_shared") == list(range(8))
    assert len(rhs_zeros.known_zeros(lu, range(8))) == 4
