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


STEWART_FK = ROOT / "examples" / "stewart_fk.yaml"


def test_the_inputs_that_are_lengths_are_the_distance_drivers():
    from symkin.spec import name_checks, validate

    mech = validate.load(STEWART_FK)
    assert name_checks.length_inputs(mech) == tuple(f"leg{k}" for k in range(1, 7))
    crank = validate.load(ROOT / "examples" / "crank_slider_input.yaml")
    assert name_checks.length_inputs(crank) == ()  # an angle may be negative


def _legs_table(path: Path, negative_at: int | None) -> Path:
    rows = ["t," + ",".join(f"leg{k}" for k in range(1, 7))]
    for n in range(4):
        legs = ["1.1"] * 6
        if n == negative_at:
            legs[2] = "-1"
        rows.append(f"{n * 0.1:g}," + ",".join(legs))
    path.write_text("\n".join(rows) + "\n")
    return path


def test_a_negative_length_in_an_inputs_table_is_refused_at_its_line(tmp_path):
    from symkin.cli import input_table

    names = tuple(f"leg{k}" for k in range(1, 7))
    table = _legs_table(tmp_path / "u.csv", negative_at=2)
    with pytest.raises(input_table.TableError, match=r"u.csv:4: column leg3: -1 is negative"):
        input_table.read(table, names, lengths=names)
    assert input_table.read(table, names).u[2, 2] == -1  # not a length: an angle may be
    good = input_table.read(_legs_table(tmp_path / "v.csv", None), names, lengths=names)
    assert (good.u == 1.1).all()


def test_the_cli_refuses_a_negative_leg_before_solving(tmp_path, capsys):
    table = _legs_table(tmp_path / "u.csv", negative_at=1)
    status = cli.main(["run", str(STEWART_FK), "--backend", "numpy", "--inputs", str(table),
                       "-o", str(tmp_path / "out.csv")])
    err = capsys.readouterr().err
    assert status == 2 and "u.csv:3: column leg3: -1 is negative" in err, err
    assert not (tmp_path / "out.csv").exists()
