"""Every ```python and ```console block of the hand-written docs pages runs as written, so
the examples cannot rot.

A page's Python blocks run in order in one namespace, in a fresh folder holding a copy of
examples/ (as a reader at the repository's root would). A console block's ``$`` lines run in
such a folder too, in bash (so ``cd dir && ...`` and redirections work as a reader types them),
``symkin`` standing for this tree's ``python -m symkin``; each must exit 0
(or the status a ``% exit: N`` line just above the block gives), and every output line the
block shows must appear in what the command printed (a line ``...`` stands for lines left out).
A line that is one plain ``symkin ...`` command (no shell syntax) runs in this process
(cli_support.symkin_main: the same main, exit status and output, without a new interpreter's
imports); any other line runs in bash."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from cli_support import Ran, symkin_main
from docs_support import DOCS, ROOT

FENCE = re.compile(r"^(?:% exit: (\d+)\n)?```(python|console)\n(.*?)^```", re.M | re.S)
SHELL = re.compile(r"[|&;<>()$`*?~\\'\"]")  # a line with any of these needs bash


def blocks(page: Path) -> list[tuple[str, str, int]]:
    """(language, code, expected exit status) of each runnable block of a page."""
    text = page.read_text(encoding="utf-8")
    return [(lang, code, int(status or 0)) for status, lang, code in FENCE.findall(text)]


def pages() -> list[Path]:
    found = [p for p in sorted(DOCS.rglob("*.md"))
             if not {"_build", "auto"} & set(p.relative_to(DOCS).parts)]
    return [p for p in found if blocks(p)]


def _reader_folder(tmp_path: Path) -> Path:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    return tmp_path


def run_console(code: str, status: int, cwd: Path) -> list[str]:
    """Run a console block; the problems found (empty when it did what it shows)."""
    problems = []
    commands = re.split(r"^\$ ", code, flags=re.M)[1:]
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    for command in commands:
        line, *shown = command.splitlines()
        words = line.split()
        if words[0] == "symkin" and not SHELL.search(line):
            done: subprocess.CompletedProcess[str] | Ran = symkin_main(
                *words[1:], cwd=cwd, env={"MPLBACKEND": "Agg"})
        else:
            script = f'symkin() {{ {shlex.quote(sys.executable)} -m symkin "$@"; }}\n{line}'
            done = subprocess.run(["bash", "-c", script], cwd=cwd, env=env, capture_output=True,
                                  text=True, timeout=900, check=False)
        printed = " ".join((done.stdout + done.stderr).split())
        if done.returncode != status:
            problems.append(f"{line}: exit {done.returncode}, not {status}: {printed[-400:]}")
        for expected in shown:
            if expected.strip() not in ("", "...") and " ".join(expected.split()) not in printed:
                problems.append(f"{line}: did not print {expected.strip()!r}")
    return problems


def run_python(codes: list[str], cwd: Path) -> None:
    namespace: dict[str, object] = {"__name__": "docs_example"}
    before = Path.cwd()
    os.chdir(cwd)
    try:
        for code in codes:
            # our own pages, run as doctest runs its examples
            exec(compile(code, "docs example", "exec"), namespace)
    finally:
        os.chdir(before)


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.relative_to(DOCS).as_posix())
def test_page_examples_run(page: Path, tmp_path: Path) -> None:
    found = blocks(page)
    python = [code for lang, code, _ in found if lang == "python"]
    if python:
        run_python(python, _reader_folder(tmp_path / "python"))
    folder = _reader_folder(tmp_path / "console")
    problems = [p for lang, code, status in found if lang == "console"
                for p in run_console(code, status, folder)]
    assert problems == []


def test_pages_with_examples_are_found() -> None:
    names = {p.relative_to(DOCS).as_posix() for p in pages()}
    assert {"getting-started.md", "guides/embedded.md", "guides/hand-check.md",
            "guides/testing.md", "guides/design.md", "reference/api.md"} <= names


@pytest.mark.parametrize("line", ["symkin run examples/four_bar.yaml --at 0",
                                  "cd . && symkin run examples/four_bar.yaml --at 0"],
                         ids=["in-process", "bash"])
def test_a_console_block_that_lies_is_caught(line: str, tmp_path: Path) -> None:
    """The harness can fail, on either path: a wrong exit status and output the command never
    prints."""
    block = f"$ {line}\nthis line is never printed\n"
    problems = run_console(block, 1, _reader_folder(tmp_path))
    assert len(problems) == 2 and "exit 0, not 1" in problems[0], problems
    assert "never printed" in problems[1]
