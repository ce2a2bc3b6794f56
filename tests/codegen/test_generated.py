"""The committed generated/ folder: byte-for-byte reproducible, well-formed, warning-free.

Run with SYMKIN_UPDATE_GOLDENS=1 to rewrite generated/ from the current templates.
"""

from __future__ import annotations

import difflib
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from codegen_support import (
    ALL_EXAMPLES,
    BACKENDS,
    EXAMPLES,
    GENERATED,
    ROOT,
    STRICT_FLAGS,
    code_without_comments,
    compile_object,
    compilers,
    example_ids,
    golden_folder,
    sources,
    system,
    write_sources,
)

import symkin

UPDATE = os.environ.get("SYMKIN_UPDATE_GOLDENS") == "1"


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


# The MATLAB/Octave backend's goldens: one example per kind of file its templates branch on
# (planar, with masses, with input drivers, with removed rows, spatial); writing .m files
# needs no Octave.
OCTAVE_GOLDENS = ("crank_slider", "four_bar_dynamics", "crank_slider_input",
                  "parallelogram_extra_bar", "spatial_slider_crank")


@pytest.mark.parametrize(("name", "backend"), [
    *((path.stem, backend) for backend in BACKENDS for path in ALL_EXAMPLES),  # heavy ones too
    *((name, "octave") for name in OCTAVE_GOLDENS)])
def test_golden_matches_regeneration(name: str, backend: str, tmp_path: Path) -> None:
    fresh = tmp_path / backend
    symkin.generate(system(name), backend=backend, out_dir=fresh)
    golden = golden_folder(name, backend)
    if UPDATE:
        shutil.rmtree(golden, ignore_errors=True)
        shutil.copytree(fresh, golden)
    assert golden.is_dir(), f"no golden for {name}; run with SYMKIN_UPDATE_GOLDENS=1"
    expected, actual = _files(golden), _files(fresh)
    assert sorted(actual) == sorted(expected), (
        f"file list differs: only golden {sorted(set(expected) - set(actual))}, "
        f"only fresh {sorted(set(actual) - set(expected))}")
    for file_name in expected:
        assert actual[file_name] == expected[file_name], (
            f"generated/{name}/{backend}/{file_name} is stale; rerun with "
            "SYMKIN_UPDATE_GOLDENS=1 and review this diff:\n"
            + unified_diff(expected[file_name], actual[file_name], file_name))


def unified_diff(golden: bytes, fresh: bytes, file_name: str, limit: int = 80) -> str:
    """The first ``limit`` lines of a unified diff from the golden file to the fresh one."""
    lines = list(difflib.unified_diff(
        golden.decode("utf-8", "replace").splitlines(keepends=True),
        fresh.decode("utf-8", "replace").splitlines(keepends=True),
        fromfile=f"golden/{file_name}", tofile=f"fresh/{file_name}"))
    more = f"... {len(lines) - limit} more diff lines\n" if len(lines) > limit else ""
    return "".join(lines[:limit]) + more


def test_golden_mismatch_message_is_a_unified_diff() -> None:
    text = unified_diff(b"a\nb\nc\n", b"a\nB\nc\n", "x.c")
    assert "--- golden/x.c" in text and "+++ fresh/x.c" in text
    assert "-b\n" in text and "+B\n" in text


def test_every_golden_has_an_example() -> None:
    examples = {path.stem for path in ALL_EXAMPLES}
    goldens = {path.name for path in GENERATED.iterdir() if path.is_dir()}
    assert goldens <= examples, f"stale golden folders: {sorted(goldens - examples)}"


_SCRIPT = """
import sys
from pathlib import Path
import symkin
system = symkin.derive(sys.argv[1])
for backend in ("c", "numpy"):
    symkin.generate(system, backend=backend, out_dir=Path(sys.argv[2]) / backend)
symkin.generate(system, backend="c", out_dir=Path(sys.argv[2]) / "float", real="float")
"""


@pytest.mark.slow
def test_same_bytes_for_any_hash_seed(tmp_path: Path) -> None:
    # all_drivers has every driver type: the most varied expressions for set/dict ordering.
    mechanism = ROOT / "examples" / "all_drivers.yaml"
    if not mechanism.exists():
        mechanism = EXAMPLES[0]
    outputs = []
    for seed in ("0", "4242"):
        out = tmp_path / seed
        subprocess.run([sys.executable, "-c", _SCRIPT, str(mechanism), str(out)], check=True,
                       cwd=ROOT, env={**os.environ, "PYTHONHASHSEED": seed})
        outputs.append({str(p.relative_to(out)): p.read_bytes() for p in out.rglob("*")
                        if p.is_file()})
    assert outputs[0] == outputs[1]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", example_ids())
def test_headers_name_template_and_spec(name: str, backend: str) -> None:
    spec = system(name).mechanism.spec_hash()
    for path in sorted(golden_folder(name, backend).glob(f"{name}*")):
        if path.name.endswith("_manifest.json"):  # JSON, no header: the spec is a field
            assert json.loads(path.read_text())["spec_sha256"] == spec
            continue
        head = path.read_text().split("\n", 12)[:12]
        text = "\n".join(head)
        assert spec in text, path.name
        assert re.search(r"template \S+\.j2", text), path.name
        assert re.search(r"do not edit", text, re.IGNORECASE), path.name
        assert not re.search(r"\b20\d\d-\d\d-\d\d\b|\d\d:\d\d:\d\d", path.read_text()), path.name


def test_names_from_the_file_only_in_comments(tmp_path: Path) -> None:
    # Give every body, point and parameter a name no template could contain by chance.
    text = (ROOT / "examples" / "crank_slider.yaml").read_text()
    renamed = re.sub(r"\b(a|b|c|crank|rod|slider|tip|P)\b", r"zqx\1", text)
    (tmp_path / "renamed.yaml").write_text(renamed)
    import symkin

    folder = tmp_path / "c"
    symkin.generate(symkin.derive(tmp_path / "renamed.yaml"), backend="c", out_dir=folder)
    for path in sorted(folder.glob("*.[ch]")):
        text = path.read_text()
        assert "zqx" in text or "kernel" not in path.name  # the names are in the comments...
        assert "zqx" not in code_without_comments(text), path.name  # ...and only there


@pytest.mark.skipif(not compilers(), reason="neither gcc nor clang is installed")
@pytest.mark.parametrize("real", ["double", "float"])
@pytest.mark.parametrize("name", example_ids())
def test_c_compiles_without_warnings(name: str, real: str, tmp_path: Path) -> None:
    if real == "double":
        folder = golden_folder(name, "c")
    else:
        # shared with test_embedded's float folder (codegen_support.sources)
        folder = write_sources(sources(ROOT / "examples" / f"{name}.yaml", "c", real="float"),
                               tmp_path / "src")
    extra = ["-Wdouble-promotion", "-Wshadow", "-Wstrict-prototypes"]
    for compiler in compilers():
        for source in sorted(folder.glob("*.c")):
            result = compile_object(compiler, source, [*STRICT_FLAGS, *extra, "-O2"],
                                    tmp_path / f"{compiler}_{source.stem}.o")
            assert result.returncode == 0, f"{compiler} {source.name}:\n{result.stderr}"
    _assert_no_mutable_data(sorted(tmp_path.glob("*.o")))


NO_POINTS_NO_PARAMETERS = {
    "name": "bare_pendulum", "parameters": {},
    "bodies": {"arm": {"q0": [0, 0, 0]}},
    "joints": [{"type": "revolute", "i": "ground", "j": "arm", "sA": [0, 0], "sB": [0, 0]}],
    "drivers": [{"type": "angle", "i": "arm", "j": "ground", "theta": "sqrt(2)*t + pi/3"}],
    "time": {"t0": 0, "t1": 1, "dt": 0.5},
}


def _test_mechanisms() -> list[str]:
    return sorted(path.stem for path in (ROOT / "tests" / "mechanisms").glob("*.yaml")) + [
        "andrews_squeezer", "bare_pendulum"]


@pytest.mark.skipif(not compilers(), reason="neither gcc nor clang is installed")
@pytest.mark.parametrize("real", ["double", "float"])
@pytest.mark.parametrize("name", _test_mechanisms())
def test_every_test_mechanism_compiles_with_the_advertised_flags(name: str, real: str,
                                                                 tmp_path: Path) -> None:
    """-std=c99 -Wall -Wextra -pedantic -Werror, double and float, with every compiler found:
    also a mechanism with no named points and no parameters (nothing unused may warn)."""
    import symkin

    if name == "bare_pendulum":
        mechanism = symkin.from_dict(NO_POINTS_NO_PARAMETERS)
    elif name == "andrews_squeezer":
        mechanism = symkin.load(ROOT / "examples" / "andrews_squeezer.yaml")
    else:
        mechanism = symkin.load(ROOT / "tests" / "mechanisms" / f"{name}.yaml")
    folder = tmp_path / "src"
    symkin.generate(symkin.derive(mechanism), backend="c", out_dir=folder, real=real)
    for compiler in compilers():
        for source in sorted(folder.glob("*.c")):
            result = compile_object(compiler, source, [*STRICT_FLAGS, "-Wdouble-promotion", "-O2"],
                                    tmp_path / f"{compiler}_{source.stem}.o")
            assert result.returncode == 0, f"{compiler} {source.name}:\n{result.stderr}"


def _assert_no_mutable_data(objects: list[Path]) -> None:
    """No writable globals or statics: no symbol in .data or .bss (nm types D, d, B, b)."""
    nm = shutil.which("nm")
    if nm is None:
        return
    listing = subprocess.run([nm, *map(str, objects)], capture_output=True, text=True,
                             check=True).stdout
    writable = [line for line in listing.splitlines()
                if len(line.split()) == 3 and line.split()[1] in "DdBb"]
    assert not writable, "mutable data in generated C:\n" + "\n".join(writable)


def test_cli_generate_writes_the_golden_files(tmp_path: Path) -> None:
    from symkin import cli

    status = cli.main(["generate", str(ROOT / "examples" / "crank_slider.yaml"),
                       "--backend", "numpy", "-o", str(tmp_path / "out")])
    assert status == 0
    assert _files(tmp_path / "out") == _files(golden_folder("crank_slider", "numpy"))


def test_cli_generate_bad_input_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    from symkin import cli

    missing = tmp_path / "missing.yaml"
    assert cli.main(["generate", str(missing), "-o", str(tmp_path / "out")]) == 2
    assert cli.main(["generate", str(ROOT / "examples" / "crank_slider.yaml"), "--backend",
                     "numpy", "--real", "float", "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "missing.yaml" in err and "--real float is not for the NumPy backend" in err
    assert "Traceback" not in err


def test_regenerating_removes_files_the_new_output_does_not_have(tmp_path: Path) -> None:
    folder = tmp_path / "c"
    symkin.generate(system("four_bar"), backend="c", out_dir=folder, linalg="sparse")
    (folder / "notes.txt").write_text("mine")
    symkin.generate(system("four_bar"), backend="c", out_dir=folder, force=True)
    names = {p.name for p in folder.iterdir()}
    assert names == set(_files(golden_folder("four_bar", "c"))) | {"notes.txt"}


def test_force_replaces_a_symlink_and_never_writes_through_it(tmp_path: Path) -> None:
    """A symlink named like a generated file, pointing outside the folder: --force replaces
    the link itself with the generated file; the file it pointed to is left as it was."""
    from symkin import cli

    folder, outside = tmp_path / "out", tmp_path / "outside.c"
    arguments = ["generate", str(ROOT / "examples" / "crank_slider.yaml"), "--backend", "c",
                 "-o", str(folder)]
    assert cli.main(arguments) == 0
    link = folder / "crank_slider_solver.c"
    generated = link.read_text()
    outside.write_text("not symkin's\n")
    link.unlink()
    link.symlink_to(outside)
    assert cli.main([*arguments, "--force"]) == 0
    assert outside.read_text() == "not symkin's\n"
    assert not link.is_symlink() and link.read_text() == generated


def test_a_symlink_to_a_generated_copy_is_not_symkins(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture) -> None:
    """symkin never writes a symlink: one named like a generated file counts as not symkin's
    even where it points to a copy of it, so generating again without --force refuses."""
    from symkin import cli

    folder, outside = tmp_path / "out", tmp_path / "outside.c"
    arguments = ["generate", str(ROOT / "examples" / "crank_slider.yaml"), "--backend", "c",
                 "-o", str(folder)]
    assert cli.main(arguments) == 0
    link = folder / "crank_slider_solver.c"
    outside.write_text(link.read_text())
    link.unlink()
    link.symlink_to(outside)
    assert cli.main(arguments) == 2
    assert "crank_slider_solver.c" in capsys.readouterr().err and link.is_symlink()
