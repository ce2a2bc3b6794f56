"""symkin verify --against HAND.m | FOLDER: the chapter's MATLAB program (Examples 2.5-2.8,
typed in from the textbook, examples/textbook_chapter2) checked in Octave against what symkin
derives for examples/crank_slider.yaml; planted slips are named by row, column and owner."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from symkin.cli import verify as verify_command
from symkin.cli.exits import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK

pytestmark = pytest.mark.skipif(shutil.which("octave-cli") is None,
                                reason="GNU Octave (octave-cli) is not on PATH")

ROOT = Path(__file__).resolve().parents[2]
CRANK_SLIDER = ROOT / "examples" / "crank_slider.yaml"
CHAPTER = ROOT / "examples" / "textbook_chapter2"


def _copy(tmp_path: Path) -> Path:
    folder = tmp_path / "chapter2"
    shutil.copytree(CHAPTER, folder)
    return folder


def _plant(path: Path, line: str, replacement: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert text.count(line) == 1
    path.write_text(text.replace(line, replacement), encoding="utf-8")


def _run(against: Path, samples: int = 8) -> tuple[int, str]:
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = verify_command.command(CRANK_SLIDER, against, samples=samples)
    return status, out.getvalue() + err.getvalue()


def test_the_chapters_program_passes() -> None:
    """Wiezy, Jakobian(q), Predkosc and Przyspieszenie as printed agree with the derivation
    at the chapter's data (its Dane.m and Rot.m found on Octave's path)."""
    status, text = _run(CHAPTER, samples=31)
    assert status == EXIT_OK, text
    for name, entries in (("Wiezy", 9), ("Jakobian", 81), ("Predkosc", 9),
                          ("Przyspieszenie", 9)):
        assert re.search(rf"{name}\s+{entries} entries  all match", text), text
    assert "31 assembled states" in text


def test_a_slip_in_one_entry_of_jakobian_is_named(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _plant(folder / "Jakobian.m", "Fq(9,3)=1;", "Fq(9,3)=-1;")
    status, text = _run(folder)
    assert status == EXIT_FAILED
    jakobian = [line for line in text.splitlines() if line.startswith("Jakobian(")]
    assert jakobian == ["Jakobian(9, 3): row 9 drivers[0] angle crank-ground (angle), "
                        "column 3 (d/d crank.phi)"]
    assert "Jakobian          81 entries  1 mismatching entry" in text


def test_a_slip_in_wiezy_is_named_by_row_and_joint(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _plant(folder / "Wiezy.m", "F(5:6,1)=r2+Rot2*sA2-(r3+Rot3*sB3);",
           "F(5:6,1)=r2+Rot2*sA2-(r3-Rot3*sB3)+[0;1e-3];")
    status, text = _run(folder / "Wiezy.m")
    assert status == EXIT_FAILED
    assert re.search(r"^Wiezy\(6\): row 6 joints\[2\] revolute rod-slider \(y\)$", text,
                     flags=re.MULTILINE), text
    assert "Wiezy(5)" not in text


def test_jakobian_of_q_and_t_is_accepted(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _plant(folder / "Jakobian.m", "function Fq=Jakobian(q)", "function Fq=Jakobian(q, t)")
    status, text = _run(folder / "Jakobian.m")
    assert status == EXIT_OK, text


def test_an_error_in_octave_is_reported_with_its_message(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _plant(folder / "Jakobian.m", "Fq(7,9)=1;", "Fq(7,9)=no_such_name;")
    status, text = _run(folder)
    assert status == EXIT_BAD_INPUT
    assert "'no_such_name' undefined" in text and "Jakobian" in text
    assert "Traceback" not in text and len(text) < 600


def test_a_wrong_shape_is_bad_input(tmp_path: Path) -> None:
    """A row where a column is meant is read as the column; a missing row is refused."""
    folder = _copy(tmp_path)
    _plant(folder / "Wiezy.m", "F(9,1)=fi1-t^2-pi/2;", "F(9,1)=fi1-t^2-pi/2; F=F';")
    status, text = _run(folder / "Wiezy.m")
    assert status == EXIT_OK, text
    _plant(folder / "Wiezy.m", "F=F';", "F=F(1:8);")
    status, text = _run(folder / "Wiezy.m")
    assert status == EXIT_BAD_INPUT
    assert "Wiezy(q, t) returned a 8 x 1 array, expected 9 (a column)" in text


def test_a_file_of_another_name_is_refused(tmp_path: Path) -> None:
    status, text = _run(CHAPTER / "Rot.m")
    assert status == EXIT_BAD_INPUT
    assert "Wiezy(q, t)" in text and "Rot.m" in text
    empty = tmp_path / "none"
    empty.mkdir()
    status, text = _run(empty)
    assert status == EXIT_BAD_INPUT and "holds none of" in text


def test_a_spread_is_refused_for_m_files_not_ignored(capsys: pytest.CaptureFixture) -> None:
    """.m hand functions take no parameters: a spread could not be applied, so --spread is
    refused (exit 2, before anything is derived); --spread 0 and no --spread check the
    nominal design."""
    from symkin import cli

    base = ["verify", str(CRANK_SLIDER), "--against", str(CHAPTER), "--samples", "3"]
    assert cli.main([*base, "--spread", "0.3"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "--spread 0.3" in err and "nominal design only" in err and "Traceback" not in err
    assert cli.main([*base, "--spread", "0"]) == EXIT_OK
    assert cli.main(base) == EXIT_OK
    assert "at the nominal" not in capsys.readouterr().err
