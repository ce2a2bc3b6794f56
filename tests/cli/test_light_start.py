"""`symkin --help`, every subcommand's help and a mistyped command cost Python's start and
argparse, nothing more: the command table (symkin.cli.SUBCOMMANDS) builds every parser from
symkin.cli.arguments and imports a command's module only when it runs; the backends' names and
flags come from the registry's written table, not from the backends.

Checked by what a fresh interpreter has imported (the list of modules does not move with the
machine's load; timings do: bench/README.md has those), against what argparse's own help
imports in the same interpreter, so that a Python whose argparse needs more still passes."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from symkin import backends
from symkin.cli import SUBCOMMANDS, _columns

ROOT = Path(__file__).resolve().parents[2]

# Every way to ask for usage: each command's help, none, a mistyped command or option, a
# missing argument, a bad choice (--version is left out: it reads the package's metadata; and
# a path given on the line is a Path, which imports pathlib, as the command will anyway).
ARGVS = [["--help"], [], ["runn"], ["--nope"], ["run"], ["run", "--backend", "fortran"],
         ["cache", "bogus"], ["generate", "--real", "float"],
         *([name, "--help"] for name, *_ in SUBCOMMANDS)]

LIGHT_SYMKIN = {"symkin", "symkin.errors", "symkin.backends", "symkin.cli",
                "symkin.cli.arguments", "symkin.cli.overrides", "symkin.cli.messages",
                "symkin.cli.exits"}
"""symkin's modules the parser needs: the registry, not a backend; no command's module."""

OWN_NEEDS = {"__future__", "collections.abc", "unicodedata", "warnings"}
"""What those modules import that argparse's help may not: each costs under 0.3 ms."""

PROBE = """
import contextlib, io, json, sys
before = set(sys.modules)
{run}
print(json.dumps(sorted(set(sys.modules) - before)))
"""

SYMKIN = """
from symkin.cli import main
for argv in json.loads(sys.argv[1]):
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        try:
            main(argv)
        except SystemExit:
            pass
"""

ARGPARSE = """
import argparse
def formatter(prog):  # its width given, as symkin.cli gives it, so that it needs no shutil
    return argparse.HelpFormatter(prog, width=78)
parser = argparse.ArgumentParser(prog="p", formatter_class=formatter)
commands = parser.add_subparsers(dest="command", required=True)
commands.add_parser("c", formatter_class=formatter).add_argument("x")
for argv in (["--help"], [], ["c", "--help"]):
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        try:
            parser.parse_args(argv)
        except SystemExit:
            pass
"""


def _imported(run: str, *arguments: str) -> set[str]:
    """The modules a fresh interpreter imports running ``run`` (its probe's own left out);
    without the site module, whose .pth files (an editable install's finder) import pathlib
    and more before the probe starts, which a user's installed symkin does not."""
    done = subprocess.run([sys.executable, "-S", "-c", PROBE.format(run=run), *arguments],
                          capture_output=True, text=True, cwd=ROOT, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    return set(json.loads(done.stdout))


def test_asking_for_usage_imports_only_the_parser_and_argparse() -> None:
    imported = _imported(SYMKIN, json.dumps(ARGVS))
    ours = {name for name in imported if name.split(".")[0] == "symkin"}
    assert ours <= LIGHT_SYMKIN, sorted(ours - LIGHT_SYMKIN)
    beyond = {name for name in imported - ours if not name.startswith("_")}
    beyond -= _imported(ARGPARSE) | OWN_NEEDS
    assert not beyond, f"the help imports more than argparse's own: {sorted(beyond)}"


def test_every_usage_is_said_as_before() -> None:
    """The parsers built from the table: the top-level help lists every command with its line,
    a mistyped command is refused with exit 2, and each command's help has its options."""
    done = subprocess.run([sys.executable, "-m", "symkin", "--help"], capture_output=True,
                          text=True, cwd=ROOT, timeout=120, env={**os.environ, "COLUMNS": "200"})
    assert done.returncode == 0 and not done.stderr
    for name, summary, *_ in SUBCOMMANDS:
        assert f"    {name}" in done.stdout and summary in done.stdout
    mistyped = subprocess.run([sys.executable, "-m", "symkin", "runn"], capture_output=True,
                              text=True, cwd=ROOT, timeout=120)
    assert mistyped.returncode == 2 and not mistyped.stdout
    assert "invalid choice: 'runn'" in mistyped.stderr and "Traceback" not in mistyped.stderr


@pytest.mark.parametrize("columns", [None, "", "abc", "-3", "0", "57", "200"])
def test_the_help_is_as_wide_as_argparse_makes_it(monkeypatch: pytest.MonkeyPatch,
                                                  columns: str | None) -> None:
    if columns is None:
        monkeypatch.delenv("COLUMNS", raising=False)
    else:
        monkeypatch.setenv("COLUMNS", columns)
    assert _columns() == shutil.get_terminal_size().columns


def test_the_written_backends_are_the_backends() -> None:
    """The registry's table (names in order of preference, modules, options) as the backends
    themselves declare them: the CLI's --backend choices and generate's flags come from it."""
    for name, module, options in backends._BUILT_IN:
        backend = backends.get(name)
        assert backend.name == name and type(backend).__module__ == module
        assert tuple(backend.options) == options, name
    merged: dict[str, tuple[str, ...]] = {}  # every declaring backend's choices, in order
    for backend in map(backends.get, backends.names()):
        for option in backend.options:
            known = merged.setdefault(option.name, ())
            merged[option.name] = known + tuple(c for c in option.choices if c not in known)
    assert [(flag[0], flag[1]) for flag in backends.declared_flags()] == list(merged.items())
    assert backends.declared_flags()[:2] == backends.get("c").options  # help and default: C's
