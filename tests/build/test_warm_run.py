"""Warm `symkin run`: the kernel index (symkin/build/index.py) skips SymPy and never serves a stale or
damaged kernel.

Every run is a real `python -m symkin`-style subprocess with its own cache folder (the tests
about the index start from a copy of one cache with the textbook's C kernel built, so that
their cold runs miss the index without compiling C again). A wrapper
reports which heavy modules the process had loaded when it ended, so "no SymPy on a warm run"
is checked on the process itself. The code runs from a snapshot of the package: the index is
keyed on symkin's own source, so edits made elsewhere in the tree while the suite runs would
(correctly) turn warm runs into misses.
"""

from __future__ import annotations

import compileall
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"
HEAVY = ("sympy", "jinja2", "pydantic", "symkin.symbolic.derivation", "symkin.spec.validate", "symkin.build.compile",
         "scipy")
# The Python driver loop factors Phi_q with LAPACK through SciPy; the C solver needs none of it.
WARM_HEAVY = {"c": [], "numpy": ["scipy"]}
MARKER = "loaded-heavy-modules:"
WRAPPER = f"""
import json, sys
from symkin.cli import main
status = main(sys.argv[1:])
print({MARKER!r} + json.dumps(sorted(m for m in {HEAVY!r} if m in sys.modules)))
sys.exit(status)
"""


@pytest.fixture(scope="module")
def snapshot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A copy of the package and its templates, with the wrapper script next to them, its
    bytecode compiled once here (where PYTHONDONTWRITEBYTECODE is set, every run would
    otherwise compile the whole package again)."""
    root = tmp_path_factory.mktemp("symkin-snapshot")
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(ROOT / "symkin", root / "symkin", ignore=ignore)
    (root / "wrapper.py").write_text(WRAPPER)
    assert compileall.compile_dir(root / "symkin", quiet=1)
    return root


@pytest.fixture(scope="module")
def kernels(snapshot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A kernel cache holding the textbook's C kernel, from one cold run of the snapshot."""
    cache = tmp_path_factory.mktemp("kernels") / "cache"
    run = symkin_run(snapshot, cache, TEXTBOOK, "-o", "seed.npz", cwd=cache.parent)
    assert run.returncode == 0 and not run.hit, run.stderr
    return cache


def seeded(kernels: Path, folder: Path) -> Path:
    """``folder`` as a cache that already holds the built kernels but no index: its first run
    misses the index (derives, generates, and finds the kernel by its sources' hash) without
    compiling C again. For the tests whose subject is the index, not the compile."""
    shutil.copytree(kernels, folder, ignore=shutil.ignore_patterns("index"))
    return folder


class Run:
    """One finished `symkin run`: exit status, output, whether it hit the index."""

    def __init__(self, result: subprocess.CompletedProcess) -> None:
        self.returncode = result.returncode
        self.stderr = result.stderr
        lines = result.stdout.splitlines()
        self.heavy = json.loads(lines[-1].removeprefix(MARKER))
        self.stdout = "\n".join(lines[:-1])
        self.hit = "cached kernel" in self.stdout


def symkin_run(snapshot: Path, cache: Path, *args: str | Path, cwd: Path) -> Run:
    env = {**os.environ, "PYTHONPATH": str(snapshot), "SYMKIN_CACHE_DIR": str(cache)}
    result = subprocess.run([sys.executable, str(snapshot / "wrapper.py"), "run",
                             *map(str, args)], cwd=cwd, env=env, capture_output=True, text=True,
                            timeout=300, check=False)
    assert "Traceback" not in result.stderr, result.stderr
    assert result.stdout.splitlines()[-1].startswith(MARKER), result.stdout
    return Run(result)


def check_crank_slider(path: Path, b: float = 5.0) -> dict[str, np.ndarray]:
    """Independent checks of a crank-slider result: the driver law phi = t^2 + pi/2, and the
    rod's length b between the crank tip and the slider pin at every time."""
    data = dict(np.load(path))
    phi = data["q"][:, data["coordinates"].tolist().index("crank.phi")]
    assert np.abs(phi - (data["t"] ** 2 + np.pi / 2)).max() < 1e-9
    tip, pin = data["r"][:, 0], data["r"][:, 1]
    assert np.abs(np.hypot(*(pin - tip).T) - b).max() < 1e-9
    return data


def same_results(first: dict[str, np.ndarray], second: dict[str, np.ndarray]) -> bool:
    return first.keys() == second.keys() and all(
        np.array_equal(first[k], second[k]) for k in first)


def entries(cache: Path) -> list[Path]:
    return sorted((cache / "index").glob("*.json"))


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_warm_run_is_identical_and_skips_sympy(snapshot: Path, kernels: Path, tmp_path: Path,
                                               backend: str) -> None:
    # the cold run derives and generates; its C kernel is built already (seeded)
    cache = seeded(kernels, tmp_path / "cache")
    extra = ("--animate", "a.gif") if backend == "numpy" else ()
    cold = symkin_run(snapshot, cache, TEXTBOOK, "--backend", backend, "-o", "cold.npz", *extra,
                      cwd=tmp_path)
    assert cold.returncode == 0, cold.stderr
    assert not cold.hit and "sympy" in cold.heavy
    assert len(entries(cache)) == 1

    warm = symkin_run(snapshot, cache, TEXTBOOK, "--backend", backend, "-o", "warm.npz", *extra,
                      cwd=tmp_path)
    assert warm.returncode == 0, warm.stderr
    assert warm.hit, warm.stdout
    # no SymPy, jinja2, pydantic, nor the modules that need them
    assert warm.heavy == WARM_HEAVY[backend]
    assert same_results(check_crank_slider(tmp_path / "cold.npz"),
                        check_crank_slider(tmp_path / "warm.npz"))
    if extra:
        assert (tmp_path / "a.gif").read_bytes()[:6] == b"GIF89a"


DISK_CAM = """name: disk
parameters: {}
bodies:
  cam: {q0: [0, 0, 0]}
  follower: {q0: [0, 3, 0], points: {R: [0, 0]}}
joints:
  - {type: revolute, i: ground, j: cam, sA: [0, 0], sB: [0, 0]}
  - {type: prismatic, i: follower, j: ground, sA: [0, 0], sB: [0, 0], v: [1, 0]}
  - {type: cam, name: k1, i: cam, j: follower, profile: {polar: "2 + 0.4*cos(s)"},
     follower: {roller: 0.5, at: R}, s0: pi/2}
drivers:
  - {type: angle, i: cam, j: ground, theta: t}
time: {t0: 0, t1: 3, dt: 0.1}
"""


def test_warm_cam_run_writes_its_outputs_without_deriving_again(snapshot: Path,
                                                                tmp_path: Path) -> None:
    """A cam's pressure angle and radius of curvature come from the file and the pair's own
    expressions: the warm run that writes them never loads the derivation (it used to derive
    the whole file again, Gamma included), and writes the cold run's numbers."""
    mechanism = tmp_path / "disk.yaml"
    mechanism.write_text(DISK_CAM)
    cache = tmp_path / "cache"
    cold = symkin_run(snapshot, cache, mechanism, "--backend", "numpy", "-o", "cold.npz",
                      cwd=tmp_path)
    assert cold.returncode == 0 and not cold.hit, cold.stderr
    warm = symkin_run(snapshot, cache, mechanism, "--backend", "numpy", "-o", "warm.npz",
                      cwd=tmp_path)
    assert warm.returncode == 0 and warm.hit, warm.stderr
    assert "symkin.symbolic.derivation" not in warm.heavy
    first, second = (dict(np.load(tmp_path / f"{run}.npz")) for run in ("cold", "warm"))
    assert {"k1.pressure_angle", "k1.curvature_radius"} <= first.keys()
    assert same_results(first, second)


def test_editing_the_file_misses(snapshot: Path, tmp_path: Path) -> None:
    """With the NumPy backend: the key is the file's bytes whatever the backend
    (test_key_changes_with_every_input), and each edit here is a new kernel, which in C
    would be a C compile each."""
    mechanism = tmp_path / "mechanism.yaml"
    text = TEXTBOOK.read_text()
    mechanism.write_text(text)
    cache = tmp_path / "cache"
    numpy = ("--backend", "numpy")
    assert not symkin_run(snapshot, cache, mechanism, *numpy, "-o", "a.npz", cwd=tmp_path).hit
    assert symkin_run(snapshot, cache, mechanism, *numpy, "-o", "a.npz", cwd=tmp_path).hit

    # A longer rod: a stale kernel would still put the pin 5 from the crank tip.
    mechanism.write_text(text.replace("b: 5.0", "b: 5.5"))
    longer = symkin_run(snapshot, cache, mechanism, *numpy, "-o", "b.npz", cwd=tmp_path)
    assert longer.returncode == 0 and not longer.hit and "sympy" in longer.heavy
    check_crank_slider(tmp_path / "b.npz", b=5.5)

    # Even a comment misses: the key is the raw bytes, which is what makes skipping
    # validation safe.
    mechanism.write_text(text.replace("b: 5.0", "b: 5.5") + "# a comment\n")
    assert not symkin_run(snapshot, cache, mechanism, *numpy, "-o", "c.npz", cwd=tmp_path).hit
    assert len(entries(cache)) == 3


def test_editing_a_template_misses(tmp_path: Path, snapshot: Path, kernels: Path) -> None:
    own = tmp_path / "snapshot"
    shutil.copytree(snapshot, own)
    cache = seeded(kernels, tmp_path / "cache")
    assert not symkin_run(own, cache, TEXTBOOK, "-o", "a.npz", cwd=tmp_path).hit
    assert symkin_run(own, cache, TEXTBOOK, "-o", "a.npz", cwd=tmp_path).hit
    with (own / "symkin" / "backends" / "numpy" / "templates" / "kernel.py.j2").open("a") as template:
        template.write("{# an edit that renders to nothing #}\n")
    again = symkin_run(own, cache, TEXTBOOK, "-o", "b.npz", cwd=tmp_path)
    assert again.returncode == 0 and not again.hit
    assert same_results(check_crank_slider(tmp_path / "a.npz"),
                        check_crank_slider(tmp_path / "b.npz"))


def test_corrupt_index_entry_is_rebuilt(snapshot: Path, kernels: Path,
                                       tmp_path: Path) -> None:
    from symkin import backends
    from symkin.build import index as cache

    folder = seeded(kernels, tmp_path / "cache")
    symkin_run(snapshot, folder, TEXTBOOK, "-o", "a.npz", cwd=tmp_path)
    (entry,) = entries(folder)
    valid = entry.read_bytes()
    key = entry.stem
    # symkin run's default backend is auto, i.e. C here: its entry is not one for NumPy
    assert cache.lookup(folder, key, cache.Options(backend=backends.get("numpy"))) is None
    other_key = json.dumps({**json.loads(valid), "key": "0" * 64}).encode()
    for damage in (b"{not json", b"", b"[]", b"\xff\xfe", other_key):
        entry.write_bytes(damage)
        assert cache.lookup(folder, key, cache.Options(backend=backends.get("c"))) is None
        assert not entry.exists()  # removed, so the next run records a good one

    entry.write_bytes(b"{not json")
    rerun = symkin_run(snapshot, folder, TEXTBOOK, "-o", "b.npz", cwd=tmp_path)
    assert rerun.returncode == 0 and not rerun.hit, rerun.stderr
    assert same_results(check_crank_slider(tmp_path / "a.npz"),
                        check_crank_slider(tmp_path / "b.npz"))
    assert entry.read_bytes() == valid
    assert symkin_run(snapshot, folder, TEXTBOOK, "-o", "b.npz", cwd=tmp_path).hit


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_damaged_kernel_is_never_loaded(snapshot: Path, kernels: Path, tmp_path: Path,
                                       backend: str) -> None:
    cache = seeded(kernels, tmp_path / "cache")
    symkin_run(snapshot, cache, TEXTBOOK, "--backend", backend, "-o", "a.npz", cwd=tmp_path)
    (entry,) = entries(cache)
    recorded = json.loads(entry.read_text())
    loaded = next(name for name in recorded["files"] if name != "manifest.json")
    # Importing this module would end the process with status 3; a damaged extension would
    # fail to load (or worse). Either way the hash no longer matches the entry.
    damage = b"raise SystemExit(3)\n" if backend == "numpy" else b"\x7fELF garbage"
    (cache / recorded["folder"] / loaded).write_bytes(damage)

    rerun = symkin_run(snapshot, cache, TEXTBOOK, "--backend", backend, "-o", "b.npz",
                       cwd=tmp_path)
    assert rerun.returncode == 0 and not rerun.hit, rerun.stderr
    assert same_results(check_crank_slider(tmp_path / "a.npz"),
                        check_crank_slider(tmp_path / "b.npz"))
    assert (cache / recorded["folder"] / loaded).read_bytes() != damage  # rebuilt, not reused
    assert symkin_run(snapshot, cache, TEXTBOOK, "--backend", backend, "-o", "c.npz",
                      cwd=tmp_path).hit


def test_entry_naming_a_folder_outside_the_cache_is_refused(tmp_path: Path) -> None:
    from symkin import backends
    from symkin.build import index as cache

    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "manifest.json").write_text("{}")
    key = "1" * 64
    entry = cache.entry_path(tmp_path / "cache", key)
    entry.parent.mkdir(parents=True)
    for folder in ("../../outside", "/abs/_symkin_x", "_symkin_x/../../outside", ".hidden"):
        entry.write_text(json.dumps({"format": cache.FORMAT, "key": key, "backend": "numpy",
                                     "folder": folder, "files": {"manifest.json": "0"}}))
        assert cache.lookup(tmp_path / "cache", key, cache.Options(backends.get("numpy"))) is None
        assert not entry.exists()  # a damaged entry is removed
    assert (outside / "manifest.json").exists()


def test_key_changes_with_every_input(tmp_path: Path) -> None:
    from symkin import backends
    from symkin.build import index as cache

    mechanism = tmp_path / "m.yaml"
    mechanism.write_bytes(TEXTBOOK.read_bytes())
    base = cache.Options(backend=backends.get("numpy"), cse=True)
    keys = {cache.index_key(mechanism, base)}
    for options in (cache.Options(backends.get("c"), True, (("linalg", "dense"),)),
                    cache.Options(backends.get("c"), True, (("real", "float"),
                                                             ("linalg", "dense"))),
                    cache.Options(backends.get("numpy"), False),
                    cache.Options(backends.get("c"), True)):
        keys.add(cache.index_key(mechanism, options))
    # a default given is the same kernel as one left out: the same key
    assert cache.index_key(mechanism, cache.Options(backends.get("c"), True, (
        ("real", "double"), ("linalg", "sparse")))) == cache.index_key(
        mechanism, cache.Options(backends.get("c"), True))
    toml = mechanism.with_suffix(".toml")
    toml.write_bytes(mechanism.read_bytes())  # same bytes, another format
    keys.add(cache.index_key(toml, base))
    assert len(keys) == 6 and None not in keys
    assert cache.index_key(tmp_path / "missing.yaml", base) is None


def test_default_options_are_the_compilers() -> None:
    """The index's defaults must be the ones symkin.build.compile.compile uses, or a warm run would
    look up another kernel than a cold run builds."""
    import inspect

    from symkin.build import compile as build
    from symkin import backends
    from symkin.build import index as cache

    defaults = inspect.signature(build.compile).parameters
    assert cache.Options(backends.get("numpy")).cse == defaults["cse"].default
    # the backend's own options: none given on either side, so the backend's defaults
    assert cache.Options(backends.get("numpy")).choices == ()
    assert defaults["options"].default is None


def test_concurrent_cold_runs_leave_one_good_entry(snapshot: Path, kernels: Path,
                                                   tmp_path: Path) -> None:
    """Three runs miss the index at once and each records its entry: one good entry is left.
    (Their kernel is already built: concurrent compiles are tests/build/test_build.py's.)"""
    cache = seeded(kernels, tmp_path / "cache")
    env = {**os.environ, "PYTHONPATH": str(snapshot), "SYMKIN_CACHE_DIR": str(cache)}
    runs = [subprocess.Popen([sys.executable, str(snapshot / "wrapper.py"), "run", str(TEXTBOOK),
                              "-o", f"{k}.npz"], cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True) for k in range(3)]
    for run in runs:
        _, stderr = run.communicate(timeout=300)
        assert run.returncode == 0, stderr
    (entry,) = entries(cache)
    assert not list((cache / "index").glob(".*"))  # no temporary files left behind
    warm = symkin_run(snapshot, cache, TEXTBOOK, "-o", "warm.npz", cwd=tmp_path)
    assert warm.hit and warm.heavy == WARM_HEAVY["c"]  # the default backend auto is C here
    for k in range(3):
        assert same_results(check_crank_slider(tmp_path / f"{k}.npz"),
                            check_crank_slider(tmp_path / "warm.npz"))
