"""Every set of a sweep starts as its own ``symkin.solve`` starts (sweeps.starts): a set drawn at
a dead centre at t0 is reported as a singular start, also when the C batch steps through it;
a set drawn far from unit size is solved in its own unit inside the C batch.

References derived here. The crank-slider of the examples (crank a, rod b, the slider's guide
at c) is driven by theta = t^2 + pi/2, so at t0 the crank points along the guide (sin theta =
1): crank and rod are collinear, a dead centre, exactly when |c - a| = b. At the inner dead
centre c = a - b the motion then moves back into range (c - a sin theta grows above -b), so
the C batch solves the whole grid from it; at the outer one c = a + b it cannot go on. And a
mechanism scaled by k moves the same: lengths times k, angles alike, the crank's angle t^2 +
pi/2 at every scale. Each set is also compared with its own symkin.solve, both backends.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.errors import SolveError
from symkin.sweeps import starts
from tests.driver_support import kernel_for, same_condition

ROOT = Path(__file__).resolve().parents[2]
T = np.linspace(0.0, 1.5, 31)


def _regular(count: int, seed: int = 5) -> np.ndarray:
    """Designs within ±5 % of the textbook's, far from a dead centre at t0 (|c - a| <= 3.5
    against b >= 4.75)."""
    rng = np.random.default_rng(seed)
    return np.array([1.0, 5.0, 4.0]) * (1 + rng.uniform(-0.05, 0.05, size=(count, 3)))


def _per_set(kernel, result, j: int, p: np.ndarray, t: np.ndarray, q0=None) -> str:
    """Set j of the sweep against its own symkin.solve; returns the reason ("" if solved)."""
    try:
        trajectory = symkin.solve(kernel, t=t, params=p, q0=q0)
    except SolveError as failure:
        assert result.reasons[j] == failure.reason, (j, result.messages[j], str(failure))
        same_condition(result.messages[j], str(failure))
        assert result.t_reached[j] == failure.t
        done = failure.trajectory.t.size
        assert result.solved[j] == done
        np.testing.assert_allclose(result.q[j, :done], failure.trajectory.q, rtol=1e-12,
                                   atol=0)
        assert np.isnan(result.q[j, done:]).all()
        return failure.reason
    assert result.status[j] == 0 and result.reasons[j] == "", result.messages[j]
    for name in ("q", "dq", "d2q"):
        np.testing.assert_allclose(getattr(result, name)[j], getattr(trajectory, name),
                                   rtol=1e-12, atol=1e-12 * np.abs(getattr(trajectory, name)).max())
    return ""


def test_sets_drawn_at_a_dead_centre_are_singular_starts_as_per_set_solve(crank_slider,
                                                                           reruns) -> None:
    regular = _regular(12)
    a, b = 1.0, 5.0
    # inner dead centre c = a - b (exactly, and 1e-12 and 1e-10 from it: the start is still
    # singular to the scaled test), outer c = a + b; the C batch steps through the inner ones
    dead = np.array([[a, b, a - b], [a, b, a - b + 1e-12], [a, b, a - b + 1e-10],
                     [2.0, b, 2.0 - b + 1e-12], [a, b, a + b], [a, b, a + b - 1e-12]])
    designs = np.concatenate([regular[:5], dead[:3], regular[5:9], dead[3:], regular[9:]])
    at_dead_centre = np.isin(np.arange(len(designs)), [5, 6, 7, 12, 13, 14])
    assert np.allclose(np.abs(designs[at_dead_centre, 2] - designs[at_dead_centre, 0]), b,
                       atol=1e-9)
    result = symkin.sweep(crank_slider, designs, T, workers=1)
    reasons = [_per_set(crank_slider, result, j, p, T) for j, p in enumerate(designs)]
    assert [r == "singular" for r in reasons] == list(at_dead_centre)
    for j in np.flatnonzero(at_dead_centre):
        assert "in a singular or limit configuration" in result.messages[j]
        assert result.solved[j] <= 1  # the assembled start at most, nothing stepped from it
    assert result.ok[~at_dead_centre].all()
    if crank_slider.backend == "c":  # only the singular starts left the C batch
        assert sorted(reruns) == list(np.flatnonzero(at_dead_centre))


def test_the_start_check_costs_no_python_per_set_away_from_a_dead_centre(
        crank_slider_system, monkeypatch) -> None:
    """Regular starts are cleared by the batch's condition estimate, in C: runtime.solving.start's
    check (a Phi_q evaluation and an inverse per set) never runs for them."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    checked: list[int] = []
    original = starts.singular_start

    def spy(*arguments):
        checked.append(1)
        return original(*arguments)

    monkeypatch.setattr(starts, "singular_start", spy)
    result = symkin.sweep(kernel, _regular(300), T, workers=1)
    assert "singular" not in result.reasons and checked == []  # (some reach a limit later)
    designs = np.concatenate([_regular(3), [[1.0, 5.0, -4.0 + 1e-12]]])
    result = symkin.sweep(kernel, designs, T, workers=1)
    assert checked == [1] and list(result.reasons) == ["", "", "", "singular"]


SCALES = np.array([1e-3, 3e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 300.0, 1e3])


def test_sets_far_from_unit_size_are_solved_in_their_unit_in_the_batch(crank_slider,
                                                                       reruns) -> None:
    """The crank-slider scaled by k = 1e-3 .. 1e3 (its length scale 5k outside 0.01 .. 100
    for the outer ones): every set equals its own symkin.solve, stays in the C batch, and
    moves as the unscaled one, lengths times k."""
    designs = np.outer(SCALES, [1.0, 5.0, 4.0])
    result = symkin.sweep(crank_slider, designs, T, workers=1)
    assert result.ok.all()
    for j, p in enumerate(designs):
        assert _per_set(crank_slider, result, j, p, T) == ""
    if crank_slider.backend == "c":
        assert reruns == []
    lengths = np.array([name.endswith((".x", ".y")) for name in crank_slider.coordinates])
    unit = SCALES.tolist().index(1.0)
    for j, k in enumerate(SCALES):
        for name in ("q", "dq", "d2q"):
            rows = getattr(result, name)
            scaled = np.where(lengths, rows[j] / k, rows[j])
            np.testing.assert_allclose(scaled, rows[unit], rtol=1e-11, atol=1e-11)
    crank = crank_slider.coordinates.index("crank.phi")
    np.testing.assert_allclose(result.q[:, :, crank], np.broadcast_to(T**2 + np.pi / 2,
                                                                      (SCALES.size, T.size)),
                               atol=1e-12)


def test_scaled_sets_with_failures_equal_per_set_solve(crank_slider, reruns) -> None:
    """Scaled sets that reach a limit position or cannot be assembled, and a singular start,
    at 1e-3, 1 and 1e3 times the size: each as its own symkin.solve. On C the limits are
    bisected in the set's unit without a re-run."""
    base = np.array([[1.0, 5.0, 4.0], [1.0, 5.0, 5.9], [1.0, 5.0, 7.0], [1.0, 5.0, -4.0 + 1e-12]])
    designs = np.concatenate([base * 1e-3, base, base * 1e3])
    result = symkin.sweep(crank_slider, designs, T, workers=1)
    reasons = [_per_set(crank_slider, result, j, p, T) for j, p in enumerate(designs)]
    assert reasons == ["", "limit position", "no assembly", "singular"] * 3
    if crank_slider.backend == "c":
        assert sorted(reruns) == [2, 3, 6, 7, 10, 11]


def test_length_scales_in_c_are_the_largest_lever_arm(crank_slider_system) -> None:
    """<prefix>_length_scales against the closed form. In the crank-slider's Phi_q the rows of
    the joint rod-slider (at [b, 0] on the rod) hold -b sin phi and b cos phi in the rod's
    angle column beside unit entries in x and y; those of the crank's tip -a sin theta and
    a cos theta; the slide's rows no lever. At q = 0 the largest arm is b. At the assembled
    start the crank is vertical (theta = pi/2: arm a) and the rod climbs from its tip (0, a) to
    the guide y = c, sin phi = (c - a) / b: arms |c - a| and sqrt(b^2 - (c - a)^2). A NaN
    coordinate gives NaN; the units follow as runtime.solving.units decides."""
    kernel = symkin.compile(crank_slider_system, backend="c")
    designs = np.outer(SCALES, [1.0, 5.0, 4.0])
    a, b, c = designs.T
    solver = kernel.batch_solver
    zeros = np.zeros(len(kernel.coordinates))
    np.testing.assert_allclose(solver.length_scales(designs, zeros, 0.0), b, rtol=1e-15)
    result = symkin.sweep(kernel, designs, T, workers=1)
    at_start = np.maximum.reduce([a, np.abs(c - a), np.sqrt(b**2 - (c - a) ** 2)])
    np.testing.assert_allclose(solver.length_scales(designs, result.q[:, 0], 0.0), at_start,
                               rtol=1e-12)
    broken = zeros.copy()
    broken[kernel.coordinates.index("rod.phi")] = np.nan
    assert np.isnan(solver.length_scales(designs[:1], broken, 0.0)).all()
    # 5k = 0.005, 0.015, ..., 500, 1500, 5000: outside 0.01 .. 100 the power of 10 below it
    expected = [1e-3, 1.0, 1.0, 1.0, 1.0, 1.0, 100.0, 1e3, 1e3]
    assert starts.set_units(solver, designs, 0.0, zeros).tolist() == expected


# A slider-crank a = 1, b = 3 driven by the slider's position x0 - t, each set with its own
# first guess: the assembly at x0 in closed form (law of cosines, crank up). x0 = a + b is the
# dead centre (crank and rod collinear along the slide).
SLIDER_CRANK = """
name: slider_crank_limit
parameters: {a: 1.0, b: 3.0, x0: 3.5}
bodies:
  crank:  {q0: [0, 0, 0]}
  rod:    {q0: [0, 0, 0]}
  slider: {q0: [0, 0, 0]}
joints:
  - {type: revolute,  name: O,     i: ground, j: crank,  sA: [0, 0], sB: [0, 0]}
  - {type: revolute,  name: A,     i: crank,  j: rod,    sA: [a, 0], sB: [0, 0]}
  - {type: revolute,  name: B,     i: rod,    j: slider, sA: [b, 0], sB: [0, 0]}
  - {type: prismatic, name: guide, i: slider, j: ground, sA: [0, 0], sB: [0, 0], v: [0, 1]}
drivers:
  - {type: slide, name: push, i: ground, j: slider, sA: [0, 0], sB: [0, 0], u: [1, 0],
     f: "x0 - t"}
time: {t0: 0, t1: 0.5, dt: 0.05}
"""


def _assembled(x0: float, a: float = 1.0, b: float = 3.0) -> list[float]:
    phi = np.arccos((a * a + x0 * x0 - b * b) / (2 * a * x0))
    ax, ay = a * np.cos(phi), a * np.sin(phi)
    return [0.0, 0.0, phi, ax, ay, np.arctan2(-ay, x0 - ax), x0, 0.0, 0.0]


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_slider_cranks_drawn_at_their_dead_centre_with_own_guesses(tmp_path, backend) -> None:
    path = tmp_path / "slider_crank_limit.yaml"
    path.write_text(SLIDER_CRANK)
    kernel = kernel_for(symkin.derive(symkin.load(path)), backend)
    x0 = np.array([3.5, 4.0 - 1e-13, 3.9, 4.0 - 1e-11, 3.99, 4.0 - 1e-12, 3.0])
    dead = x0 > 4.0 - 1e-10  # a + b = 4, the start within rounding of it
    designs = np.column_stack([np.ones(x0.size), np.full(x0.size, 3.0), x0])
    guesses = np.array([_assembled(x) for x in x0])
    t = np.linspace(0.0, 0.5, 11)
    result = symkin.sweep(kernel, designs, t, q0=guesses, workers=1)
    reasons = [_per_set(kernel, result, j, p, t, guesses[j]) for j, p in enumerate(designs)]
    assert [r == "singular" for r in reasons] == list(dead)
    assert result.ok[~dead].all()
    crank = kernel.coordinates.index("crank.phi")
    for j in np.flatnonzero(~dead):  # the crank follows the law of cosines
        x = x0[j] - t
        np.testing.assert_allclose(result.q[j, :, crank],
                                   np.arccos((1 + x * x - 9) / (2 * x)), atol=1e-9)


def test_a_float_kernel_sweep_with_a_limit_ends_as_per_set_solve(crank_slider_system) -> None:
    """In float the C substeps would fall below the resolution of t (they hung): such a set is
    decided by symkin.solve's own edge treatment, in double."""
    kernel = symkin.compile(crank_slider_system, backend="c", real="float")
    assert kernel.edge_solver() is None
    designs = np.array([[1.0, 5.0, 4.0], [1.0, 5.0, 5.9]])
    result = symkin.sweep(kernel, designs, T, workers=1)
    assert list(result.reasons) == ["", "limit position"]
    with pytest.raises(SolveError) as caught:
        symkin.solve(kernel, t=T, params=designs[1])
    assert result.messages[1] == str(caught.value)




_EDGE = """
import json, sys
import numpy as np
import symkin
from symkin import backends
from symkin.backends.c.edge import EdgeSolver
from symkin.build.cache import open_cache
from symkin.contract.options import Options
files = json.loads(open(sys.argv[1], encoding="utf-8").read())
kernel = backends.get("c").build(files, open_cache())
p = np.array([1.0, 5.0, 5.9])
run = symkin.solve(kernel, t=np.linspace(0.0, 0.05, 6), params=p)
edge = EdgeSolver(kernel.ffi, kernel.lib, kernel.name, kernel.nq)
found = edge(Options(), p, (float(run.t[-1]), run.q[-1], run.dq[-1], run.d2q[-1]),
             float(run.cond[-1]), 1.0, {h_min!r}, {h_min!r})
print(found.outcome, kernel.lib.CRANK_SLIDER_EDGE_STOPPED, found.t, found.failed, kernel.real)
"""


def _edge_search(tmp_path: Path, real: str, h_min: float) -> tuple[int, int, float, float]:
    """The search in a process of its own (a search that never ends meets the timeout). The
    generated files come from this run's shared System and sources (codegen_support), so the
    process builds, or finds in the kernel cache, what symkin.compile would: no derivation."""
    from codegen_support import sources

    options = {} if real == "double" else {"real": real}
    files = tmp_path / f"edge_{real}.json"
    files.write_text(json.dumps(sources(ROOT / "examples" / "crank_slider.yaml", "c", **options)),
                     encoding="utf-8")
    script = tmp_path / f"edge_{real}.py"
    script.write_text(_EDGE.format(h_min=h_min))
    done = subprocess.run([sys.executable, str(script), str(files)], capture_output=True,
                          text=True, timeout=240, check=False,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr
    outcome, stopped, t, failed, built = done.stdout.split()
    assert built == real  # the files were generated with the precision asked for
    return int(outcome), int(stopped), float(t), float(failed)


def test_the_generated_edge_search_ends_in_float_too(tmp_path) -> None:
    """The generated solve_edge called from C directly, towards the limit position of the
    crank-slider with c = 5.9, where cos(theta) = (c - b) / a, theta = t^2 + pi/2 (closed
    form, as _limit_time). In double with h_min 1e-6 it stops there; in float with h_min and
    delta below the resolution of a float t its substeps used to double and halve forever (a
    step that cannot move t passed as solved): now they end, blocked short of the limit, never
    past it (float cannot reach the default tolerances near a limit)."""
    limit = float(np.sqrt(np.arccos(0.9)))
    outcome, stopped, t, failed = _edge_search(tmp_path, "double", 1e-6)
    assert outcome == stopped and abs(t - limit) < 2e-6 and failed <= 2e-6
    _, _, t, failed = _edge_search(tmp_path, "float", 1e-12)
    assert failed > 0 and t <= limit


def test_a_tie_of_the_largest_is_named_by_its_first_time_not_by_rounding() -> None:
    """rod.P.y spread the same at every time (up to rounding noise, which differs between the
    backends): the summary names the first time, on either backend."""
    from symkin.sweeps.result import first_of_largest

    width = np.full(31, 0.2) + np.random.default_rng(1).normal(scale=1e-15, size=31)
    assert first_of_largest(width) == 0
    width[7] = 0.3
    assert first_of_largest(width) == 7
    assert first_of_largest(np.array([np.nan, 1.0, 1.0 + 1e-12, 0.5])) == 1
    assert first_of_largest(np.array([[0.1, 2.0], [2.0, 0.3]])) == 1
