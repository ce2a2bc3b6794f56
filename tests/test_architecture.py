"""The package's layering holds: the import-linter contracts of pyproject.toml are kept, the
package is ruff-clean and mypy --strict clean (settings in pyproject.toml), and no module grows
past the size one reader can hold at once."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MAX_MODULE_LINES = 450  # one reader holds a module at once


def test_import_contracts_are_kept() -> None:
    result = subprocess.run(
        [sys.executable, "-c", "import sys; from importlinter.cli import lint_imports_command; "
         "sys.exit(lint_imports_command())"],
        cwd=ROOT, capture_output=True, text=True, env={"PYTHONPATH": str(ROOT), "PATH": ""},
        check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


def test_no_module_is_too_long() -> None:
    """Modules and templates alike (a template splits into partials: {% include %} of a
    ``_name.j2`` file, which renders to no file of its own)."""
    paths = [*(ROOT / "symkin").rglob("*.py"), *(ROOT / "symkin").rglob("*.j2")]
    long = {str(path.relative_to(ROOT)): n for path in paths
            if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES}
    assert not long, f"split these modules: {long}"


def test_partial_templates_are_included_not_rendered() -> None:
    import symkin
    from symkin import backends
    from symkin.codegen import lower, render

    derived = symkin.derive(ROOT / "examples" / "crank_slider.yaml")
    for name in backends.names():
        for option in backends.get(name).options:
            for value in option.choices:
                code = lower.lower(derived, backends.get(name), {option.name: value})
                rendered = render.template_names(code)
                assert rendered and not [name for name in rendered if name.startswith("_")]
        # each backend's templates live in its own folder and include each other there
        root = backends.get(name).template_root
        folder = root / backends.get(name).template_folder
        sources = "".join(path.read_text(encoding="utf-8") for path in folder.rglob("*.j2"))
        for partial in folder.rglob("_*.j2"):
            included = partial.relative_to(root).as_posix()
            used = (f'{{% include "{included}" %}}' in sources  # a partial, or a macro file
                    or f'{{% from "{included}" import' in sources)
            assert used, f"{partial} is included nowhere"


def _tool(module: str, *arguments: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", module, *arguments], cwd=ROOT,
                          capture_output=True, text=True, check=False)


def test_package_is_ruff_clean() -> None:
    result = _tool("ruff", "check", "--no-cache", "symkin")
    assert result.returncode == 0, result.stdout + result.stderr


def test_package_is_mypy_strict_clean() -> None:
    result = _tool("mypy", "--no-incremental")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Success" in result.stdout


def test_every_subpackage_ships_in_the_wheel() -> None:
    """pyproject finds the packages (a new backend's folder is not named there): every folder
    of modules must then be a package, or it would be missing from an installed symkin."""
    import tomllib

    from setuptools import find_packages

    found = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    shipped = set(find_packages(str(ROOT), include=found["packages"]["find"]["include"]))
    folders = {".".join(module.parent.relative_to(ROOT).parts)
               for module in (ROOT / "symkin").rglob("*.py")
               if "templates" not in module.parts}
    assert folders <= shipped, f"add an __init__.py to: {sorted(folders - shipped)}"


def test_architecture_names_every_module() -> None:
    """ARCHITECTURE.md is the map of the package: each module appears in it by name."""
    import re

    text = (ROOT / "ARCHITECTURE.md").read_text(encoding="utf-8")
    missing = [str(path.relative_to(ROOT)) for path in (ROOT / "symkin").rglob("*.py")
               if path.stem not in ("__init__", "__main__")
               and not re.search(rf"\b{re.escape(path.stem)}\b", text)]
    assert not missing, f"describe these modules in ARCHITECTURE.md: {missing}"
