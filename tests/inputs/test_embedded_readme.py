"""The generated folder's README: its minimal program, taken from the README itself, compiles
with the strict flags against the folder alone and runs, for a time-driven and an
input-driven mechanism; its numbers are checked against closed forms of the crank-slider."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from codegen_support import golden_folder

ROOT = Path(__file__).resolve().parents[2]
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror"]

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")


def _run_readme_main(example: str, tmp_path: Path) -> list[list[float]]:
    folder = tmp_path / example
    # the folder symkin.generate writes, byte for byte (tests/codegen/test_generated.py)
    shutil.copytree(golden_folder(example, "c"), folder)
    readme = (folder / f"{example}_README.md").read_text()
    assert "(Example 2.6)" not in readme
    code = re.search(r"```c\n(.*?)```", readme, re.DOTALL)
    assert code is not None, "the README has no C program"
    (folder / "main.c").write_text(code.group(1))
    exe = folder / "main"
    sources = sorted(str(p) for p in folder.glob("*.c"))
    subprocess.run(["gcc", *FLAGS, f"-I{folder}", "-o", str(exe), *sources, "-lm"],
                   check=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    return [[float(v) for v in line.split()] for line in out.splitlines()]


def test_time_driven_readme_program(tmp_path: Path) -> None:
    # each row: the step, then every named point (crank.tip, rod.P) as x y
    rows = np.array(_run_readme_main("crank_slider", tmp_path))
    assert rows.shape == (10, 5)
    t = 0.05 * rows[:, 0]
    phi = t**2 + np.pi / 2  # the file's crank angle; the crank tip is (cos phi, sin phi)
    assert np.allclose(rows[:, 1], np.cos(phi), atol=2e-6)  # printed with 6 decimals
    assert np.allclose(rows[:, 2], np.sin(phi), atol=2e-6)
    # rod.P is the rod's far end: the rod (b = 5) keeps its length
    assert np.allclose(np.hypot(*(rows[:, 3:5] - rows[:, 1:3]).T), 5.0, atol=1e-5)


def test_input_driven_readme_program(tmp_path: Path) -> None:
    rows = np.array(_run_readme_main("crank_slider_input", tmp_path))
    assert rows.shape == (10, 5)
    # the program moves the input from the value q0 satisfies (crank angle 1.5708): the
    # tip stays on the crank's circle, at the angle the rows' own x and y give
    assert np.allclose(np.hypot(rows[:, 1], rows[:, 2]), 1.0, atol=2e-6)
    assert np.allclose(rows[0, 1:3], [np.cos(1.5708), np.sin(1.5708)], atol=2e-6)


def test_input_driven_readme_program_of_length_inputs(tmp_path: Path) -> None:
    """stewart_fk's inputs are leg lengths, whose rows |P - B|^2 - u^2 are flat at the
    nominal u = 0: the README's program starts them at the drawn home pose's lengths (the
    law of cosines of test_op_budget's _home_legs), so it assembles there, and moves them."""
    rows = np.array(_run_readme_main("stewart_fk", tmp_path))
    assert rows.shape == (10, 1 + 3 * 6)  # the step, then the six named points' x y z
    apart = np.radians([110, 10] * 3)  # base radius 1, platform 0.6 at height 1
    legs = np.sqrt(1 + 0.6**2 + 1 - 2 * 0.6 * np.cos(apart))
    readme = (tmp_path / "stewart_fk" / "stewart_fk_README.md").read_text()
    held = re.search(r"u0\[STEWART_FK_NU\] = \{ (.*?) \};", readme)
    assert held is not None
    assert np.allclose([float(v) for v in held.group(1).split(",")], legs, rtol=1e-12)
    # the first named point, the platform's P1, where the file draws it (x, y; height 1)
    assert np.allclose(rows[0, 1:4], [-0.10418890660015805, 0.5908846518073249, 1.0],
                       atol=2e-6)
