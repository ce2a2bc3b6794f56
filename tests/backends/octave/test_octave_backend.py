"""The MATLAB/Octave backend: generated .m files lint clean of Octave-only syntax, hold one
function each, take the parameters as an argument, and — run in Octave — give the rows NumPy
gives, for every planar and spatial example."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from codegen_support import compiled, derived, golden_folder
from octave_support import assert_octave_equals_numpy, needs_octave

import symkin
from symkin import cli
from symkin.backends import get

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = sorted((ROOT / "examples").glob("*.yaml"))
# What GNU Octave accepts and MATLAB does not: '#' comments, != and !, ++/+= and friends,
# the end* keywords, double-quoted strings.
OCTAVE_ONLY = {
    "# (an Octave comment)": re.compile(r"#"),
    "!= or ! (Octave's not)": re.compile(r"!"),
    "++ or -- (increments)": re.compile(r"\+\+|--(?!-)\s*;"),
    "+=, -=, *=, /= (compound assignment)": re.compile(r"[-+*/]="),
    "endfunction, endif, endfor, endwhile": re.compile(r"\bend(function|if|for|while)\b"),
    "a double-quoted string": re.compile(r'"'),
    "printf (Octave's; MATLAB has fprintf)": re.compile(r"(?<!f)printf\("),
}
# a planar one with masses (multipliers), a spatial one, an over-constrained one
LINTED = ("crank_slider", "four_bar_dynamics", "spatial_slider_crank",
          "parallelogram_extra_bar_loads")


def lint(text: str) -> list[str]:
    """The Octave-only constructs in one .m file's text, as 'line N: what'."""
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        found += [f"line {number}: {what}" for what, pattern in OCTAVE_ONLY.items()
                  if pattern.search(line)]
    return found


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folders = {}
    for name in LINTED:
        folder = tmp_path_factory.mktemp(name)
        symkin.generate(derived(ROOT / "examples" / f"{name}.yaml"), "octave", folder)
        folders[name] = folder
    return folders


def test_lint_finds_octave_only_syntax() -> None:
    """The lint itself: each construct it must refuse is found (and a clean line is not)."""
    bad = ["x = 1; # note", "if a != b", "k++;", "k += 1;", "endfunction", 'disp("a")',
           "printf('%d', 1)", "y = ~x;  % not"]
    assert [bool(lint(line)) for line in bad] == [True] * 7 + [False]


@pytest.mark.parametrize("name", LINTED)
def test_generated_m_files_run_in_matlab_too(generated: dict[str, Path], name: str) -> None:
    """No Octave-only syntax, and one function per file named as the file."""
    files = sorted(generated[name].glob("*.m"))
    assert {f.stem for f in files} >= {f"{name}_{what}" for what in
                                        ("phi", "phi_q", "phi_t", "gamma", "points", "data",
                                         "solve", "point_kinematics")}
    for path in files:
        text = path.read_text(encoding="utf-8")
        assert not lint(text), f"{path.name}: {lint(text)}"
        functions = re.findall(r"^function\b.*?(\w+)\(", text, flags=re.MULTILINE)
        assert functions == [path.stem], f"{path.name} defines {functions}"
        assert text.startswith("function ")


def test_multipliers_only_where_the_file_has_masses(generated: dict[str, Path]) -> None:
    assert not list(generated["crank_slider"].glob("*_multipliers.m"))
    assert (generated["four_bar_dynamics"] / "four_bar_dynamics_multipliers.m").is_file()
    assert (generated["parallelogram_extra_bar_loads"] /
            "parallelogram_extra_bar_loads_removed.m").is_file()


def test_row_comments_name_the_joint_or_driver(generated: dict[str, Path]) -> None:
    phi = (generated["crank_slider"] / "crank_slider_phi.m").read_text(encoding="utf-8")
    assert re.search(r"out\(9\) = .*% drivers\[0\] angle crank-ground", phi)
    phi_q = (generated["crank_slider"] / "crank_slider_phi_q.m").read_text(encoding="utf-8")
    assert re.search(r"% \(9, 3\) drivers\[0\] angle crank-ground \(angle\), crank\.phi", phi_q)


# Deriving and lowering these takes SymPy a minute or more (each, twice lowered): slow.
HEAVY = {"cam_cycloidal", "delta", "delta_fk", "stewart", "stewart_legs", "stewart_legs_fk"}
# Checked where its derivation and NumPy kernel are built anyway:
# tests/spatial/test_stewart_fk.py::test_octave_runs_equal_numpy.
ELSEWHERE = {"stewart_legs_fk"}


@needs_octave
@pytest.mark.parametrize("path", [pytest.param(p, id=p.stem, marks=[pytest.mark.slow]
                                               if p.stem in HEAVY else [])
                                  for p in EXAMPLES if p.stem not in ELSEWHERE])
def test_octave_runs_equal_numpy(path: Path) -> None:
    """symkin.solve with the octave kernel gives NumPy's rows to 1e-12 on every example. The
    NumPy kernel is built from the goldens, which test_generated proves equal to a fresh
    generation, and so is the Octave one where the example has .m goldens; the other
    examples' .m files are generated here, through symkin.compile."""
    golden = golden_folder(path.stem, "octave").is_dir()
    assert_octave_equals_numpy(derived(path), compiled(path, "numpy"), path.stem,
                               compiled(path, "octave") if golden else None)


@needs_octave
def test_parameters_are_an_argument(generated: dict[str, Path]) -> None:
    """Phi at other parameters than the nominal ones, in Octave, equals NumPy's there: the
    parameters are p, never constants baked into the files."""
    numpy = compiled(ROOT / "examples" / "crank_slider.yaml", "numpy")
    octave = get("octave").load(generated["crank_slider"],
                                {**_manifest(generated["crank_slider"]), "backend": "octave"})
    q = np.linspace(0.1, 0.9, numpy.nq)
    p = numpy.p_values * np.array([1.3, 0.7, 1.1])
    for function in ("phi", "phi_q", "phi_t"):
        assert np.allclose(getattr(octave, function)(q, 0.4, p),
                           getattr(numpy, function)(q, 0.4, p), rtol=1e-14, atol=1e-14)
    assert not np.allclose(octave.phi(q, 0.4, p), octave.phi(q, 0.4))


def _manifest(folder: Path) -> dict[str, object]:
    import json

    return dict(json.loads(next(folder.glob("*_manifest.json")).read_text(encoding="utf-8")))


@needs_octave
@pytest.mark.parametrize("name", ["crank_slider", "spatial_slider_crank"])
def test_the_generated_driver_solves_as_numpy(generated: dict[str, Path], name: str) -> None:
    """<prefix>_solve.m (predictor, Newton, velocity, acceleration) run in Octave over the
    file's grid gives NumPy's rows."""
    folder = generated[name]
    script = (f"[T, Q, DQ, D2Q] = {name}_solve(); fprintf('%.17g\\n', [T; Q; DQ; D2Q]);")
    result = subprocess.run(["octave-cli", "--norc", "--quiet", "--eval", script], cwd=folder,
                            capture_output=True, text=True, timeout=120, check=True)
    numpy = symkin.solve(compiled(ROOT / "examples" / f"{name}.yaml", "numpy"))
    values = np.array(result.stdout.split(), dtype=float)
    nq = numpy.q.shape[1]
    table = values.reshape(-1, 1 + 3 * nq)
    assert np.allclose(table[:, 0], numpy.t, rtol=0, atol=1e-15)
    for k, field in enumerate(("q", "dq", "d2q")):
        ours = table[:, 1 + k * nq: 1 + (k + 1) * nq]
        theirs = np.asarray(getattr(numpy, field))
        assert np.max(np.abs(ours - theirs)) <= 1e-9 * (1 + np.max(np.abs(theirs))), field


@needs_octave
@pytest.mark.parametrize("name", ["crank_slider", "spatial_slider_crank"])
def test_point_kinematics_equal_the_trajectorys(generated: dict[str, Path], name: str) -> None:
    """<prefix>_point_kinematics (r + R s and its derivatives; spatial: R from the Euler
    parameters) equals the runtime's points at a row of a NumPy run."""
    numpy = symkin.solve(compiled(ROOT / "examples" / f"{name}.yaml", "numpy"))
    expected = numpy.point_arrays()
    row = 7

    def column(values: np.ndarray) -> str:
        return "[" + ";".join(repr(float(v)) for v in values) + "]"

    state = ", ".join(column(getattr(numpy, f)[row]) for f in ("q", "dq", "d2q"))
    script = (f"[P, V, A] = {name}_point_kinematics({state}); "
              "fprintf('%.17g\\n', [P(:); V(:); A(:)]);")
    result = subprocess.run(["octave-cli", "--norc", "--quiet", "--eval", script],
                            cwd=generated[name], capture_output=True, text=True, timeout=120,
                            check=True)
    values = np.array(result.stdout.split(), dtype=float)
    count, size = expected[0].shape[1:]
    assert values.size == 3 * count * size
    for k, array in enumerate(expected):
        ours = values[k * count * size:(k + 1) * count * size].reshape(size, count).T
        assert np.max(np.abs(ours - array[row])) <= 1e-13 * (1 + np.max(np.abs(array[row])))


@needs_octave
def test_run_cli_with_the_octave_backend(tmp_path: Path) -> None:
    """symkin run --backend octave writes NumPy's rows (the CLI called in this process: the
    console script's own process is tested in tests/build/test_packaging.py)."""
    rows = {}
    for backend in ("octave", "numpy"):
        out = tmp_path / f"{backend}.csv"
        assert cli.main(["run", str(ROOT / "examples" / "crank_slider.yaml"), "--backend",
                         backend, "-o", str(out)]) == 0
        rows[backend] = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.max(np.abs(rows["octave"] - rows["numpy"])) <= 1e-12


def test_without_octave_the_backend_says_so(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    """No octave-cli on PATH: exit 2 with a one-paragraph message, no traceback."""
    monkeypatch.setenv("PATH", str(Path(sys.executable).parent))
    status = cli.main(["run", str(ROOT / "examples" / "crank_slider.yaml"), "--backend",
                       "octave", "-o", str(tmp_path / "run.csv")])
    err = capsys.readouterr().err
    assert status == 2
    assert "octave-cli" in err and "not on PATH" in err
    assert "Traceback" not in err
