"""The kernel cache and generated folders under attack and accident (issue: nothing lost,
nothing planted): planted and damaged kernels, unusable cache folders, killed and concurrent
builds, and output folders that hold other people's files — each with its exact outcome."""

from __future__ import annotations

import functools
import json
import multiprocessing
import os
import pickle
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled, derived

import symkin
from symkin import backends, cli
from symkin.build import cache as build_cache
from symkin.errors import SymkinWarning, UsageError

ROOT = Path(__file__).resolve().parents[2]
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"


@functools.cache
def _reference() -> np.ndarray:
    """q over the textbook file's grid, from its NumPy kernel (built once per run, from the
    goldens: codegen_support.compiled)."""
    return symkin.solve(compiled(TEXTBOOK, "numpy")).q


def _kernel_folder(cache: Path, backend: str) -> Path:
    found = [p for p in cache.iterdir() if p.name.startswith("_symkin_crank_slider_")
             and ("_py_" in p.name) == (backend == "numpy")]
    assert len(found) == 1, found
    return found[0]


@pytest.fixture
def system() -> symkin.System:
    """The textbook crank-slider's System, derived once per run (plain data: the tests here
    compile and generate from it, never change it)."""
    return derived(TEXTBOOK)


def test_a_planted_numpy_kernel_is_never_executed(system: symkin.System, tmp_path: Path) -> None:
    """Someone knows the (predictable) folder name of a kernel and puts a module there first:
    it is moved aside and rebuilt, never imported."""
    first = tmp_path / "first"
    symkin.compile(system, backend="numpy", cache_dir=first)
    name = _kernel_folder(first, "numpy").name
    victim = tmp_path / "victim"
    planted = victim / name
    planted.mkdir(parents=True)
    marker = tmp_path / "PLANTED"
    (planted / "crank_slider.py").write_text(f"open({str(marker)!r}, 'w').write('x')\n")
    (planted / "crank_slider_manifest.json").write_text("{}")
    kernel = symkin.compile(system, backend="numpy", cache_dir=victim)
    assert not marker.exists()
    np.testing.assert_allclose(symkin.solve(kernel).q, _reference(), atol=1e-12)


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A cache holding the textbook's C and NumPy kernels, built once for this module: each
    damage test damages its own copy of a kernel folder (new files, so this process, which has
    the originals loaded, never maps what a test rewrites)."""
    cache = tmp_path_factory.mktemp("built")
    for backend in ("c", "numpy"):
        symkin.compile(derived(TEXTBOOK), backend=backend, cache_dir=cache)
    return cache


@pytest.mark.parametrize("damage", ["truncate", "random", "edit"])
@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_a_damaged_kernel_is_rebuilt_not_loaded(damage: str, backend: str, built: Path,
                                                system: symkin.System, tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    cache.mkdir(mode=0o700)
    shutil.copytree(_kernel_folder(built, backend), cache / _kernel_folder(built, backend).name)
    # Loaded and run in another process, as a user's next run would be (an extension module
    # this process imported would be found by name instead of the rebuilt one). It loads this
    # run's System, pickled (a System pickles faithfully), instead of deriving it again.
    pickled = tmp_path / "system.pickle"
    pickled.write_bytes(pickle.dumps(system))
    code = (f"import pickle, symkin; s = pickle.loads(open({str(pickled)!r}, 'rb').read()); "
            f"k = symkin.compile(s, backend={backend!r}, cache_dir={str(cache)!r}); "
            "print(k.backend, float(symkin.solve(k).q[-1, 6]))")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    folder = _kernel_folder(cache, backend)
    target = next(p for p in folder.iterdir()
                  if p.name.endswith(".so" if backend == "c" else "crank_slider.py"))
    data = target.read_bytes()
    if damage == "truncate":
        target.write_bytes(data[:1000])
    elif damage == "random":
        target.write_bytes(np.random.default_rng(1).bytes(len(data)))
    else:
        target.write_bytes(data + b"\nraise SystemExit('edited')\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env=env, timeout=300)
    assert result.returncode == 0, result.stderr
    loaded, slider_x = result.stdout.split()
    assert loaded == backend
    assert abs(float(slider_x) - _reference()[-1, 6]) < 1e-12
    assert target.read_bytes() != data[:1000] and b"edited" not in target.read_bytes()


def test_a_cache_others_can_write_is_not_used(system: symkin.System, tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o1777)
    with pytest.warns(SymkinWarning, match="others may write to it"):
        kernel = symkin.compile(system, backend="numpy", cache_dir=shared)
    assert list(shared.iterdir()) == []
    assert kernel.folder is not None and shared not in kernel.folder.parents


@pytest.mark.parametrize("how", ["read-only", "a file"])
def test_an_unusable_cache_folder_falls_back_with_one_note(how: str, tmp_path: Path) -> None:
    if hasattr(os, "geteuid") and os.geteuid() == 0 and how == "read-only":
        pytest.skip("root writes into read-only folders")
    cache = tmp_path / "cache"
    if how == "a file":
        cache.write_text("not a folder")
    else:
        cache.mkdir(mode=0o500)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "SYMKIN_CACHE_DIR": str(cache)}
    result = subprocess.run([sys.executable, "-m", "symkin", "run", str(TEXTBOOK)],
                            capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr
    assert result.stderr.count("\n") == 1 and "is not used" in result.stderr
    assert "Traceback" not in result.stderr


def test_a_build_killed_mid_way_leaves_nothing_that_outlives_it(system: symkin.System,
                                                                tmp_path: Path) -> None:
    """kill -9 during the C compile leaves its temporary folder; the next run removes it
    (its process is gone) and builds a good kernel."""
    cache = tmp_path / "cache"
    slow = tmp_path / "slow-cc"
    # It answers the key's `--version` at once (else the build waits for that query's 30 s
    # time-out before it even starts) and hangs only in the compile the test kills.
    slow.write_text("#!/bin/sh\n[ \"$1\" = --version ] && exec cc \"$@\"\nsleep 60\n"
                    "exec cc \"$@\"\n")
    slow.chmod(slow.stat().st_mode | stat.S_IXUSR)
    pickled = tmp_path / "system.pickle"  # this run's System: the process need not derive it
    pickled.write_bytes(pickle.dumps(system))
    code = (f"import pickle, symkin; s = pickle.loads(open({str(pickled)!r}, 'rb').read()); "
            f"symkin.compile(s, cache_dir={str(cache)!r})")
    process = subprocess.Popen([sys.executable, "-c", code], start_new_session=True,
                               env={**os.environ, "PYTHONPATH": str(ROOT), "CC": str(slow)})
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not any(
            p.name.startswith("._symkin_") for p in (cache.iterdir() if cache.exists() else [])):
        time.sleep(0.2)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    left = [p for p in cache.iterdir() if p.name.startswith("._symkin_")]
    assert left, "the build never started"
    build_cache._clean_stale.cache_clear()
    kernel = symkin.compile(system, backend="c", cache_dir=cache)
    assert kernel.backend == "c"
    assert not any(p.exists() for p in left)
    np.testing.assert_allclose(symkin.solve(kernel).q, _reference(), atol=1e-12)


def _compile_variant(job: tuple[str, str, str]) -> float:
    text, name, cache = job
    mechanism = symkin.from_dict(__import__("yaml").safe_load(text) | {"name": name})
    kernel = symkin.compile(symkin.derive(mechanism), backend="c", cache_dir=cache)
    return float(symkin.solve(kernel).q[-1, 6])


@pytest.mark.parametrize("distinct", [True, False])
def test_three_concurrent_cold_builds(distinct: bool, tmp_path: Path) -> None:
    """3 processes build at once into one empty cache: 3 different mechanisms, or 3 times the
    same one; every process gets a correct kernel and the cache holds one folder each. (Three
    race as eight did: two losers of one rename, or three publishers beside each other; each
    process costs a derivation and a C compile.)"""
    cache = str(tmp_path / "cache")
    text = TEXTBOOK.read_text()
    names = [f"cs{k}" if distinct else "cs" for k in range(3)]
    with multiprocessing.get_context("fork").Pool(3) as pool:
        results = pool.map(_compile_variant, [(text, name, cache) for name in names])
    reference = _reference()[-1, 6]
    assert all(abs(value - reference) < 1e-12 for value in results)
    folders = [p for p in Path(cache).iterdir() if p.name.startswith("_symkin_")]
    assert len(folders) == len(set(names))
    assert not [p for p in Path(cache).iterdir() if p.name.startswith(".")]


def test_cache_clear_removes_only_what_symkin_wrote(system: symkin.System, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    cache = tmp_path / "cache"
    symkin.compile(system, backend="numpy", cache_dir=cache)
    (cache / "notes.txt").write_text("mine")
    monkeypatch.setenv("SYMKIN_CACHE_DIR", str(cache))
    assert cli.main(["cache", "info"]) == 0
    assert "kernels: 1" in capsys.readouterr().out
    assert cli.main(["cache", "clear"]) == 0
    assert [p.name for p in cache.iterdir()] == ["notes.txt"]


# ----- generated folders ---------------------------------------------------------------------

def test_generate_never_deletes_files_a_foreign_manifest_lists(system: symkin.System,
                                                                tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "important.txt").write_text("keep me")
    (out / "manifest.json").write_text(json.dumps({"files": {"important.txt": "0"}}))
    (out / "crank_slider_manifest.json").write_text(json.dumps(
        {"generator": "symkin", "name": "crank_slider", "files": {"important.txt": "0"}}))
    with pytest.raises(UsageError, match="files symkin did not write"):
        symkin.generate(system, backend="c", out_dir=out)
    symkin.generate(system, backend="c", out_dir=out, force=True)
    assert (out / "important.txt").read_text() == "keep me"


def test_generate_refuses_a_folder_of_other_files_with_exit_2(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "thesis.tex").write_text("years of work")
    command = ["generate", str(TEXTBOOK), "-o", str(out)]
    assert cli.main(command) == 2
    assert "thesis.tex" in capsys.readouterr().err
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]
    assert cli.main([*command, "--force"]) == 0
    assert (out / "thesis.tex").read_text() == "years of work"


def test_two_mechanisms_share_a_folder(system: symkin.System, tmp_path: Path) -> None:
    out = tmp_path / "out"
    four_bar = derived(ROOT / "examples" / "four_bar.yaml")
    symkin.generate(system, backend="numpy", out_dir=out)
    symkin.generate(four_bar, backend="numpy", out_dir=out)
    symkin.generate(system, backend="numpy", out_dir=out)  # regenerate the first: no refusal
    names = {p.name for p in out.iterdir()}
    assert {"crank_slider.py", "crank_slider_manifest.json", "four_bar.py",
            "four_bar_manifest.json"} <= names
    loaded = backends.load(out, "four_bar")
    assert loaded.name == "four_bar"
    with pytest.raises(FileNotFoundError, match="2 symkin manifests"):
        backends.load(out)


def test_an_edited_generated_file_is_not_deleted(system: symkin.System, tmp_path: Path) -> None:
    """A generated file the user changed is theirs now: switching to the dense LU (which no
    longer writes the sparse LU files) must not delete the edited one."""
    out = tmp_path / "out"
    symkin.generate(system, backend="c", out_dir=out, linalg="sparse")
    edited = out / "crank_slider_sparse_lu.c"
    edited.write_text(edited.read_text() + "/* my tuning */\n")
    with pytest.raises(UsageError):
        symkin.generate(system, backend="c", out_dir=out, linalg="dense")
    symkin.generate(system, backend="c", out_dir=out, linalg="dense", force=True)
    assert edited.read_text().endswith("/* my tuning */\n")
    assert not (out / "crank_slider_sparse_lu.h").exists()  # unedited: symkin's to remove
    shutil.rmtree(out)
