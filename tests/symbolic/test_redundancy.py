"""Redundant constraints: the rows of an over-constrained file that depend on the others at the
assembled t0 are found, named, removed for the run and checked along the motion.

References are derived here by hand: the parallelogram's closed form (the coupler translates,
every bar turns by the crank angle), the row count of a linkage whose true mobility is known
from its geometry, and for a slightly wrong extra bar the residual its removed row must show
(the bar's angle from the row that was kept, by an arccos).
"""

from __future__ import annotations

import copy
import functools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from codegen_support import compiled, derived

import symkin
from symkin import cli
from symkin.errors import MechanismError
from symkin.runtime.outputs import redundant
from symkin.spec.validate import from_dict

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "parallelogram_extra_bar.yaml"
BACKENDS = ["numpy", "c"]
A, D, E, TH0 = 1.0, 1.0, 0.5, math.pi / 3  # the example's parameters
REMOVED = "joints[5] C revolute extra-coupler (y)"


def _document() -> dict[str, Any]:
    return yaml.safe_load(EXAMPLE.read_text())


def _closed_form(t: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(q, dq, ddq) of the coordinates the parallelogram fixes: theta = pi/2 t turns the
    crank, the rocker and the extra bar alike about their ground pivots; the coupler, framed
    at A, translates with A = a (cos(th0 + theta), sin(th0 + theta))."""
    w = math.pi / 2
    angle = TH0 + w * t
    zero = np.zeros_like(t)
    turn = (w * t, np.full_like(t, w), zero)
    return {
        "crank.phi": turn, "rocker.phi": turn, "extra.phi": turn,
        "coupler.phi": (zero, zero, zero),
        "coupler.x": (A * np.cos(angle), -A * w * np.sin(angle), -A * w * w * np.cos(angle)),
        "coupler.y": (A * np.sin(angle), A * w * np.cos(angle), -A * w * w * np.sin(angle)),
        "rocker.x": (np.full_like(t, D), zero, zero), "extra.x": (np.full_like(t, E), zero, zero),
    }


# ----- what is removed ---------------------------------------------------------------------

def test_parallelogram_with_an_extra_bar_loses_exactly_its_one_dependent_row() -> None:
    """13 equations (6 revolutes, 1 driver) on 12 coordinates; the linkage really moves with
    one freedom the driver fixes, so the rank is 12: one row removed, the last joint row."""
    system = derived(EXAMPLE)
    assert len(system.q) == 12 and len(system.rows) == 12
    assert system.phi_q.shape == (12, 12)
    assert [str(r) for r in system.removed] == [REMOVED]
    assert system.removed[0].index == 11  # its place among the 13 rows written
    assert system.rows[-1].section == "drivers"  # the driver is kept
    assert REMOVED not in [str(r) for r in system.rows]
    # Grübler says 0; the joints' rows have rank 11 on 12 coordinates: it moves, with 1.
    assert system.dof == 0 and system.mobility == 1


def test_a_square_file_is_untouched() -> None:
    system = derived(ROOT / "examples" / "four_bar.yaml")
    assert system.removed == () and system.mobility is None


def test_joint_rows_are_removed_before_driver_rows() -> None:
    """A pendulum driven twice, consistently (angle t, tip on (cos t, sin t)): 5 rows on 3
    coordinates; the drivers' 3 rows are kept and the revolute's 2 removed."""
    system = derived(ROOT / "tests" / "mechanisms" / "pendulum_two_drivers.yaml")
    assert [r.section for r in system.rows] == ["drivers"] * 3
    assert [str(r) for r in system.removed] == ["joints[0] revolute ground-crank (x)",
                                                "joints[0] revolute ground-crank (y)"]


def test_a_drawing_rounded_to_17_digits_removes_the_same_row() -> None:
    """Every coordinate written as a 17-digit decimal instead of an expression: the rounding
    (1e-17) is far below the rank tolerance, so the same row is found dependent."""
    c, s = A * math.cos(TH0), A * math.sin(TH0)
    drawn = {"O0": (0.0, 0.0), "O1": (D, 0.0), "O2": (E, 0.0), "A": (c, s), "B": (D + c, s),
             "C": (E + c, s)}
    document = _document()
    document["parameters"] = {}
    for body in document["bodies"].values():
        body["points"] = {name: [f"{v:.17g}" for v in drawn[name]] for name in body["points"]}
    system = symkin.derive(from_dict(document))
    assert [str(r) for r in system.removed] == [REMOVED]
    kernel = symkin.compile(system, backend="numpy")
    trajectory = symkin.solve(kernel)
    assert not trajectory.flagged.any()
    assert np.abs(trajectory.removed_residual).max() < 1e-12
    k = trajectory.coordinates.index("coupler.x")
    np.testing.assert_allclose(trajectory.q[:, k], _closed_form(trajectory.t)["coupler.x"][0],
                               atol=1e-9)


# ----- the motion --------------------------------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
def test_parallelogram_motion_matches_its_closed_form(backend: str) -> None:
    kernel = compiled(EXAMPLE, backend)
    assert kernel.removed == (REMOVED,)
    trajectory = symkin.solve(kernel)
    expected = _closed_form(trajectory.t)
    for name, (q, dq, ddq) in expected.items():
        k = trajectory.coordinates.index(name)
        np.testing.assert_allclose(trajectory.q[:, k], q, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(trajectory.dq[:, k], dq, atol=1e-8, err_msg=name)
        np.testing.assert_allclose(trajectory.d2q[:, k], ddq, atol=1e-6, err_msg=name)
    assert trajectory.removed == (REMOVED,)
    assert trajectory.removed_residual.shape == (trajectory.t.size, 1)
    assert np.abs(trajectory.removed_residual).max() < 1e-12
    assert not trajectory.flagged.any()


def test_the_c_kernel_runs_the_generated_removed_routine() -> None:
    """The compiled C routine against the removed row written out by hand: the y of C on the
    extra bar minus the y of C on the coupler, at random states."""
    kernel = compiled(EXAMPLE, "c")
    assert hasattr(kernel.lib, "parallelogram_extra_bar_removed")
    rng = np.random.default_rng(3)
    names = kernel.coordinates
    for _ in range(20):
        q = rng.normal(size=len(names))
        value = dict(zip(names, q))
        local = A * math.sin(TH0)  # C in the extra bar's frame at O2: (a cos th0, a sin th0)
        extra_c = value["extra.y"] + A * math.cos(TH0) * math.sin(value["extra.phi"]) \
            + local * math.cos(value["extra.phi"])
        # C in the coupler's frame at A: (e, 0)
        coupler_c = value["coupler.y"] + E * math.sin(value["coupler.phi"])
        np.testing.assert_allclose(kernel.removed_phi(q, 0.3), [extra_c - coupler_c],
                                   rtol=1e-13, atol=1e-13)


# ----- a removed row that does not hold ----------------------------------------------------

def _wrong_bar(delta: float) -> dict[str, Any]:
    """The extra bar drawn 'delta' longer along x at its top: still an assembled drawing at
    t0, but no longer parallel, so the linkage with it would be rigid."""
    document = copy.deepcopy(_document())
    moved = ["e + a*cos(th0) + delta", "a*sin(th0)"]
    document["parameters"]["delta"] = delta
    document["bodies"]["extra"]["points"]["C"] = moved
    document["bodies"]["coupler"]["points"]["C"] = list(moved)
    return document


@functools.cache
def _wrong_bar_system(delta: float) -> symkin.System:
    """_wrong_bar(delta) derived once for both backends."""
    return symkin.derive(from_dict(_wrong_bar(delta)))


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_slightly_wrong_extra_bar_assembles_and_is_flagged_along_the_motion(
        backend: str) -> None:
    """delta = 1e-3: the drawing is consistent at t0, so the assembly passes and the same row
    is removed; along the motion the kept rows move the parallelogram, and the removed row's
    residual is what the extra bar's kept x-row leaves in y (derived here): flags raised."""
    system = _wrong_bar_system(1e-3)
    assert [str(r) for r in system.removed] == [REMOVED]
    assert system.mobility == 0  # the joints alone leave nothing for the driver: rigid
    trajectory = symkin.solve(symkin.compile(system, backend=backend))
    residual = trajectory.removed_residual[:, 0]
    assert abs(residual[0]) < 1e-12 and not trajectory.flagged[0]
    assert trajectory.flagged[1:].all()
    assert redundant.violated(trajectory, 1e-8) == (REMOVED,)
    # The reference: the coupler's C is the parallelogram's; the extra bar (length L, drawn at
    # angle alpha0) turns so that its top's x matches; its y then misses by the residual.
    cx = E + 1e-3 + A * np.cos(TH0 + math.pi / 2 * trajectory.t)
    cy = A * np.sin(TH0 + math.pi / 2 * trajectory.t)
    top = np.array([A * math.cos(TH0) + 1e-3, A * math.sin(TH0)])
    length, alpha0 = float(np.hypot(*top)), math.atan2(top[1], top[0])
    alpha = np.arccos((cx - E) / length)  # the branch above the ground, as drawn
    assert alpha0 < math.pi / 2
    np.testing.assert_allclose(residual, length * np.sin(alpha) - cy, atol=1e-9)
    assert np.abs(residual).max() > 1e-4


def test_cli_run_notes_the_removed_row_and_warns_where_it_breaks(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "wrong_bar.yaml"
    path.write_text(yaml.safe_dump(_wrong_bar(1e-3)))
    out = tmp_path / "run.npz"
    assert cli.main(["run", str(path), "--backend", "numpy", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "1 equation removed as redundant" in err and REMOVED in err
    assert "do not hold there" in err and "|Phi| up to" in err
    saved = np.load(out)
    assert saved["flagged"][1:].all()
    assert saved["removed"].tolist() == [REMOVED]
    assert saved["removed_residual"].shape == (saved["t"].size, 1)
    assert abs(saved["removed_residual"][-1, 0]) > 1e-4


def test_cli_run_of_the_example_notes_and_does_not_warn(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["run", str(EXAMPLE), "--backend", "c", "-o",
                     str(tmp_path / "r.csv")]) == 0
    err = capsys.readouterr().err
    assert REMOVED in err and "warning" not in err


def test_cli_show_says_which_row_is_removed_and_why(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["show", str(EXAMPLE)]) == 0
    out = capsys.readouterr().out
    assert "removed as redundant (13 equations for 12 coordinates" in out
    assert "rank 12" in out and REMOVED in out
    assert "degrees of freedom: 0 by the count, 1 by the rank of the joints' rows at t0" in out


def test_nan_residual_counts_as_broken() -> None:
    residual = np.array([[0.0], [math.nan], [1e-12]])
    q = np.ones((3, 2))
    assert redundant.exceeded(residual, q, 1e-8)[:, 0].tolist() == [False, True, False]


# ----- refused ------------------------------------------------------------------------------

def _pendulum(theta: str, twice: bool = False, drivers: bool = True) -> dict[str, Any]:
    joint = {"type": "revolute", "i": "ground", "j": "crank", "sA": [0, 0], "sB": [0, 0]}
    return {
        "name": "pendulum", "parameters": {"a": 1.0},
        "bodies": {"crank": {"q0": [0, 0, 0], "points": {"tip": ["a", 0]}}},
        "joints": [joint, copy.deepcopy(joint)] if twice else [joint],
        "drivers": [{"type": "angle", "i": "crank", "j": "ground", "theta": theta},
                    {"type": "trajectory", "j": "crank", "sB": "tip",
                     "f": ["cos(t)", "sin(t)"]}] if drivers else [],
        "time": {"t0": 0, "t1": 1, "dt": 0.1},
    }


def test_contradicting_equations_are_refused_with_the_row_named() -> None:
    """The angle driver says 0.5 rad at t0, the trajectory driver 0: no assembly."""
    with pytest.raises(MechanismError) as caught:
        symkin.derive(from_dict(_pendulum("t + 0.5")))
    message = str(caught.value)
    assert "over-constrained: the equations cannot all hold at t0" in message
    assert "max |Phi| = " in message and caught.value.path[0] in ("joints", "drivers")


def test_cli_refuses_contradicting_equations_located_exit_2(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "contradiction.yaml"
    path.write_text(yaml.safe_dump(_pendulum("t + 0.5"), sort_keys=False))
    for command in (["show"], ["run", "--backend", "numpy"]):
        assert cli.main([*command, str(path)]) == cli.EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert err.startswith(f"symkin: error: {path}:"), err
        line = int(err.split(f"{path}:")[1].split(":")[0])
        assert line > 1 and "cannot all hold at t0" in err
        assert "Traceback" not in err and err.count("\n") == 1


def test_a_freedom_no_driver_fixes_is_refused() -> None:
    """The revolute written twice and no driver: 4 rows on 3 coordinates, rank 2 at t0 and
    nearby: the pendulum's swing is free."""
    with pytest.raises(MechanismError) as caught:
        symkin.derive(from_dict(_pendulum("t", twice=True, drivers=False)))
    assert "keeps 1 freedom(s) no driver fixes" in str(caught.value)


def test_a_singular_t0_is_told_apart_from_a_free_mechanism() -> None:
    """The example drawn at its change point (th0 = 0: every bar on the x axis): the rank at
    t0 is 11, but 12 at a configuration assembled nearby."""
    document = _document()
    document["parameters"]["th0"] = 0
    with pytest.raises(MechanismError) as caught:
        symkin.derive(from_dict(document))
    message = str(caught.value)
    assert "t0 is a singular configuration" in message and "rank 11" in message


def test_the_dependent_row_is_found_among_the_rows_not_just_the_last() -> None:
    """A driven pendulum listed after the parallelogram: 16 rows on 15 coordinates. The row
    that depends on the others is the extra bar's (its component outside the kept rows' span
    is roundoff, far below the tolerance); the pendulum's rows, written last, all stay."""
    document = _document()
    document["bodies"]["ground"]["points"]["P0"] = [3, 0]
    document["bodies"]["pendulum"] = {"points": {"P0": [3, 0], "P1": [4, 0]}}
    document["joints"].append({"type": "revolute", "name": "P", "i": "ground",
                               "j": "pendulum", "at": "P0"})
    document["drivers"].append({"type": "angle", "name": "swing", "i": "pendulum",
                                "j": "ground", "theta": "t"})
    system = symkin.derive(from_dict(document))
    assert len(system.q) == 15
    assert [str(r) for r in system.removed] == [REMOVED]
    assert system.removed[0].dependency < 1e-12
    assert [str(r) for r in system.rows][-4:-2] == ["joints[6] P revolute ground-pendulum (x)",
                                                    "joints[6] P revolute ground-pendulum (y)"]


@pytest.mark.parametrize(("error", "dependent"), [(0.0, True), (1e-16, True), (1e-12, True),
                                                  (1e-6, False)])
def test_the_rank_tolerance_sits_between_roundoff_and_a_real_difference(
        error: float, dependent: bool) -> None:
    """A row equal to the sum of two others up to ``error`` (what rounding a drawing to 17
    digits, or an assembly to 1e-13, leaves) counts as dependent; 1e-6 off it does not. The
    columns differ by 1e6 in scale (millimetres against radians): equilibration hides that."""
    from symkin.symbolic import redundancy

    rng = np.random.default_rng(7)
    rows = rng.normal(size=(3, 4))
    extra = rows[0] + rows[1] + error * rng.normal(size=4)
    jacobian = np.vstack([rows, extra]) * np.array([1e3, 1e3, 1e-3, 1.0])
    scaled = redundancy.equilibrate(jacobian)
    kept, outside = redundancy.ordered_selection(scaled, [0, 1, 2, 3])
    assert (kept == [0, 1, 2]) is dependent
    assert redundancy.numerical_rank(scaled) == (3 if dependent else 4)
    assert (outside[3] < redundancy.RANK_TOLERANCE) is dependent


def test_a_warm_run_from_the_cache_still_knows_the_removed_rows(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The second run loads the kernel through the warm-run index (no derivation): the
    manifest's ``removed`` key carries the rows, so the note and the check remain."""
    for backend in BACKENDS:
        for _ in range(2):
            out = tmp_path / f"{backend}.npz"
            assert cli.main(["run", str(EXAMPLE), "--backend", backend, "-o", str(out)]) == 0
            captured = capsys.readouterr()
            assert REMOVED in captured.err
            assert np.load(out)["removed"].tolist() == [REMOVED]
        assert "cached kernel" in captured.out


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_sweep_says_which_sets_break_the_removed_row(backend: str) -> None:
    """The extra bar's error as a parameter, nominal 0 (the row removed is found there): the
    set with delta = 1e-3 breaks it along the motion, the exact ones do not."""
    system = _wrong_bar_system(0.0)
    kernel = symkin.compile(system, backend=backend)
    result = symkin.sweep(kernel, {"delta": [0.0, 1e-3, 0.0]}, workers=1)
    assert result.ok.all()
    assert result.removed == (REMOVED,)
    assert result.removed_broken.tolist() == [False, True, False]


def test_millimetres_and_a_point_and_joint_named_e_change_nothing() -> None:
    """The example 1000 times larger, with its point C and joint C named E (SymPy's constant's
    name): the equilibrated rank and the assembly tolerance scale with the drawing."""
    document = _document()
    document["parameters"].update(a=1000.0, d=1000.0, e=500.0)
    for body in ("extra", "coupler"):
        points = document["bodies"][body]["points"]
        points["E"] = points.pop("C")
    document["joints"][5].update(name="E", at="E")
    system = symkin.derive(from_dict(document))
    assert [str(r) for r in system.removed] == [REMOVED.replace(" C ", " E ")]
    assert system.mobility == 1
    trajectory = symkin.solve(symkin.compile(system, backend="numpy"))
    # (the condition-based flags of a millimetre drawing are the plain parallelogram's own:
    # only the removed row's check is asked about here)
    assert not redundant.exceeded(trajectory.removed_residual, trajectory.q, 1e-8).any()
    k = trajectory.coordinates.index("coupler.x")
    np.testing.assert_allclose(trajectory.q[:, k], 1000 * _closed_form(trajectory.t)[
        "coupler.x"][0], atol=1e-9 * 1000)


def test_scan_lists_only_assemblies_that_keep_the_removed_row() -> None:
    """With the crank pinned at t0, the parallelogram's rocker has two places (parallel or
    crossed); the extra bar fits only the parallel one, and the bar's own mirror image meets
    C's x but not its y. So the file has exactly one assembly at t0."""
    from symkin.runtime.scanning.scan import scan

    kernel = compiled(EXAMPLE, "numpy")
    report = scan(kernel, t=np.array([0.0, 0.01]))
    assert len(report.branches) == 1 and report.branches[0].taken
    k = kernel.coordinates.index("coupler.phi")
    assert abs(report.branches[0].q[k]) < 1e-9
