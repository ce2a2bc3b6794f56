"""`symkin verify MECH --against hand.py`: the report, exit status 0 / 1 / 2, bad input shown
plainly (no traceback)."""

from __future__ import annotations

from pathlib import Path

import pytest

from symkin import cli

ROOT = Path(__file__).resolve().parents[2]
TEXTBOOK = str(ROOT / "examples" / "crank_slider_general.yaml")
FAITHFUL = str(ROOT / "examples" / "textbook_hand.py")
CORRECTED = str(ROOT / "examples" / "textbook_hand_corrected.py")
FOUR_BAR = str(ROOT / "tests" / "verify_cases" / "four_bar.yaml")
FOUR_BAR_HAND = ROOT / "tests" / "verify_cases" / "four_bar_hand.py"


def _run(capsys, *argv: str) -> tuple[int, str, str]:
    status = cli.main(["verify", *argv])
    out, err = capsys.readouterr()
    return status, out, err


def test_faithful_transcription_is_flagged_with_entry_and_joint(capsys) -> None:
    status, out, err = _run(capsys, TEXTBOOK, "--against", FAITHFUL)
    assert status == 1 and err == ""
    assert "gamma      9 entries  2 mismatching entries" in out
    assert "gamma[4]: row 4 joints[2] revolute rod-slider (x)" in out
    assert "gamma[5]: row 5 joints[2] revolute rod-slider (y)" in out
    assert "MISMATCH: 2 entries differ" in out


def test_corrected_transcription_passes(capsys) -> None:
    status, out, _ = _run(capsys, TEXTBOOK, "--against", CORRECTED)
    assert status == 0
    assert out.count("all match") == 4 and "OK: the hand derivation matches" in out


def test_at_the_nominal_design_the_slip_hides(capsys) -> None:
    status, out, _ = _run(capsys, TEXTBOOK, "--against", FAITHFUL, "--spread", "0")
    assert status == 0 and "at the nominal design" in out


def test_same_seed_same_report(capsys) -> None:
    first = _run(capsys, TEXTBOOK, "--against", FAITHFUL, "--seed", "7", "--samples", "20")
    second = _run(capsys, TEXTBOOK, "--against", FAITHFUL, "--seed", "7", "--samples", "20")
    assert first == second and "differs in 20 of 20 samples" in first[1]


def _bad(capsys, *argv: str) -> str:
    status, out, err = _run(capsys, *argv)
    assert status == 2, out + err
    assert "Traceback" not in out + err and out == ""
    return err


def _hand(tmp_path: Path, text: str) -> str:
    path = tmp_path / "hand.py"
    path.write_text(text)
    return str(path)


def test_missing_hand_file(capsys, tmp_path) -> None:
    err = _bad(capsys, FOUR_BAR, "--against", str(tmp_path / "nope.py"))
    assert "nope.py does not exist" in err


def test_hand_file_is_a_folder(capsys, tmp_path) -> None:
    # a folder is read as MATLAB/Octave hand files (tests/verify/test_verify_matlab.py)
    err = _bad(capsys, FOUR_BAR, "--against", str(tmp_path))
    assert "is a folder that holds none of" in err and ".py file" in err


def test_hand_file_with_a_syntax_error(capsys, tmp_path) -> None:
    err = _bad(capsys, FOUR_BAR, "--against", _hand(tmp_path, "def phi(q, t, p):\n  return (\n"))
    assert "running the file failed: SyntaxError" in err and "line " in err


def test_hand_file_that_fails_on_import(capsys, tmp_path) -> None:
    err = _bad(capsys, FOUR_BAR, "--against", _hand(tmp_path, "import numpy\nx = 1 / 0\n"))
    assert "ZeroDivisionError" in err and "line 2" in err


def test_hand_function_that_raises_is_named(capsys, tmp_path) -> None:
    text = FOUR_BAR_HAND.read_text().replace("g[8] = 1.0", "g[9] = 1.0")
    err = _bad(capsys, FOUR_BAR, "--against", _hand(tmp_path, text))
    assert "gamma(q, dq, t, p) raised IndexError" in err and "g[9] = 1.0" in err


def test_wrong_shape_is_reported(capsys, tmp_path) -> None:
    text = FOUR_BAR_HAND.read_text().replace("J = np.zeros((9, 9))", "J = np.zeros((9, 10))")
    err = _bad(capsys, FOUR_BAR, "--against", _hand(tmp_path, text))
    assert "phi_q(q, t, p) returned shape (9, 10), expected 9 x 9" in err


def test_non_numeric_result_is_reported(capsys, tmp_path) -> None:
    err = _bad(capsys, FOUR_BAR, "--against",
               _hand(tmp_path, "def phi_t(q, t, p):\n    return 'zero'\n"))
    assert "phi_t(q, t, p) returned str, not numbers" in err


def test_no_functions_defined(capsys, tmp_path) -> None:
    err = _bad(capsys, FOUR_BAR, "--against", _hand(tmp_path, "PHI = 1\n"))
    assert "defines none of phi(q, t, p)" in err


def test_a_name_that_is_not_a_function(capsys, tmp_path) -> None:
    err = _bad(capsys, FOUR_BAR, "--against", _hand(tmp_path, "phi_q = 3\n"))
    assert "phi_q is a int, not a function" in err


def test_hand_written_for_another_mechanism(capsys) -> None:
    err = _bad(capsys, str(ROOT / "examples" / "crank_slider.yaml"), "--against", FAITHFUL)
    assert "it declares PARAMETERS = a, b, c, sA0x" in err
    assert "the mechanism's parameters are a, b, c (in the order" in err


def test_undeclared_order_for_another_mechanism_fails_plainly(capsys, tmp_path) -> None:
    text = FOUR_BAR_HAND.read_text().replace("PARAMETERS = ", "_PARAMETERS = ").replace(
        "COORDINATES = ", "_COORDINATES = ")
    err = _bad(capsys, str(ROOT / "examples" / "crank_slider.yaml"), "--against",
               _hand(tmp_path, text))
    assert "raised ValueError" in err  # unpacking 3 parameters into 7 names


@pytest.mark.parametrize("option, value, message", [
    ("--samples", "0", "--samples 0: give at least 1"),
    ("--spread", "-1", "--spread -1.0: give a number >= 0"),
    ("--tolerance", "0", "--tolerance 0.0: give a positive number"),
])
def test_bad_options(capsys, option, value, message) -> None:
    assert message in _bad(capsys, FOUR_BAR, "--against", str(FOUR_BAR_HAND), option, value)


def test_bad_mechanism_file(capsys, tmp_path) -> None:
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: x\nbodies: {}\ntime: {t1: 1, dt: 0.1}\n")
    err = _bad(capsys, str(broken), "--against", str(FOUR_BAR_HAND))
    assert "broken.yaml" in err
