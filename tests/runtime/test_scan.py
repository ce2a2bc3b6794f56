"""symkin scan: assembly branches at t0, singular configurations and limit positions over the
driver range, on both backends (the C kernel really built and run).

References are closed forms derived here: circle intersections for the branches of a four-bar,
the law of cosines for the non-Grashof limit, the parallelogram's change point where the
driven angle 0.5 - t is zero.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, symkin_main
from codegen_support import compiled

from symkin.runtime import driver
from symkin.runtime.scanning.scan import scan

ROOT = Path(__file__).resolve().parents[2]
MECHANISMS = ROOT / "tests" / "mechanisms"
BACKENDS = ("numpy", "c")
T_LIMIT = math.acos(-0.25)  # non_grashof.yaml: a = b = c = 2, d = 3; cos(theta*) = -1/4


def _kernel(name: str, backend: str):
    kernel = compiled(MECHANISMS / f"{name}.yaml", backend)  # built once per test run
    assert kernel.backend == backend
    return kernel


def circles(c1: np.ndarray, r1: float, c2: np.ndarray, r2: float) -> list[np.ndarray]:
    """The two intersections of two circles that meet."""
    d = float(np.linalg.norm(c2 - c1))
    along = (r1**2 - r2**2 + d**2) / (2 * d)
    height = math.sqrt(r1**2 - along**2)
    u = (c2 - c1) / d
    n = np.array([-u[1], u[0]])
    return [c1 + along * u + height * n, c1 + along * u - height * n]


def _angle_gap(a: float, b: float) -> float:
    return abs(math.remainder(a - b, 2 * math.pi))


def _coordinate(kernel, q: np.ndarray, name: str) -> float:
    return float(q[list(kernel.coordinates).index(name)])


@pytest.mark.parametrize("backend", BACKENDS)
def test_four_bar_has_exactly_two_branches_elbow_up_and_down(backend: str) -> None:
    kernel = _kernel("non_grashof", backend)
    theta = 0.7
    report = scan(kernel, t=driver.grid(theta, 2.5, 0.05))
    assert len(report.branches) == 2 and report.t0 == theta
    assert [b.taken for b in report.branches] == [True, False]
    a = np.array([2 * math.cos(theta), 2 * math.sin(theta)])  # crank tip, crank a = 2
    ground = np.array([3.0, 0.0])  # O4, d = 3
    expected = [(math.atan2(*(b - a)[::-1]), math.atan2(*(b - ground)[::-1]))
                for b in circles(a, 2.0, ground, 2.0)]  # coupler b = 2, rocker c = 2
    found = [(_coordinate(kernel, br.q, "coupler.phi"), _coordinate(kernel, br.q, "rocker.phi"))
             for br in report.branches]
    for coupler, rocker in expected:
        assert any(_angle_gap(coupler, fc) < 1e-8 and _angle_gap(rocker, fr) < 1e-8
                   for fc, fr in found), (expected, found)
    for branch in report.branches:
        assert _coordinate(kernel, branch.q, "coupler.x") == pytest.approx(a[0], abs=1e-9)
        assert _coordinate(kernel, branch.q, "coupler.y") == pytest.approx(a[1], abs=1e-9)
        assert not branch.near_singular


@pytest.mark.parametrize("backend", BACKENDS)
def test_non_grashof_limit_position_on_every_branch(backend: str) -> None:
    kernel = _kernel("non_grashof", backend)
    report = scan(kernel, all_branches=True)
    assert len(report.motions) == 2
    for motion in report.motions:
        assert motion.stop is not None and motion.stop.reason == "limit position"
        assert abs(motion.stop.t - T_LIMIT) < 1e-6
        assert motion.reached < T_LIMIT
        assert {j.split()[1] for j in motion.stop.joints} == {"A", "B", "O4"}
        assert motion.stop.drivers == ("drivers[0] input angle crank-ground",)
        assert motion.singular == ()


@pytest.mark.parametrize("backend", BACKENDS)
def test_parallelogram_change_point_is_passed_with_rank_loss_one(backend: str) -> None:
    kernel = _kernel("parallelogram", backend)
    report = scan(kernel)
    (motion,) = report.motions  # only the branch a run takes
    assert report.branches[motion.branch].taken
    assert motion.stop is None and motion.reached == 1.0
    ((t, rank_loss, groups),) = motion.singular
    assert abs(t - 0.5) < 1e-6 and rank_loss == 1  # theta = 0.5 - t = 0: all bars on the x axis
    assert {row.split()[1] for row in groups[0]} == {"O0", "O1", "A0", "B0"}
    assert motion.flagged == ((0.5, 0.5),)
    # Two assemblies at t0 (theta = 0.5): the parallelogram and the folded rhombus, where the
    # coupler's far end B is the other intersection of the circles about A and O1.
    a = np.array([math.cos(0.5), math.sin(0.5)])
    ends = circles(a, 1.0, np.array([1.0, 0.0]), 1.0)
    expected = sorted(math.atan2(*(b - a)[::-1]) for b in ends)
    found = sorted(_coordinate(kernel, b.q, "c0.phi") for b in report.branches)
    assert len(found) == 2
    assert all(_angle_gap(e, f) < 1e-8 for e, f in zip(expected, found)), (expected, found)


def _cli(*args: str) -> Ran:
    return symkin_main("scan", *args, cwd=ROOT)


def test_cli_reports_branches_and_limit_position() -> None:
    result = _cli(str(MECHANISMS / "non_grashof.yaml"), "--backend", "c", "--all-branches")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "assembly branches at t = 0: 2" in out
    assert "(reached from q0: a run takes it)" in out
    assert out.count("limit position at t = 1.82347658") == 2
    assert "B revolute coupler-rocker" in out and "input angle crank-ground cannot go on" in out


def test_cli_reports_a_singular_configuration() -> None:
    result = _cli(str(MECHANISMS / "parallelogram.yaml"), "--backend", "numpy", "--t1", "0.8")
    assert result.returncode == 0, result.stderr
    assert "singular configuration passed at t = 0.50000000" in result.stdout
    assert "loses rank 1" in result.stdout and "reaches the end of the grid, t = 0.8" \
        in result.stdout


def test_cli_set_moves_the_limit_position() -> None:
    # d = 2.5: cos(theta*) = (a^2 + d^2 - (b + c)^2) / (2 a d) = (4 + 6.25 - 16) / 10
    result = _cli(str(MECHANISMS / "non_grashof.yaml"), "--backend", "numpy", "--set", "d=2.5")
    assert result.returncode == 0, result.stderr
    line = next(x for x in result.stdout.splitlines() if "limit position at t = " in x)
    found = float(line.split("limit position at t = ")[1].split(":")[0])
    assert abs(found - math.acos(-0.575)) < 1e-6


@pytest.mark.parametrize("stop", ["keyboard", "solve"])
def test_cli_ctrl_c_exits_130(stop: str, monkeypatch: pytest.MonkeyPatch,
                              capsys: pytest.CaptureFixture[str]) -> None:
    import symkin.runtime.scanning.scan as module
    from symkin.cli import main
    from symkin.runtime.outputs.results import Trajectory

    def interrupted(*args, **kwargs):
        if stop == "keyboard":
            raise KeyboardInterrupt
        empty = np.zeros((0, 1))
        raise driver.SolveInterrupted(Trajectory(np.zeros(0), empty, empty, empty, ("a.x",)),
                                      0.0)

    monkeypatch.setattr(module, "scan", interrupted)
    status = main(["scan", str(MECHANISMS / "non_grashof.yaml"), "--backend", "numpy"])
    assert status == 130
    assert "interrupted" in capsys.readouterr().err


@pytest.mark.parametrize("args", [("--dt", "0"), ("--t1", "nan"), ("--set", "zz=3"),
                                  ("--t0", "3", "--t1", "1")])
def test_cli_bad_input_exits_2_with_one_paragraph(args: tuple[str, ...]) -> None:
    result = _cli(str(MECHANISMS / "non_grashof.yaml"), "--backend", "numpy", *args)
    assert result.returncode == 2
    assert result.stdout == ""
    assert result.stderr.startswith("symkin: error:") and result.stderr.count("\n") == 1


def test_cli_a_mechanism_that_cannot_close_has_no_branches_and_exits_0() -> None:
    # d = 10 > a + b + c = 6: no assembly exists at any t.
    result = _cli(str(MECHANISMS / "non_grashof.yaml"), "--backend", "numpy", "--set", "d=10")
    assert result.returncode == 0, result.stderr
    assert "assembly branches at t = 0: 0 (none found" in result.stdout
    assert "motion from branch" not in result.stdout
