"""`symkin --help` (and every subcommand's) imports none of the libraries the work needs: its
cost is Python's start plus argparse (4x `python -c pass` in instructions, from 6.3x).

Checked by what a fresh interpreter has imported after printing the help, not with a timer
(timings move with the machine's load; the list of modules does not)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

HEAVY = ("numpy", "sympy", "scipy", "cffi", "jinja2", "pydantic", "yaml", "mpmath",
         "matplotlib", "tqdm", "inspect")
"""Libraries the help must not import (inspect: what dataclasses pulls in, a fifth of the
help's own cost)."""

PROBE = """
import contextlib, io, json, sys
from symkin.cli import main
with contextlib.redirect_stdout(io.StringIO()) as out:
    try:
        main(sys.argv[1:])
    except SystemExit:
        pass
print(json.dumps({"help": out.getvalue(), "modules": sorted(sys.modules)}))
"""


@pytest.mark.parametrize("argv", [["--help"], ["run", "--help"], ["sweep", "--help"],
                                  ["scan", "--help"], ["cache", "--help"]])
def test_help_imports_no_heavy_library(argv):
    done = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout)
    assert "usage: symkin" in seen["help"]
    loaded = {name.split(".")[0] for name in seen["modules"]}
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))
