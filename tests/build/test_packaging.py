"""The package installs with a plain (non-editable) `pip install .` and works from any folder.

The install goes into a fresh virtual environment built from the running interpreter: it sees
the running interpreter's site-packages (pip, setuptools, wheel and symkin's dependencies)
through a .pth file, so no download is needed and nothing comes from the base interpreter,
also when the tests themselves run in a virtualenv. The package is installed without its
dependencies: what is checked is the wheel's own content — modules, templates and the console
script.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


_NEVER_COPIED = shutil.ignore_patterns(".git", "__pycache__", "*.egg-info", ".pytest_cache",
                                       ".hypothesis", ".mypy_cache", ".ruff_cache")


def _not_sources(folder: str, names: list[str]) -> set[str]:
    """Caches and a top-level setuptools ``build/`` are left out; ``symkin/build`` (the build
    stage of the package) is not."""
    skipped = set(_NEVER_COPIED(folder, names))
    if Path(folder) == ROOT and "build" in names:
        skipped.add("build")
    return skipped


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A venv with symkin installed from a copy of the source tree; returns its bin folder."""
    work = tmp_path_factory.mktemp("packaging")
    source = work / "source"
    shutil.copytree(ROOT, source, ignore=_not_sources)
    env_dir = work / "venv"
    # No ensurepip: the running interpreter's pip is used through the .pth file below.
    venv.create(env_dir, system_site_packages=False, with_pip=False)
    bin_dir = env_dir / "bin"
    # The running interpreter's packages (itself maybe a virtualenv, whose base interpreter
    # lacks them), seen through a .pth file: dependencies and build tools without a download.
    inner = subprocess.run([str(bin_dir / "python"), "-c",
                            "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                           capture_output=True, text=True, check=True).stdout.strip()
    outer = {sysconfig.get_paths()[key] for key in ("purelib", "platlib")}
    Path(inner, "outer-site-packages.pth").write_text(
        "".join(f"{path}\n" for path in sorted(outer)), encoding="utf-8")
    subprocess.run([str(bin_dir / "python"), "-m", "pip", "install", "-q", "--no-deps",
                    "--no-build-isolation", str(source)], check=True, cwd=work)
    return bin_dir


@pytest.mark.slow
def test_console_script_runs_from_any_folder(installed: Path, tmp_path: Path) -> None:
    mechanism = tmp_path / "mech.yaml"
    shutil.copy(ROOT / "examples" / "crank_slider.yaml", mechanism)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    result = subprocess.run([str(installed / "symkin"), "show", str(mechanism)], cwd=tmp_path,
                            capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stderr
    assert "1 degree(s) of freedom" in result.stdout


@pytest.mark.slow
def test_templates_ship_inside_the_package(installed: Path, tmp_path: Path) -> None:
    """Each backend's templates ship in its own folder of the installed package."""
    code = ("import symkin, pathlib; root = pathlib.Path(symkin.__file__).parent; "
            "print(root); print(sorted(p.relative_to(root).as_posix() "
            "for p in root.rglob('*.j2')))")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    result = subprocess.run([str(installed / "python"), "-c", code], cwd=tmp_path,
                            capture_output=True, text=True, env=env, check=True)
    root, listing = result.stdout.splitlines()
    assert "site-packages" in root
    expected = sorted(p.relative_to(ROOT / "symkin").as_posix() for p in
                      (ROOT / "symkin").rglob("*.j2"))
    assert {p.split("/")[1] for p in expected} == {"c", "numpy", "octave"}
    assert listing == repr(expected)
    assert sys.version_info >= (3, 11)


@pytest.mark.slow
def test_installed_version_comes_from_the_package_metadata(installed: Path,
                                                           tmp_path: Path) -> None:
    import tomllib

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    shown = subprocess.run([str(installed / "symkin"), "--version"], cwd=tmp_path, env=env,
                           capture_output=True, text=True, check=True).stdout.strip()
    assert shown == f"symkin {declared}"
    code = ("import symkin, importlib.metadata as m; "
            "print(symkin.__version__, m.version('symkin'), symkin.__file__)")
    version, metadata, where = subprocess.run(
        [str(installed / "python"), "-c", code], cwd=tmp_path, env=env, capture_output=True,
        text=True, check=True).stdout.split()
    assert version == metadata == declared and "site-packages" in where
