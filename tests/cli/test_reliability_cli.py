"""The command line at its boundaries (issue: nothing lost, nothing planted): unbounded inputs,
hostile text, closed pipes, unwritable outputs and Ctrl-C, each with its exact outcome.

Each case runs the command as a user would (tests/cli_support.py): its exit status, stdout and
stderr; the closed pipe and Ctrl-C in a real ``python -m symkin`` process, the others in this
one. Every run uses the test run's shared kernel cache, which the Ctrl-C cases warm first.
"""

from __future__ import annotations

import os
import pty
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, ctrl_c_as_at_a_terminal, symkin_main, unreachable_crank_slider

ROOT = Path(__file__).resolve().parents[2]
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"


def symkin(*args: str, cwd: Path, cache: Path) -> Ran:
    return symkin_main(*args, cwd=cwd, env={"SYMKIN_CACHE_DIR": str(cache)})


@pytest.fixture
def cache(shared_cache: Path) -> Path:
    return shared_cache


@pytest.mark.parametrize("options, says", [
    (["--t0", "nan"], "--t0 nan: give a finite number"),
    (["--dt", "inf"], "--dt inf: give a finite number"),
    (["--dt", "-0.1"], "the time step must be positive"),
    (["--dt", "1e-300"], "more than the 10,000,000 allowed"),
    (["--dt", "1.5e-8"], "would need 22.4 GB"),
    (["--t0", "2"], "before it starts"),
])
def test_grid_options_are_checked_like_the_file(options: list[str], says: str, tmp_path: Path,
                                                cache: Path) -> None:
    result = symkin("run", str(TEXTBOOK), *options, cwd=tmp_path, cache=cache)
    assert result.returncode == 2, result.stderr
    assert says in result.stderr and result.stderr.count("\n") == 1


def test_an_endless_file_is_read_no_further_than_the_limit(tmp_path: Path, cache: Path) -> None:
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero on this system")
    began = time.monotonic()
    result = symkin("show", "/dev/zero", cwd=tmp_path, cache=cache)
    assert result.returncode == 2 and "larger than 1000000 bytes" in result.stderr
    assert time.monotonic() - began < 30


@pytest.mark.parametrize("suffix, text", [
    (".yaml", "name: deep\nparameters: {a: " + "[" * 400 + "1" + "]" * 400 + "}\n"),
    (".toml", "name = 'deep'\na = " + "[" * 600 + "1" + "]" * 600 + "\n"),
    (".yaml", "name: deep\nparameters: {a: " + "[" * 40 + "1" + "]" * 40 + "}\n"),
])
def test_nesting_depth_is_bounded(suffix: str, text: str, tmp_path: Path, cache: Path) -> None:
    path = tmp_path / f"deep{suffix}"
    path.write_text(text)
    result = symkin("show", str(path), cwd=tmp_path, cache=cache)
    assert result.returncode == 2
    assert "nested more than 32 deep" in result.stderr


def test_control_characters_never_reach_the_terminal(tmp_path: Path, cache: Path) -> None:
    path = tmp_path / "escape.yaml"
    path.write_text('name: esc\nparameters: {"a\\e]0;PWNED\\a\\e[2J": 1}\n'
                    "bodies: {b: {}}\ntime: {t1: 1, dt: 0.1}\n")
    result = symkin("show", str(path), cwd=tmp_path, cache=cache)
    assert result.returncode == 2
    assert "\x1b" not in result.stderr and "\x07" not in result.stderr
    assert "a\\x1b]0;PWNED\\x07\\x1b[2J" in result.stderr


def test_a_closed_pipe_ends_quietly(tmp_path: Path, cache: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "SYMKIN_CACHE_DIR": str(cache)}
    process = subprocess.Popen([sys.executable, "-m", "symkin", "schema"], cwd=tmp_path,
                               env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert process.stdout is not None and process.stderr is not None
    assert len(process.stdout.read(10)) == 10
    process.stdout.close()  # the reader goes away, as `| head -c 10` does
    stderr = process.stderr.read().decode()
    process.wait(timeout=60)
    assert "Traceback" not in stderr and "BrokenPipeError" not in stderr


def test_failed_solve_says_why_even_when_its_output_cannot_be_written(tmp_path: Path,
                                                                       cache: Path) -> None:
    short = unreachable_crank_slider(tmp_path)  # the slide's offset c beyond crank + rod
    assert "c: 9.0" in short.read_text()
    (tmp_path / "a_file").write_text("not a folder")
    result = symkin("run", str(short), "-o", str(tmp_path / "a_file" / "out.csv"),
                    cwd=tmp_path, cache=cache)
    assert result.returncode == 1
    lines = result.stderr.splitlines()
    assert "cannot be assembled" in lines[0] and "Solved 0 of 31" in lines[0]
    assert "cannot write" in lines[1]


def test_no_claim_of_written_rows_without_an_output(tmp_path: Path, cache: Path) -> None:
    short = unreachable_crank_slider(tmp_path)
    result = symkin("run", str(short), cwd=tmp_path, cache=cache)
    assert result.returncode == 1
    assert "are written" not in result.stderr and "those are" not in result.stderr


def _read_until(fd: int, marker: bytes | None, deadline: float) -> bytes:
    """What a pseudo-terminal shows until ``marker`` appears (None: until the child closes it)."""
    seen = b""
    while time.monotonic() < deadline and (marker is None or marker not in seen):
        ready, _, _ = select.select([fd], [], [], 0.5)
        if not ready:
            continue
        try:
            chunk = os.read(fd, 4096)
        except OSError:  # EIO: the child has closed its end
            break
        if not chunk:
            break
        seen += chunk
    return seen


@pytest.mark.parametrize("backend, dt", [("numpy", "1e-5"), ("c", "2e-7")])
def test_ctrl_c_writes_the_rows_solved_and_exits_130(backend: str, dt: str, tmp_path: Path,
                                                     cache: Path) -> None:
    """SIGINT mid-run: within a fraction of a second the solve stops, the rows solved so far
    are written (a consistent prefix of the grid), and the exit status is 130."""
    symkin("run", str(TEXTBOOK), "--backend", backend, cwd=tmp_path, cache=cache)  # warm
    env = {**os.environ, "PYTHONPATH": str(ROOT), "SYMKIN_CACHE_DIR": str(cache)}
    out = tmp_path / "partial.npz"
    # stderr on a pseudo-terminal: the progress bar then says when the solve has begun, so the
    # interrupt lands in the solve however slowly the interpreter starts on a loaded machine.
    terminal, child_end = pty.openpty()
    process = subprocess.Popen(
        [sys.executable, "-m", "symkin", "run", str(TEXTBOOK), "--backend", backend, "--dt", dt,
         "-o", str(out)], cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=child_end,
        text=True, preexec_fn=ctrl_c_as_at_a_terminal)
    os.close(child_end)
    try:
        seen = _read_until(terminal, b"solving", deadline=time.monotonic() + 120)
        assert process.poll() is None, "the run ended before it could be interrupted"
        process.send_signal(signal.SIGINT)
        began = time.monotonic()
        process.wait(timeout=120)
        stderr = (seen + _read_until(terminal, None, deadline=time.monotonic() + 30)).decode(errors="replace")
    finally:
        os.close(terminal)
        if process.stdout:
            process.stdout.close()
    assert process.returncode == 130, stderr
    assert "interrupted at t = " in stderr and "Traceback" not in stderr
    data = np.load(out)
    solved = data["t"].size
    assert 0 < solved < round(1.5 / float(dt)) + 1
    np.testing.assert_allclose(data["t"], float(dt) * np.arange(solved), rtol=0, atol=1e-12)
    # the last row written is a solved configuration: the crank angle follows t**2 + pi/2
    assert abs(data["q"][-1, 2] - (data["t"][-1] ** 2 + np.pi / 2)) < 1e-9
    stopped_within = time.monotonic() - began
    assert stopped_within < 60  # mostly the writing of the rows; the solve stops at once
