"""The error model's cheap bound in the generated C (``<prefix>_within_bound``): where it
clears a point the model could not have flagged it. The generated ``<prefix>_flagged`` (its
bound first, then the model) is compiled into a small program and run on many random points
-- near the targets as well as far from them -- and compared with the runtime's own model,
``runtime.solving.accuracy.flagged_norms``, written in Python: the same answer at every point. Also
a point whose condition is not finite is flagged."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.contract import options as contract
from symkin.contract import tuning
from symkin.runtime.solving import accuracy

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")

HARNESS = r"""
#include <stdio.h>
#include "@P@_solver.c"
/* one point a line: inv_norm cond residual correction nq ndq nddq target_q target_dq
   target_ddq; prints the generated model's flag */
int main(void)
{
    @P@_options o;
    static @P@_workspace w;
    @P@_report r;
    double v[10];
    @P@_default_options(&o);
    while (scanf("%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3],
                 &v[4], &v[5], &v[6], &v[7], &v[8], &v[9]) == 10) {
        r.inv_norm = v[0];
        r.cond = v[1];
        r.residual = v[2];
        w.correction = v[3];
        o.target_q = v[7];
        o.target_dq = v[8];
        o.target_ddq = v[9];
        @P@_region_for(&o, &w); /* as each call does: here every point is a call */
        printf("%d\n", @P@_flagged(&o, &w, &r, v[4], v[5], v[6], 2));
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def model_program(crank_slider_system, tmp_path_factory) -> tuple[Path, int]:
    folder = tmp_path_factory.mktemp("flag_bound")
    symkin.generate(crank_slider_system, backend="c", out_dir=folder)
    prefix = crank_slider_system.name
    (folder / "main.c").write_text(HARNESS.replace("@P@", prefix))
    program = folder / "main"
    sources = [str(p) for p in sorted(folder.glob("*.c"))
               if p.name not in ("main.c", f"{prefix}_solver.c")]
    subprocess.run(["gcc", "-std=c99", "-O2", f"-I{folder}", "-o", str(program),
                    str(folder / "main.c"), *sources, "-lm"], check=True)
    return program, len(crank_slider_system.q)


def _points(count: int, seed: int) -> np.ndarray:
    """Random points, log-uniform over wide ranges so that the targets are met by some and
    missed by others, and a share right at the edge (residuals near target / s)."""
    rng = np.random.default_rng(seed)
    inv_norm = 10.0 ** rng.uniform(-1, 7, count)
    norm_a = 10.0 ** rng.uniform(-1, 2, count)
    residual = 10.0 ** rng.uniform(-18, -8, count)
    correction = np.where(rng.random(count) < 0.5, -1.0, 10.0 ** rng.uniform(-16, -7, count))
    nq, ndq = 10.0 ** rng.uniform(-3, 4, count), 10.0 ** rng.uniform(-3, 4, count)
    nddq = 10.0 ** rng.uniform(-3, 6, count)
    targets = 10.0 ** rng.uniform(-12, -4, (count, 3))
    return np.column_stack([inv_norm, inv_norm * norm_a, residual, correction, nq, ndq, nddq,
                            targets])


def test_the_generated_model_flags_as_the_runtime_model(model_program) -> None:
    """At 20,000 random points the generated flag equals runtime.solving.accuracy's: the bound
    never clears a point the model flags (nor does anything else)."""
    program, n = model_program
    points = _points(20000, 38)
    text = "\n".join(" ".join(repr(float(x)) for x in row) for row in points)
    out = subprocess.run([str(program)], input=text, capture_output=True, text=True,
                         check=True).stdout.split()
    generated = np.array([int(v) for v in out], dtype=bool)
    assert generated.size == len(points)
    expected = np.empty(len(points), dtype=bool)
    for k, row in enumerate(points):
        inv_norm, cond, residual, correction, nq, ndq, nddq, tq, tdq, tddq = map(float, row)
        options = contract.Options(target_q=tq, target_dq=tdq, target_ddq=tddq)
        expected[k] = accuracy.flagged_norms(
            inv_norm, cond / inv_norm, residual, n, nq, ndq, nddq, options,
            tuning.UNIT_ROUNDOFF["double"], math.nan if correction < 0 else correction)
    assert 0.2 < expected.mean() < 0.8  # both answers well represented
    wrong = np.flatnonzero(generated != expected)
    assert wrong.size == 0, f"{wrong.size} points differ, the first: {points[wrong[0]]}"


def test_a_non_finite_condition_is_flagged(model_program) -> None:
    program, _ = model_program
    line = "1 {cond} 1e-15 -1 1 1 1 1e-8 1e-7 1e-6"
    text = "\n".join(line.format(cond=c) for c in ("inf", "nan"))
    out = subprocess.run([str(program)], input=text, capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["1", "1"]


REGION_HARNESS = r"""
#include <stdio.h>
#include "@P@_solver.c"
/* sequences of points, one a line as above; a line "new" starts a sequence (a fresh
   workspace). Prints per point: whether the bound's region held it (covered), the flag, and
   whether the region cleared the end of a step from the last point's norms (region_clears)
   with the norms it cleared for. */
int main(void)
{
    @P@_options o;
    static @P@_workspace w;
    @P@_report r;
    double v[10];
    char word[64];
    @P@_default_options(&o);
    while (scanf("%63s", word) == 1) {
        int i, covered, flag, clears;
        if (word[0] == 'n') {
            for (i = 0; i < 9; ++i) w.region[i] = -1;
            w.norms[0] = w.norms[1] = w.norms[2] = 0;
            continue;
        }
        sscanf(word, "%lf", &v[0]);
        for (i = 1; i < 10; ++i) if (scanf("%lf", &v[i]) != 1) return 1;
        r.inv_norm = v[0];
        r.cond = v[1];
        r.residual = v[2];
        w.correction = v[3];
        o.target_q = v[7];
        o.target_dq = v[8];
        o.target_ddq = v[9];
        w.clear[0] = w.clear[1] = -1;
        @P@_region_for(&o, &w); /* as each call does, once: here every point is a call */
        clears = @P@_region_clears(&w, &r);
        covered = @P@_covered(&w, &r, v[4], v[5], 7);
        flag = @P@_flagged(&o, &w, &r, v[4], v[5], v[6], 2);
        printf("%d %d %d %.17g %.17g\n", covered, flag, clears, w.clear[0], w.clear[1]);
        w.norms[0] = v[4];
        w.norms[1] = v[5];
        w.norms[2] = v[6];
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def region_program(crank_slider_system, tmp_path_factory) -> tuple[Path, int]:
    folder = tmp_path_factory.mktemp("flag_region")
    symkin.generate(crank_slider_system, backend="c", out_dir=folder)
    prefix = crank_slider_system.name
    (folder / "main.c").write_text(REGION_HARNESS.replace("@P@", prefix))
    program = folder / "main"
    sources = [str(p) for p in sorted(folder.glob("*.c"))
               if p.name not in ("main.c", f"{prefix}_solver.c")]
    subprocess.run(["gcc", "-std=c99", "-O2", f"-I{folder}", "-o", str(program),
                    str(folder / "main.c"), *sources, "-lm"], check=True)
    return program, len(crank_slider_system.q)


def _walks(sequences: int, length: int, seed: int) -> list[np.ndarray]:
    """Sequences of points as a run meets them: targets fixed per sequence (in half of them
    other targets from some point on, as a later call may pass), the condition and the norms
    drifting by a few per cent a step (now and then a jump), residuals anywhere in their
    range and, at one point in ten, a Newton correction that was solved for. The targets are
    drawn so that a sequence crosses the edge of the bound and of the model."""
    rng = np.random.default_rng(seed)
    walks = []
    for _ in range(sequences):
        steps = rng.normal(0.0, 0.05, (length, 3)) + np.where(
            rng.random((length, 3)) < 0.03, rng.normal(0.0, 1.5, (length, 3)), 0.0)
        inv_norm, nq, ndq = (10.0 ** (rng.uniform(low, high) + np.cumsum(steps[:, k]))
                             for k, (low, high) in enumerate([(0, 5), (-2, 3), (-2, 3)]))
        cond = inv_norm * 10.0 ** rng.uniform(-1, 2)
        residual = 10.0 ** rng.uniform(-18, -11, length)
        correction = np.where(rng.random(length) < 0.1, 10.0 ** rng.uniform(-16, -8, length),
                              -1.0)
        nddq = 10.0 ** rng.uniform(-3, 6, length)
        targets = np.tile(10.0 ** rng.uniform(-11, -4, 3), (length, 1))
        if rng.random() < 0.5:  # other targets from a point on: a region is not carried over
            targets[rng.integers(1, length):] = 10.0 ** rng.uniform(-11, -4, 3)
        walks.append(np.column_stack([inv_norm, cond, residual, correction, nq, ndq, nddq,
                                      targets]))
    return walks


def _model(row: np.ndarray, n: int, nq: float | None = None, ndq: float | None = None) -> bool:
    inv_norm, cond, residual, correction, q, dq, nddq, tq, tdq, tddq = map(float, row)
    options = contract.Options(target_q=tq, target_dq=tdq, target_ddq=tddq)
    return accuracy.flagged_norms(
        inv_norm, cond / inv_norm, residual, n, q if nq is None else nq,
        dq if ndq is None else ndq, nddq, options, tuning.UNIT_ROUNDOFF["double"],
        math.nan if correction < 0 else correction)


def test_the_bound_s_region_flags_as_the_runtime_model(region_program) -> None:
    """The region where the cheap bound was proven (<prefix>_covered, _widen) stands for the
    bound along runs of points: at 20,000 points in 200 drifting sequences the generated flag
    equals runtime.solving.accuracy's, and many points are decided by the region alone. Where
    region_clears cleared a step's end for norms up to work->clear, the model flags no point
    with those norms (the largest ones are tried)."""
    program, n = region_program
    walks = _walks(200, 100, 41)
    text = "\n".join("new\n" + "\n".join(" ".join(repr(float(x)) for x in row) for row in walk)
                     for walk in walks)
    out = subprocess.run([str(program)], input=text, capture_output=True, text=True,
                         check=True).stdout.splitlines()
    rows = np.vstack(walks)
    got = np.array([[float(x) for x in line.split()] for line in out])
    assert got.shape == (len(rows), 5)
    covered, generated, clears = got[:, 0] == 1, got[:, 1] == 1, got[:, 2] == 1
    expected = np.array([_model(row, n) for row in rows])
    assert 0.2 < expected.mean() < 0.8  # both answers well represented
    wrong = np.flatnonzero(generated != expected)
    assert wrong.size == 0, f"{wrong.size} points differ, the first: {rows[wrong[0]]}"
    # the region decides a good share of the points the model clears (46 % at this seed),
    # and clears the end of many steps
    assert covered[~expected].mean() > 0.3 and clears.sum() > 1000
    assert not expected[covered].any()
    for k in np.flatnonzero(clears):  # the end of that step at the largest norms cleared
        assert not _model(rows[k], n, nq=got[k, 3], ndq=got[k, 4]), rows[k]
