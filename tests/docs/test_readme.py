"""README.md is the front door: short, the two set-up commands exactly as CI runs them, and
its example works as written."""

from __future__ import annotations

import re
from pathlib import Path

from docs_support import ROOT
from test_docs_examples import run_console, run_python

README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_readme_is_short() -> None:
    assert len(README.splitlines()) <= 200


def test_setup_commands_are_the_ones_ci_runs() -> None:
    assert ("python3 -m pip install . && symkin run examples/crank_slider.yaml --backend c "
            "-o crank_slider.csv --plot crank_slider.png") in README
    assert "python3 -m pip install '.[test]' && python3 -m pytest" in README
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert "python3 -m pip install -q '.[test]'" in ci and "python3 -m pytest" in ci
    # the docs build command it gives is the one CI runs
    assert "python3 -m sphinx -W -b html docs docs/_build/html" in README
    assert "python3 -m sphinx -W -b html docs docs/_build/html" in ci


def test_readme_picture_exists() -> None:
    pictures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", README)
    assert pictures and all((ROOT / p).is_file() for p in pictures)


def test_readme_example_runs(tmp_path: Path) -> None:
    """The example file solves with the command the README gives, and its Python runs."""
    import shutil

    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    yaml_block = re.search(r"```yaml\n(.*?)```", README, re.S)
    assert yaml_block is not None
    (tmp_path / "my_four_bar.yaml").write_text(yaml_block.group(1), encoding="utf-8")
    said = re.search(r"`(symkin run my_four_bar\.yaml[^`]*)`", README)
    assert said is not None
    assert run_console(f"$ {said.group(1)}\nsolved 21 time points, t = 0 to 1\n", 0,
                       tmp_path) == []
    assert (tmp_path / "out.csv").exists() and (tmp_path / "out.png").exists()
    python = re.findall(r"```python\n(.*?)```", README, re.S)
    assert python
    run_python(python, tmp_path)
