"""The ``symkin`` command run inside the test process, for the CLI tests.

A test of the command line wants what a user sees: the exit status, stdout and stderr. A new
``python -m symkin`` process shows that too, but costs a second or more of imports (NumPy,
SymPy) and derives the mechanism again, where :func:`symkin_main` calls the same
``symkin.cli.main`` in this process, with the arguments, working folder and environment of
the command, and hands back the same three things. An exception escaping ``main`` (what a
user would see as a traceback) fails the test as it is raised.

What only a real process shows (the ``python -m symkin`` entry, signals, closed pipes, the
exit status as the shell sees it) keeps its subprocess tests, through :func:`symkin_process`.
"""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

from symkin.cli import main

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Ran:
    """What a run of the command shows: as subprocess.CompletedProcess names it."""

    returncode: int
    stdout: str
    stderr: str


@contextlib.contextmanager
def _environment(cwd: Path, env: Mapping[str, str]) -> Iterator[None]:
    """The working folder and environment variables of one command, restored after it."""
    before = Path.cwd()
    saved = {name: os.environ.get(name) for name in env}
    os.chdir(cwd)
    os.environ.update(env)
    try:
        yield
    finally:
        os.chdir(before)
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def _fresh_warnings() -> None:
    """The warning filters of a new interpreter, each warning shown once again: a command run
    in this process says what it would say on its own."""
    warnings.resetwarnings()
    warnings.simplefilter("default")
    for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning,
                     ResourceWarning):
        warnings.simplefilter("ignore", category)


def symkin_main(*args: str, cwd: Path, env: Mapping[str, str] | None = None) -> Ran:
    """``symkin ARGS`` run in ``cwd`` with ``env`` added, in this process."""
    out, err = io.StringIO(), io.StringIO()
    with _environment(cwd, env or {}), warnings.catch_warnings(), \
            contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        _fresh_warnings()
        try:
            status = main(list(args))
        except SystemExit as stop:  # argparse: --help, --version, a bad option
            status = stop.code if isinstance(stop.code, int) else 0 if stop.code is None else 1
    return Ran(status, out.getvalue(), err.getvalue())


def ctrl_c_as_at_a_terminal() -> None:
    """Popen's preexec_fn for a child that is sent Ctrl-C: SIGINT at its default disposition,
    as a shell starts a command. An ignored SIGINT is inherited through exec, and Python then
    keeps ignoring it; in a fresh-clone CI run two such children ran to their end with exit 0
    (the test-run process they were started from had SIGINT ignored at the C level; which
    earlier test left it so was not found: none left Python's handler changed)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


def symkin_process(*args: str, cwd: Path, env: Mapping[str, str] | None = None,
                   timeout: float = 300) -> subprocess.CompletedProcess[str]:
    """``python -m symkin ARGS`` in a new process: for what only a process shows."""
    environment = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}
    result = subprocess.run([sys.executable, "-m", "symkin", *args], cwd=cwd, env=environment,
                            capture_output=True, text=True, timeout=timeout, check=False)
    assert "Traceback" not in result.stderr, result.stderr
    return result


def unreachable_crank_slider(folder: Path) -> Path:
    """``folder/short.yaml``: the textbook crank-slider with the slide's offset c = 9, beyond
    crank and rod together (a + b = 6), so it cannot be assembled at t = 0. The tests of a run
    that solves no row all write these same bytes: the first run builds the kernel, the others
    find it in the shared cache's index (symkin.build.index is keyed by the file's bytes)."""
    text = (ROOT / "examples" / "crank_slider.yaml").read_text(encoding="utf-8")
    path = folder / "short.yaml"
    path.write_text(text.replace("c: 4.0}", "c: 9.0}"), encoding="utf-8")
    return path
