"""The `symkin run` contract (README, "Running a mechanism"): output names, exit codes, partial results, no traceback."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, symkin_main, symkin_process, unreachable_crank_slider
from driver_support import MECHANISMS

from symkin.cli.run_outputs import ProgressBar

ROOT = Path(__file__).resolve().parents[2]
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"
COORDINATES = ["crank.x", "crank.y", "crank.phi", "rod.x", "rod.y", "rod.phi", "slider.x",
               "slider.y", "slider.phi"]


def run(*args: str, cwd: Path) -> Ran:
    return symkin_main("run", *args, cwd=cwd)


def test_npz_csv_plot_and_animation(tmp_path: Path) -> None:
    result = run(str(TEXTBOOK), "-o", "out.npz", "--plot", "out.png", "--animate", "out.gif",
                 cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # no progress bar when stderr is not a terminal
    data = np.load(tmp_path / "out.npz")
    assert sorted(data.files) == ["cond", "coordinates", "d2q", "ddr", "dq", "dr", "flagged",
                                  "points", "q", "r", "t"]
    assert data["flagged"].shape == data["cond"].shape == (31,) and not data["flagged"].any()
    assert data["t"].shape == (31,) and data["q"].shape == data["d2q"].shape == (31, 9)
    assert data["coordinates"].tolist() == COORDINATES
    assert data["points"].tolist() == ["crank.tip", "rod.P"]
    assert data["r"].shape == data["ddr"].shape == (31, 2, 2)
    # rod.P is the slider pin (b along the rod from the crank tip): r equals slider x, y
    assert np.abs(data["r"][:, 1] - data["q"][:, 6:8]).max() < 1e-12
    assert (tmp_path / "out.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "out.gif").read_bytes()[:6] == b"GIF89a"

    result = run(str(TEXTBOOK), "--backend", "c", "-o", "out.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    header = (tmp_path / "out.csv").read_text().splitlines()[0].split(",")
    point_columns = [f"{p}_{s}" for p in ("crank.tip", "rod.P")
                     for s in ("x", "y", "vx", "vy", "ax", "ay")]
    assert header == ["t", *COORDINATES, *(c + "_t" for c in COORDINATES),
                      *(c + "_tt" for c in COORDINATES), *point_columns, "flagged"]
    table = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1)
    assert np.abs(table[:, 1:10] - data["q"]).max() < 1e-12
    assert np.abs(table[:, 19:28] - data["d2q"]).max() < 1e-11


def test_grid_options(tmp_path: Path) -> None:
    result = run(str(TEXTBOOK), "--t0", "0.5", "--t1", "1", "--dt", "0.1", "-o", "g.npz",
                 cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert np.load(tmp_path / "g.npz")["t"] == pytest.approx([0.5, 0.6, 0.7, 0.8, 0.9, 1.0])


def test_failed_solve_writes_partial_results_and_exits_1(tmp_path: Path) -> None:
    result = run(str(MECHANISMS / "dead_centre.yaml"), "-o", "p.csv", "--plot", "p.png",
                 cwd=tmp_path)
    assert result.returncode == 1
    assert "t = 0.55" in result.stderr and "limit position near t = 0.5 " in result.stderr
    assert "joints[1] revolute crank-rod" in result.stderr
    assert "Solved 11 of 21 time points" in result.stderr
    table = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    assert table.shape[0] == 11 and table[-1, 0] == 0.5
    assert (tmp_path / "p.png").exists()


def test_cannot_assemble_exits_1_and_writes_an_empty_table(tmp_path: Path) -> None:
    unreachable_crank_slider(tmp_path)  # 3 bodies, 9 coordinates
    result = run("short.yaml", "-o", "s.npz", cwd=tmp_path)
    assert result.returncode == 1 and "cannot be assembled at t = 0" in result.stderr
    assert np.load(tmp_path / "s.npz")["q"].shape == (0, 9)


@pytest.mark.parametrize("args, message", [
    (["-o", "out.txt"], "must end in .npz or .csv"),
    (["--plot", "out.jpg"], "must end in .png"),
    (["--animate", "out.mp4"], "must end in .gif"),
    (["--dt", "0"], "time step must be positive"),
    (["--t0", "2", "--t1", "1"], "before it starts"),
])
def test_bad_options_exit_2(args, message, tmp_path: Path) -> None:
    result = run(str(TEXTBOOK), *args, cwd=tmp_path)
    assert result.returncode == 2 and message in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_bad_mechanism_file_exits_2(tmp_path: Path) -> None:
    """In a real process: the exit status the shell sees."""
    (tmp_path / "bad.yaml").write_text(TEXTBOOK.read_text().replace("type: angle", "type: angel"))
    result = symkin_process("run", "bad.yaml", "-o", "x.npz", cwd=tmp_path)
    assert result.returncode == 2 and "bad.yaml" in result.stderr
    assert not (tmp_path / "x.npz").exists()


def test_progress_bar_draws_and_ends_the_line() -> None:
    stream = io.StringIO()
    bar = ProgressBar(stream)
    bar(5, 10)
    bar(10, 10)
    bar.finish()
    assert "10/10" in stream.getvalue() and stream.getvalue().endswith("\n")
