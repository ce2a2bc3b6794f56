"""The command line at the edges: a flagged point is warned about on one line and the run
exits 0 with a `flagged` column; --stop-at-singular keeps the old stop; a limit position exits
1 with the rows before it written."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from cli_support import Ran, symkin_main, unreachable_crank_slider

ROOT = Path(__file__).resolve().parents[2]
MECHANISMS = ROOT / "tests" / "mechanisms"


def run(*args: str, cwd: Path) -> Ran:
    return symkin_main("run", *args, cwd=cwd)


def test_change_point_is_warned_about_once_and_exits_0(tmp_path: Path) -> None:
    result = run(str(MECHANISMS / "parallelogram.yaml"), "--backend", "c", "-o", "out.csv",
                 cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    warnings = [line for line in result.stderr.splitlines() if "warning:" in line]
    assert len(warnings) == 1 and "at t = 0.5:" in warnings[0]
    assert "loses rank 1" in warnings[0] and "O0 revolute ground-r0 (x)" in warnings[0]
    header = (tmp_path / "out.csv").read_text().splitlines()[0].split(",")
    assert header[-1] == "flagged"
    table = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1)
    assert table.shape[0] == 21 and table[:, -1].tolist() == [float(k == 10) for k in range(21)]


def test_stop_at_singular_exits_1_with_the_rows_before(tmp_path: Path) -> None:
    result = run(str(MECHANISMS / "parallelogram.yaml"), "--stop-at-singular", "-o", "out.npz",
                 cwd=tmp_path)
    assert result.returncode == 1
    assert "Phi_q is singular at t = 0.5" in result.stderr
    data = np.load(tmp_path / "out.npz")
    assert data["t"].size == 10 and not data["flagged"].any()


def test_limit_position_exits_1_and_says_how_to_go_on(tmp_path: Path) -> None:
    result = run(str(MECHANISMS / "non_grashof.yaml"), "-o", "out.npz", cwd=tmp_path)
    assert result.returncode == 1
    assert "limit position near t = 1.82347658" in result.stderr
    assert "reversing the driver" in result.stderr
    assert np.load(tmp_path / "out.npz")["t"].size == 37


def test_a_run_that_stops_before_its_first_row_writes_the_header(tmp_path: Path) -> None:
    """The textbook crank-slider with its slide out of the reach of crank and rod (c = 9):
    no row is solved, and -o out.csv still writes the columns (was a traceback, no file)."""
    unreachable_crank_slider(tmp_path)
    result = run("short.yaml", "-o", "out.csv", cwd=tmp_path)
    assert result.returncode == 1 and "cannot be assembled" in result.stderr
    lines = (tmp_path / "out.csv").read_text().splitlines()
    assert len(lines) == 1 and lines[0].startswith("t,crank.x,") and lines[0].endswith(",flagged")


def test_a_step_of_a_non_real_argument_is_not_finite_on_both_backends(tmp_path: Path) -> None:
    """theta = t**2 + pi/2 + Heaviside(acos(w)) with --set w=2: acos(2) is not real, so the
    step's argument is NaN. NumPy's heaviside keeps the NaN; the C step did not (NaN > 0 and
    NaN < 0 are both false: it gave H = 1/2 and a motion), so the backends disagreed."""
    text = (ROOT / "examples" / "crank_slider.yaml").read_text()
    text = text.replace("c: 4.0}", "c: 4.0, w: 0.5}").replace(
        'theta: "t**2 + pi/2"', 'theta: "t**2 + pi/2 + Heaviside(acos(w))"')
    (tmp_path / "step.yaml").write_text(text)
    for backend in ("c", "numpy"):
        good = run("step.yaml", "--backend", backend, "-o", f"{backend}.csv", cwd=tmp_path)
        assert good.returncode == 0, good.stderr
        bad = run("step.yaml", "--backend", backend, "--set", "w=2", cwd=tmp_path)
        assert bad.returncode == 1, (backend, bad.stderr)
        assert "Phi in row 8 (drivers[0] angle crank-ground (angle)) is not finite at t = 0" \
            in bad.stderr
