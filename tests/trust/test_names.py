"""Names: a body may be called ``input`` (the driver keyword only as a whole value), and a
mechanism may not take a name <math.h> declares, in any precision.

References: the same mechanism under its original names (examples/), and the compiler's own
math.h read through its preprocessor, in strict C99 and in its default dialect.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled

import symkin
from symkin.backends.c import toolchain
from symkin.errors import MechanismError
from symkin.spec import names
from symkin.spec.validate import from_dict

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parents[1] / "examples"
RENAMED = [("custom_named_input.yaml", "custom_driver.yaml", {"input": "crank"}),
           ("links_named_input.yaml", "cardan.yaml", {"input": "shaft1", "output": "shaft2"})]


def _q_at(path: Path, t: float) -> dict[str, float]:
    result = symkin.solve(compiled(path, "numpy"), t=np.array([t]))
    return {name: float(result.q[0, k]) for k, name in enumerate(result.coordinates)}


@pytest.mark.parametrize(("renamed", "original", "bodies"), RENAMED)
def test_a_body_named_input_moves_as_under_its_original_name(
        renamed: str, original: str, bodies: dict[str, str]) -> None:
    got = _q_at(HERE / renamed, 0.3)
    want = _q_at(EXAMPLES / original, 0.3)
    for name, value in got.items():
        body, part = name.split(".")
        assert value == pytest.approx(want[f"{bodies.get(body, body)}.{part}"], abs=1e-12)


def test_a_parameter_named_input_is_still_refused() -> None:
    assert names.name_problem("input", "parameter") is not None
    assert names.name_problem("input", "body") is None


def _math_h(dialect: list[str]) -> set[str]:
    """The identifiers math.h declares as functions, or defines as function-like macros,
    with ``dialect`` (double-underscore names are refused by another rule)."""
    compiler = toolchain.c_compiler()
    if compiler is None:
        pytest.skip("no C compiler")
    text = subprocess.run([*compiler, *dialect, "-E", "-dD", "-x", "c", "-"],
                          input="#include <math.h>\n", capture_output=True, text=True,
                          check=True).stdout
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    declared = set(re.findall(r"extern [^;(]*?\b([A-Za-z]\w*) \(", "\n".join(lines)))
    declared |= set(re.findall(r"#define ([a-z]\w*)\(", text))
    return {name for name in declared if "__" not in name and not name.startswith("_")}


@pytest.mark.parametrize("dialect", [["-std=c99"], []], ids=["c99", "default"])
def test_every_name_math_h_declares_is_refused_for_a_mechanism(dialect: list[str]) -> None:
    accepted = sorted(name for name in _math_h(dialect)
                      if names.name_problem(name, "mechanism") is None)
    assert not accepted, f"math.h names accepted for a mechanism: {accepted}"


def test_a_mechanism_named_sinf_is_refused_at_its_name() -> None:
    document = {"name": "sinf", "bodies": {"b": {}},
                "joints": [{"type": "revolute", "i": "ground", "j": "b", "sA": [0, 0],
                            "sB": [0, 0]}],
                "drivers": [{"type": "angle", "i": "b", "j": "ground", "theta": "t"}],
                "time": {"t0": 0, "t1": 1, "dt": 0.5}}
    with pytest.raises(MechanismError, match="'sinf' is the name of a C math library"):
        from_dict(document)
