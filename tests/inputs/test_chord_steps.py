"""The generated C's input-driven solve, which starts with simplified Newton steps on the
factors of the last solution (no new Phi_q until they have converged), against independent
references along a finely sampled path, as a controller samples it (the steps then move q a
little, and those steps are what the simplified iteration serves):

- the pose by the closed-form inverse kinematics of the delta robot (tests/inputs/
  test_parallel_fk_examples.py) to 1e-12, and q, dq, ddq equal to the NumPy backend's (full
  Newton at every point, the Python runtime) to 1e-12: the simplified steps stop at the
  rounding level, not at a tolerance;
- the 1-norm of the change of Phi_q by which the C solver decides whether the condition
  estimate it carries from point to point must be made afresh, against NumPy's.
"""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from codegen_support import golden_folder

import symkin
from tests.inputs.test_parallel_fk_examples import _delta_angles, _delta_centres, _kernel

T = np.linspace(0.0, 1.0, 2001)  # 2000 points a cycle: steps of about 2e-4 in the pose


def _inputs() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arm angles along the path, with rates and accelerations by central differences
    (any values serve: both backends solve with the same ones)."""
    u = _delta_angles(_delta_centres(T))
    du = np.gradient(u, T, axis=0)
    return u, du, np.gradient(du, T, axis=0)


# The reference's rows: every 20th point of the path. Full Newton converges to the same
# rounding level from any nearby start, so its solution at a point does not depend on the
# points solved before it; the C solver's simplified steps do, and it runs the whole path.
EVERY = slice(None, None, 20)


def test_simplified_steps_give_newtons_solution() -> None:
    u, du, ddu = _inputs()
    c = symkin.solve(_kernel("delta_fk", "c"), t=T, inputs=u, input_rates=du, input_accels=ddu)
    reference = symkin.solve(_kernel("delta_fk", "numpy"), t=T[EVERY], inputs=u[EVERY],
                             input_rates=du[EVERY], input_accels=ddu[EVERY])
    names = _kernel("delta_fk", "c").coordinates
    at = [names.index(f"platform.{axis}") for axis in ("x", "y", "z")]
    assert np.max(np.abs(c.q[:, at] - _delta_centres(T))) < 1e-12
    assert np.max(np.abs(c.q[EVERY] - reference.q)) < 1e-12
    for got, want in ((c.dq[EVERY], reference.dq), (c.d2q[EVERY], reference.d2q)):
        assert np.max(np.abs(got - want)) < 1e-12 * max(1.0, np.max(np.abs(want)))


HARNESS = r"""
#include <stdio.h>
#include "delta_fk_solver.c" /* its static functions, in this program */
int main(void)
{
    delta_fk_real a[DELTA_FK_NNZ], b[DELTA_FK_NNZ];
    int e;
    for (e = 0; e < DELTA_FK_NNZ; ++e) {
        a[e] = (e % 7) - 3.25 + 0.5 * (e % 3);
        b[e] = (e % 5) * 0.75 - 1;
    }
    printf("%.17g\n", delta_fk_difference_norm1(a, b));
    b[3] = NAN;
    printf("%.17g\n", delta_fk_difference_norm1(a, b));
    return 0;
}
"""


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")
def test_difference_norm_is_the_largest_column_sum(tmp_path: Path) -> None:
    """The test that lets the condition estimate be carried (theta = ||A^-1||_1 ||A' - A||_1)
    needs ||A' - A||_1: the largest column sum of |A' - A|, here against NumPy's on the
    matrices scattered from the pattern; NaN when an entry is."""
    folder = tmp_path / "delta_fk"
    shutil.copytree(golden_folder("delta_fk", "c"), folder)  # what generate writes (test_generated)
    (folder / "harness.c").write_text(HARNESS)
    # The function under test is compiled into the harness (with the solver it includes) at
    # -O2, as the kernel's build compiles it; the other files are only there for the linker
    # (the harness calls none of their functions), so they are compiled unoptimised: the
    # kernel's 157 kB of -O2 cost seconds and changed nothing the harness runs.
    linked = [str(path) for path in sorted(folder.glob("*.c"))
              if not path.name.endswith(("_solver.c", "harness.c"))]
    subprocess.run(["gcc", "-std=c99", "-O0", "-c", *linked], cwd=folder, check=True)
    objects = [str(folder / Path(source).with_suffix(".o").name) for source in linked]
    exe = folder / "harness"
    subprocess.run(["gcc", "-std=c99", "-O2", f"-I{folder}", "-o", str(exe),
                    str(folder / "harness.c"), *objects, "-lm"], check=True)
    printed = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    norm, with_nan = (float(v) for v in printed.split())
    kernel = _kernel("delta_fk", "numpy")
    e = np.arange(len(kernel.pattern_rows))
    a, b = (e % 7) - 3.25 + 0.5 * (e % 3), (e % 5) * 0.75 - 1
    difference = np.zeros((kernel.nq, kernel.nq))
    difference[kernel.pattern_rows, kernel.pattern_cols] = a - b
    assert norm == pytest.approx(np.linalg.norm(difference, 1), rel=1e-15)
    assert math.isnan(with_nan)
