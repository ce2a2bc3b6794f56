"""Command-line habits: --version, --set NAME=VALUE, run --at T, the CSV's point columns, the
default backend of generate, and the messages for mistakes in them (exit 2, no traceback).

References are the textbook crank-slider's closed form (Example 2.7), written here:
phi1 = t**2 + pi/2, crank tip (a cos phi1, a sin phi1), rod angle asin((c - a sin phi1)/b),
slider x = a cos phi1 + b cos phi2, and their time derivatives by hand.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from cli_support import Ran, symkin_main, symkin_process

import symkin
from symkin.cli import overrides
from symkin.errors import UsageError

ROOT = Path(__file__).resolve().parents[2]
TEXTBOOK = ROOT / "examples" / "crank_slider.yaml"


def symkin_cli(*args: str, cwd: Path, env: dict[str, str] | None = None) -> Ran:
    return symkin_main(*args, cwd=cwd, env=env)


def closed_form(t: np.ndarray, a: float = 1.0, b: float = 5.0, c: float = 4.0) -> dict:
    """Example 2.7 with first and second derivatives (chain rule by hand)."""
    phi1, w1, e1 = t**2 + np.pi / 2, 2 * t, 2.0 + 0 * t
    tip = np.stack([a * np.cos(phi1), a * np.sin(phi1)], -1)
    tip_v = np.stack([-a * np.sin(phi1) * w1, a * np.cos(phi1) * w1], -1)
    tip_a = np.stack([-a * np.cos(phi1) * w1**2 - a * np.sin(phi1) * e1,
                      -a * np.sin(phi1) * w1**2 + a * np.cos(phi1) * e1], -1)
    s2 = (c - tip[:, 1]) / b                   # sin(phi2)
    phi2 = np.arcsin(s2)
    w2 = -tip_v[:, 1] / (b * np.cos(phi2))     # d/dt of b sin(phi2) = c - y2
    e2 = (-tip_a[:, 1] + b * np.sin(phi2) * w2**2) / (b * np.cos(phi2))
    x3 = tip[:, 0] + b * np.cos(phi2)
    v3 = tip_v[:, 0] - b * np.sin(phi2) * w2
    a3 = tip_a[:, 0] - b * np.cos(phi2) * w2**2 - b * np.sin(phi2) * e2
    return {"phi1": phi1, "w1": w1, "tip": (tip, tip_v, tip_a), "phi2": phi2, "w2": w2,
            "e2": e2, "x3": x3, "v3": v3, "a3": a3}


# ----- --version -----------------------------------------------------------------------------

def test_version(tmp_path: Path) -> None:
    import tomllib

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert symkin.__version__ == declared
    result = symkin_process("--version", cwd=tmp_path)  # a real process: the shell's view
    assert result.returncode == 0 and result.stdout.strip() == f"symkin {declared}"


# ----- --set ---------------------------------------------------------------------------------

def test_set_parses_names_and_values() -> None:
    assert overrides.parse(["b=5.5", " a = 2*pi/3 "]) == {"b": "5.5", "a": "2*pi/3"}
    for bad in (["b"], ["=1"], ["b="], ["1b=2"], ["b=1", "b=2"]):
        with pytest.raises(UsageError):
            overrides.parse(bad)


def test_set_changes_the_solved_mechanism(tmp_path: Path) -> None:
    """Nominal, overridden, nominal again: the warm-run index never hands one run's kernel
    (with its nominal values) to the other."""
    for override, b, c in ((), 5.0, 4.0), (("--set", "b=5.5", "--set", "c=7/2"), 5.5, 3.5), \
            ((), 5.0, 4.0):
        result = symkin_cli("run", str(TEXTBOOK), "--backend", "numpy", *override,
                            "-o", "out.csv", cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        table = np.genfromtxt(tmp_path / "out.csv", delimiter=",", names=True, deletechars="")
        exact = closed_form(table["t"], b=b, c=c)
        assert np.abs(table["rod.phi"] - exact["phi2"]).max() < 1e-9
        assert np.abs(table["slider.x"] - exact["x3"]).max() < 1e-9
        assert np.abs(table["slider.x_tt"] - exact["a3"]).max() < 1e-7


def test_set_on_show_and_generate(tmp_path: Path) -> None:
    shown = symkin_cli("show", str(TEXTBOOK), "--set", "b=6", cwd=tmp_path)
    assert shown.returncode == 0 and "p[1] = b = 6\n" in shown.stdout, shown.stdout
    local = symkin_cli("show", "--local", str(ROOT / "examples" / "crank_slider_drawn.yaml"),
                       "--set", "b=6", "--set", "a=pi/3", cwd=tmp_path)
    assert local.returncode == 0, local.stderr
    assert "parameters: {a: pi/3, b: 6.0, c: 4.0}" in local.stdout
    made = symkin_cli("generate", str(TEXTBOOK), "--backend", "numpy", "--set", "a=1.5",
                      "-o", "gen", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    assert "1.5" in (tmp_path / "gen" / "crank_slider_manifest.json").read_text()


@pytest.mark.parametrize("value, words", [
    ("z=1", "has no parameter 'z'; its parameters are: a, b, c"),
    ("b=__import__('os')", "Give a number or an expression of numbers"),
    ("b=a*2", "Give a number or an expression of numbers"),
    ("b=1/0", "--set b=1/0"),
    ("b", "write NAME=VALUE"),
])
def test_bad_set_exits_2(value: str, words: str, tmp_path: Path) -> None:
    result = symkin_cli("run", str(TEXTBOOK), "--set", value, "-o", "x.csv", cwd=tmp_path)
    assert result.returncode == 2 and words in result.stderr, result.stderr
    assert list(tmp_path.iterdir()) == []


# ----- run --at ------------------------------------------------------------------------------

@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_at_prints_one_configuration(backend: str, tmp_path: Path) -> None:
    at = 0.7
    result = symkin_cli("run", str(TEXTBOOK), "--backend", backend, "--at", str(at),
                        "-o", "one.npz", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert f"crank_slider at t = {at} ({backend} backend" in result.stdout
    rows = {line.split()[0]: [float(v) for v in line.split()[1:]]
            for line in result.stdout.splitlines()[3:] if line.strip()
            and line.split()[0] not in ("point",)}
    exact = closed_form(np.array([at]))
    assert rows["crank.phi"] == pytest.approx([exact["phi1"][0], exact["w1"][0], 2.0],
                                              abs=1e-9)
    assert rows["rod.phi"] == pytest.approx([exact["phi2"][0], exact["w2"][0], exact["e2"][0]],
                                            abs=1e-8)
    tip = [exact["tip"][k][0][i] for k in range(3) for i in range(2)]
    assert rows["crank.tip"] == pytest.approx(tip, abs=1e-8)
    saved = np.load(tmp_path / "one.npz")
    assert saved["t"].tolist() == [at] and saved["q"].shape == (1, 9)


def test_at_needs_no_grid_options(tmp_path: Path) -> None:
    result = symkin_cli("run", str(TEXTBOOK), "--at", "0.5", "--plot", "p.png", cwd=tmp_path)
    assert result.returncode == 2 and "--plot need a time grid" in result.stderr
    result = symkin_cli("run", str(TEXTBOOK), "--at", "nan", cwd=tmp_path)
    assert result.returncode == 2 and "finite" in result.stderr


# ----- CSV point columns, --select, generate's backend -----------------------------------------

def test_csv_point_columns_match_the_closed_form(tmp_path: Path) -> None:
    result = symkin_cli("run", str(TEXTBOOK), "-o", "out.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    table = np.genfromtxt(tmp_path / "out.csv", delimiter=",", names=True, deletechars="")
    exact = closed_form(table["t"])
    for k, order in enumerate(("", "v", "a")):
        for i, axis in enumerate("xy"):
            column = table[f"crank.tip_{order}{axis}"]
            assert np.abs(column - exact["tip"][k][:, i]).max() < 1e-8, (order, axis)
    # rod.P is the slider's pin: on the slide y = c, moving with the slider
    assert np.abs(table["rod.P_x"] - exact["x3"]).max() < 1e-9
    assert np.abs(table["rod.P_vx"] - exact["v3"]).max() < 1e-8
    assert np.abs(table["rod.P_ay"]).max() < 1e-8


def test_bad_select_exits_2_with_the_valid_names(tmp_path: Path) -> None:
    result = symkin_cli("run", str(TEXTBOOK), "--plot", "p.png", "--select", "crank.phi,rod.Q",
                        cwd=tmp_path)
    assert result.returncode == 2
    assert "rod.Q" in result.stderr and "crank.phi, crank.x" not in result.stderr
    # Ten of the eleven names, those of the body the unknown name names first.
    assert ("choose from: rod.x, rod.y, rod.phi, rod.P, crank.x, crank.y, crank.phi, "
            "slider.x, slider.y, slider.phi and 1 more") in " ".join(result.stderr.split())
    assert not (tmp_path / "p.png").exists()


def test_generate_defaults_to_the_backend_run_uses(tmp_path: Path) -> None:
    made = symkin_cli("generate", str(TEXTBOOK), "-o", "c", cwd=tmp_path)
    assert made.returncode == 0 and (tmp_path / "c" / "crank_slider.c").exists()
    # without a C compiler, auto writes the NumPy module and says so
    made = symkin_cli("generate", str(TEXTBOOK), "-o", "py", cwd=tmp_path,
                      env={"CC": "no-such-compiler-here"})
    assert made.returncode == 0 and (tmp_path / "py" / "crank_slider.py").exists()
    assert "no C compiler found" in made.stderr
    # an explicit C request writes C source, which needs no compiler
    made = symkin_cli("generate", str(TEXTBOOK), "--backend", "c", "-o", "c2", cwd=tmp_path,
                      env={"CC": "no-such-compiler-here"})
    assert made.returncode == 0 and (tmp_path / "c2" / "crank_slider.c").exists()


def test_docs_walkthrough_is_the_drawn_example() -> None:
    """The drawn-layout page's walk-through file (docs/file-format/drawn.md) is valid and is
    the example file."""
    import yaml

    section = (ROOT / "docs" / "file-format" / "drawn.md").read_text(encoding="utf-8")
    start = section.index("```yaml") + len("```yaml")
    block = section[start:section.index("```\n", start)]
    from_readme = symkin.from_dict(yaml.safe_load(block))
    example = symkin.load(ROOT / "examples" / "crank_slider_drawn.yaml")
    assert from_readme.canonical_json() == example.canonical_json()
    assert from_readme.units == example.units


def test_at_columns_never_run_together() -> None:
    """The widest numbers %g prints (sign, 12 digits, a three-digit exponent) still leave a
    space between columns, so every row splits into its numbers."""
    import numpy as np

    from symkin.cli import run_outputs
    from symkin.runtime.outputs.results import Trajectory

    widest = np.array([[-1.23456789012e-100, -9.87654321098e-200, -1.1e-16]])
    trajectory = Trajectory(t=np.zeros(1), q=widest, dq=widest, d2q=widest,
                            coordinates=("b.x", "b.y", "b.phi"), points=(("b", "P"),),
                            point_vectors=np.array([[-1.234567891e-100, -2.5e-300]]))
    text = run_outputs.configuration(trajectory, "m", "numpy backend")
    for line in text.splitlines()[3:]:
        if line and not line.startswith("point"):
            assert all(np.isfinite(float(v)) for v in line.split()[1:]), line
