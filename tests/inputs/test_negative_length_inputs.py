"""A length input (a distance driver's f written ``input``) is never negative: its row holds
f squared, so -1 was solved, silently, as 1. ``symkin.solve(inputs=...)`` refuses it as the
CLI's inputs table does (one rule, runtime.input_driven.inputs.negative_length), and the generated C
``solve_inputs`` returns ``<PREFIX>_BAD_INPUT`` with nothing solved. The mechanism is a ram
on a guide along x pushed by a leg from one unit off the guide: its x is sqrt(leg^2 - 1)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from motion_support import kernel as built

import symkin
from symkin import cli
from symkin.contract import status

HERE = Path(__file__).resolve().parent
RAM_LEG = HERE / "ram_leg.yaml"
T = np.array([0.0, 0.1, 0.2, 0.3])
BACKENDS = ["numpy", pytest.param("c", marks=pytest.mark.skipif(
    shutil.which("gcc") is None, reason="gcc is not installed"))]



@pytest.fixture(scope="module", params=BACKENDS)
def kernel(request):
    return built(RAM_LEG, request.param)


def test_the_kernel_knows_which_inputs_are_lengths(kernel):
    assert kernel.input_names == ("leg",) and kernel.input_lengths == ("leg",)


@pytest.mark.parametrize("given", [np.array([1.5, 2.0, -2.0, -2.5]),
                                   {"leg": [1.5, 2.0, -2.0, -2.5]}])
def test_solve_refuses_a_negative_length_input_naming_its_point(kernel, given):
    with pytest.raises(symkin.SolveError, match=(
            r"inputs\['leg'\] at point 2 \(t = 0.2\): -2 is negative, but leg is a distance "
            r"driver's length \|B - A\| \(2 negative value\(s\) in all\); give lengths >= 0")):
        symkin.solve(kernel, t=T, inputs=given)


def test_solve_takes_lengths_of_zero_and_more_at_their_closed_form(kernel):
    legs = np.array([1.5, 1.625, 1.75, 1.875])
    result = symkin.solve(kernel, t=T, inputs=legs)
    x = result.q[:, list(kernel.coordinates).index("ram.x")]
    assert np.abs(x - np.sqrt(legs**2 - 1)).max() < 1e-12


def test_the_cli_table_is_refused_by_the_same_rule(tmp_path, capsys):
    table = tmp_path / "legs.csv"
    table.write_text("t,leg\n0,1.5\n0.1,-1.5\n")
    status_ = cli.main(["run", str(RAM_LEG), "--backend", "numpy", "--inputs", str(table),
                        "-o", str(tmp_path / "out.csv")])
    err = capsys.readouterr().err
    assert status_ == 2, err
    assert f"{table}:3: column leg: -1.5 is negative, but leg is a distance driver's" in err
    assert not (tmp_path / "out.csv").exists()


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
def test_the_generated_c_solve_inputs_refuses_a_negative_length():
    kernel = built(RAM_LEG, "c")
    ffi, lib, name = kernel.ffi, kernel.lib, kernel.name
    options = ffi.new(f"{name}_options *")
    getattr(lib, f"{name}_default_options")(options)
    state, work = ffi.new(f"{name}_state *"), ffi.new(f"{name}_workspace *")
    report = ffi.new(f"{name}_report *")
    state.q[0:kernel.nq] = [float(v) for v in kernel.q0]
    state.started = 0
    p = ffi.new(f"{name}_real[]", max(1, len(kernel.parameter_names)))
    x = list(kernel.coordinates).index("ram.x")

    def solve(leg: float) -> int:
        return int(getattr(lib, f"{name}_solve_inputs")(
            options, p, ffi.new(f"{name}_real[]", [leg]), ffi.NULL, ffi.NULL, state, work,
            report))

    assert solve(2.0) == status.OK and state.q[x] == pytest.approx(math.sqrt(3), abs=1e-12)
    before = list(state.q[0:kernel.nq])
    assert solve(-2.0) == status.BAD_INPUT == report.status
    assert list(state.q[0:kernel.nq]) == before  # nothing solved, the state as it was
    # zero is a length, not refused (here out of reach: Newton says so, and the next call
    # starts from the last solution)
    assert solve(-0.0) not in (status.OK, status.BAD_INPUT)
    assert solve(1.5) == status.OK and state.q[x] == pytest.approx(math.sqrt(1.25), abs=1e-12)
    header = (kernel.folder / f"{name}_solver.h").read_text()
    assert f"#define {name.upper()}_BAD_INPUT {status.BAD_INPUT} " in header
