"""The generated folder documents itself: the minimal ``main`` in its README compiles against
the folder alone and prints a moving point (the RSSR's first point is its crank's fixed pivot:
a program that printed only the first point would print ten rows of zeros); the README names
every function of the header and the caller's duties."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from codegen_support import STRICT_FLAGS, golden_folder

CC = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(CC is None, reason="no C compiler")


def _readme(name: str) -> str:
    return (golden_folder(name, "c") / f"{name}_README.md").read_text()


def _main_of(readme: str) -> str:
    found = re.findall(r"```c\n(.*?)```", readme, flags=re.S)
    assert len(found) == 1, "the README has one C program"
    return found[0]


def _run_main(name: str, tmp_path: Path) -> np.ndarray:
    folder = tmp_path / name
    shutil.copytree(golden_folder(name, "c"), folder)
    (folder / "main.c").write_text(_main_of(_readme(name)))
    program = folder / "main"
    built = subprocess.run([CC, *STRICT_FLAGS, "-O1", "-o", str(program),
                            *map(str, sorted(folder.glob("*.c"))), "-lm"],
                           capture_output=True, text=True, check=False)
    assert built.returncode == 0, built.stderr
    ran = subprocess.run([str(program)], capture_output=True, text=True, timeout=60,
                         check=False)
    assert ran.returncode == 0, ran.stderr
    return np.loadtxt(ran.stdout.splitlines())


@pytest.mark.parametrize("name, first_fixed", [("rssr", True), ("crank_slider_input", False),
                                               ("crank_slider", False)])
def test_the_readme_main_prints_a_point_that_moves(name, first_fixed, tmp_path):
    rows = _run_main(name, tmp_path)
    assert rows.shape[0] == 10 and np.array_equal(rows[:, 0], np.arange(10))
    values = rows[:, 1:]
    moved = np.ptp(values, axis=0)
    assert moved.max() > 1e-3, "no printed number changes over the ten steps"
    size = 3 if name == "rssr" else 2
    if first_fixed:  # the old main printed only this one: it does not move
        assert np.ptp(values[:, :size], axis=0).max() < 1e-12


def test_the_rssr_main_agrees_with_the_crank_angle(tmp_path):
    """Independently: the crank's tip (point 2, crank.A at a = 0.1 from the z axis) is at
    angle 2 pi t, t = k * 0.01."""
    rows = _run_main("rssr", tmp_path)
    tip = rows[:, 4:7]
    angle = 2 * np.pi * 0.01 * np.arange(10)
    np.testing.assert_allclose(tip[:, 0], 0.1 * np.cos(angle), atol=1e-6)
    np.testing.assert_allclose(tip[:, 1], 0.1 * np.sin(angle), atol=1e-6)


@pytest.mark.parametrize("name", ["crank_slider_load", "parallelogram_extra_bar_loads"])
def test_the_readme_names_every_function_of_the_headers(name):
    readme = _readme(name)
    folder = golden_folder(name, "c")
    declared = set()
    for header in (f"{name}.h", f"{name}_solver.h"):
        declared |= set(re.findall(rf"\b{name}_(\w+)\(", (folder / header).read_text()))
    said = set(re.findall(rf"`(?:{name})?_(\w+)", readme))
    missing = sorted(declared - said)
    assert not missing, f"not in the README: {missing}"
    assert f"{name.upper()}_NLOADS" in readme and "sizeof(" in readme


def test_the_removed_rows_are_the_callers_duty():
    name = "parallelogram_extra_bar"
    readme = _readme(name)
    assert f"`{name}_removed(state.q, state.t, p, out)`" in readme and "duty" in readme
    header = (golden_folder(name, "c") / f"{name}.h").read_text()
    assert "the runtime checks they stay" not in header
    assert "no solve of this folder looks at them" in header
