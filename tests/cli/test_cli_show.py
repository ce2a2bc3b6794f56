"""`symkin show` on the textbook crank-slider: it reads as Example 2.5 (a)-(d), (h).

The expected rows below are written from the chapter (Example 2.5 / 2.7), not from symkin.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from codegen_support import EXAMPLES, derived

from symkin import cli
from symkin.symbolic import show

ROOT = Path(__file__).resolve().parents[2]

LABELS = [
    "joints[0] revolute ground-crank (x)", "joints[0] revolute ground-crank (y)",
    "joints[1] revolute crank-rod (x)", "joints[1] revolute crank-rod (y)",
    "joints[2] revolute rod-slider (x)", "joints[2] revolute rod-slider (y)",
    "joints[3] prismatic slider-ground (angle)",
    "joints[3] prismatic slider-ground (perpendicular)",
    "drivers[0] angle crank-ground (angle)",
]
# Example 2.5 (a): Phi, as sympy prints it (sstr orders terms alphabetically).
PHI = ["-crank.x", "-crank.y", "a*cos(crank.phi) + crank.x - rod.x",
       "a*sin(crank.phi) + crank.y - rod.y", "b*cos(rod.phi) + rod.x - slider.x",
       "b*sin(rod.phi) + rod.y - slider.y", "slider.phi", "c - slider.y",
       "crank.phi - t**2 - pi/2"]
# Example 2.5 (h): Gamma, with the angular rates written crank.phi'.
GAMMA = ["0", "0", "a*crank.phi'**2*cos(crank.phi)", "a*crank.phi'**2*sin(crank.phi)",
         "b*rod.phi'**2*cos(rod.phi)", "b*rod.phi'**2*sin(rod.phi)", "0", "0", "2"]
PHI_T = ["0"] * 8 + ["-2*t"]
# The structural non-zeros of Example 2.5 (c), by hand: row -> columns.
PATTERN = ["x........", ".x.......", "x.xx.....", ".xx.x....", "...x.xx..", "....xx.x.",
           "........x", ".......x.", "..x......"]


@pytest.fixture(scope="module")
def text_report(crank_slider_path: Path) -> str:
    return _run_show([str(crank_slider_path)])


@pytest.fixture(scope="module")
def latex_report(crank_slider_path: Path) -> str:
    return _run_show(["--latex", str(crank_slider_path)])


def _run_show(arguments: list[str]) -> str:
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main(["show", *arguments]) == 0
    return out.getvalue()


def _section(report: str, title: str) -> list[str]:
    """The lines of one section of the text report (after 'title:' up to a blank line)."""
    lines = report.splitlines()
    start = lines.index(title + ":") + 1
    end = lines.index("", start) if "" in lines[start:] else len(lines)
    return lines[start:end]


def _labelled(lines: list[str]) -> list[tuple[str, str]]:
    """Split '  [r] label  value' into (label, value), checking r counts up from 0."""
    result = []
    for r, line in enumerate(lines):
        match = re.fullmatch(r"  \[(\d+)\] (.+?)  +(.+)", line)
        assert match, line
        assert int(match.group(1)) == r
        result.append((match.group(2).strip(), match.group(3)))
    return result


def test_dof_and_sizes_are_printed(text_report: str) -> None:
    assert text_report.splitlines()[0] == \
        "mechanism crank_slider: 9 coordinates, 9 equations, 1 degree(s) of freedom"


def test_coordinates_and_parameters(text_report: str) -> None:
    assert _section(text_report, "coordinates q") == [
        f"  q[{k}] = {body}.{c}" for k, (body, c) in enumerate(
            (b, c) for b in ("crank", "rod", "slider") for c in ("x", "y", "phi"))]
    assert _section(text_report, "parameters p") == ["  p[0] = a = 1", "  p[1] = b = 5",
                                                     "  p[2] = c = 4"]


@pytest.mark.parametrize("title,expected", [("Phi", PHI), ("Phi_t", PHI_T), ("Gamma", GAMMA)])
def test_rows_are_labelled_with_their_joint_or_driver(text_report: str, title: str,
                                                      expected: list[str]) -> None:
    rows = _labelled(_section(text_report, title))
    assert [label for label, _ in rows] == LABELS
    assert [value for _, value in rows] == expected


def test_jacobian_pattern_and_entries(text_report: str) -> None:
    pattern = _section(text_report, "Phi_q pattern (17 non-zeros)")
    assert pattern == [f"  [{r}] {row}" for r, row in enumerate(PATTERN)]
    entries = _section(text_report, "Phi_q entries")
    assert len(entries) == 17
    assert "  (2,2) d/d crank.phi: -a*sin(crank.phi)" in entries
    assert "  (5,5) d/d rod.phi: b*cos(rod.phi)" in entries
    assert "  (7,7) d/d slider.y: -1" in entries


def test_latex_report(latex_report: str) -> None:
    assert "Mechanism \\texttt{crank\\_slider}: 9 coordinates, 9 equations, 1 degree(s) of " \
           "freedom." in latex_report
    for label in LABELS:
        assert f"& {label} \\\\" in latex_report
    for title in ("\\Phi =", "\\Phi_{\\mathbf{q}} =", "\\Phi_t =", "\\Gamma ="):
        assert title in latex_report
    assert latex_report.count("\\begin{equation}") == latex_report.count("\\end{equation}") == 5
    assert "\\dot{\\varphi_{\\mathrm{crank}}}^{2} a \\cos{\\left(\\varphi_{\\mathrm{crank}}" \
        in latex_report
    assert "- t^{2} - \\frac{\\pi}{2}" in latex_report


def test_python_m_symkin_show_from_another_directory(tmp_path: Path,
                                                   crank_slider_path: Path) -> None:
    result = subprocess.run([sys.executable, "-m", "symkin", "show", str(crank_slider_path)],
                            capture_output=True, text=True, timeout=120, cwd=tmp_path, check=False,
                            env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert result.stdout.splitlines()[0].endswith("1 degree(s) of freedom")


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_show_every_example(path: Path) -> None:
    """show's text and LaTeX reports of each example's System: the run's shared derivation
    (codegen_support.derived), which `symkin show` prints as it is; the command's own path
    from the file is taken by the textbook's reports above."""
    system = derived(path)
    report = show.text(system)
    sizes = re.fullmatch(r"mechanism \w+: (\d+) coordinates, (\d+) equations, \d+ "
                         r"degree\(s\) of freedom", report.splitlines()[0])
    assert sizes and sizes.group(1) == sizes.group(2)
    latex = show.latex(system)
    assert "\\Gamma =" in latex
