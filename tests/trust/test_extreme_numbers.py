"""Extreme numbers in a file: refused with exit 2 at their line (the number quoted short), or
run right; never exit 1 without a place.

References: the Cardan closed form (test_exact_numbers.assert_cardan) for a cross whose axes
are written 1e-200 and 1e200 long (a direction has no length); the file's own line numbers
for the refusals.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from codegen_support import compiled

import symkin
from symkin import cli
from tests.trust.test_exact_numbers import assert_cardan

HERE = Path(__file__).resolve().parent
REFUSED = [("subnormal_axis.yaml", 12, "at joints[0].axis[1]: 1e-310 is below the smallest normal double"),
           ("mass_1e300.yaml", 12, "at bodies.crank.mass: the mass 1e+300 is too large"),
           ("com_without_mass.yaml", 14, "at bodies.slider.com: the body gives a centre of mass "
                                         "(com) but no mass")]


@pytest.mark.parametrize(("name", "line", "said"), REFUSED)
def test_refused_at_its_line_with_exit_2(name: str, line: int, said: str, tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    code = cli.main(["run", str(HERE / name), "--backend", "numpy", "-o",
                     str(tmp_path / "r.csv")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert f"{name}:{line}: {said}" in err
    assert not re.search(r"\d{20}", err), "a number printed in full"
    assert len(err) < 600


@pytest.mark.parametrize("name", ["universal_tiny_axes.yaml", "universal_huge_axes.yaml"])
def test_a_cross_drawn_at_any_length_runs_as_the_cardan(name: str) -> None:
    assert_cardan(symkin.solve(compiled(HERE / name, "numpy")))
