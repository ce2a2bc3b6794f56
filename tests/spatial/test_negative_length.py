"""A distance driver's f is a length: the row holds f squared, so a negative f was solved
silently as its absolute value (a Stewart leg's force then changes sign). A time function
negative anywhere on the file's grid is refused at its line, on both backends."""

from __future__ import annotations

from pathlib import Path

import pytest

from symkin import cli

ROOT = Path(__file__).resolve().parents[2]
STEWART = ROOT / "examples" / "stewart.yaml"


def _with_leg(tmp_path: Path, old: str, new: str) -> Path:
    text = STEWART.read_text()
    assert text.count(old) >= 1
    path = tmp_path / "stewart.yaml"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize("backend", ["numpy", "c"])
def test_a_leg_written_minus_sqrt_is_refused_at_its_line(tmp_path, capsys, backend):
    path = _with_leg(tmp_path, 'f: "sqrt(', 'f: "-sqrt(')
    status = cli.main(["run", str(path), "--backend", backend])
    err = capsys.readouterr().err
    assert status == 2, err
    assert f"{path}:19: at drivers[0].f: the length f is negative at t = 0" in err, err


def test_a_length_negative_only_late_in_the_grid_is_refused_there(tmp_path, capsys):
    # leg 1 as a plain function of t that crosses zero at t = 0.75 (the grid is 0 .. 1)
    text = STEWART.read_text()
    start = text.index('f: "sqrt(')
    end = text.index('"}', start)
    path = tmp_path / "stewart.yaml"
    path.write_text(text[:start] + 'f: "1.1*(0.75 - t)' + text[end:])
    status = cli.main(["show", str(path)])
    err = capsys.readouterr().err
    assert status == 2 and "the length f is negative at t = 0.755" in err, err
