"""Generated C folders can be compiled as one translation unit, several mechanisms together.

Every symbol and macro of the generated C carries the mechanism's prefix, so a unity build
(all .c files #included into one file, as embedded projects often do) of two mechanisms side
by side compiles cleanly under the advertised flags. An unprefixed name (`#define N`, a
`typedef ... real`, a static helper) would collide and fail here.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-c"]
PAIRS = [("crank_slider", "four_bar"), ("quick_return", "all_drivers")]


@pytest.mark.parametrize("first, second", PAIRS)
def test_two_mechanisms_in_one_translation_unit(first: str, second: str, tmp_path: Path) -> None:
    compiler = shutil.which("gcc") or shutil.which("cc")
    if compiler is None:
        pytest.fail("no C compiler: CI installs gcc, and the C tests must run, not skip")
    folders = [ROOT / "generated" / name / "c" for name in (first, second)]
    sources = [source for folder in folders for source in sorted(folder.glob("*.c"))]
    assert len(sources) >= 6, sources
    unity = tmp_path / "unity.c"
    unity.write_text("".join(f'#include "{source}"\n' for source in sources), encoding="utf-8")
    includes = [f"-I{folder}" for folder in folders]
    result = subprocess.run([compiler, *FLAGS, *includes, str(unity), "-o",
                             str(tmp_path / "unity.o")], capture_output=True, text=True,
                            check=False)
    assert result.returncode == 0, result.stderr
