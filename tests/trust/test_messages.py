"""Messages located where the mistake is: a character YAML does not allow is named with its
line and column (YAML's reader says only its character position in the stream).

Reference: the place of the character in the text the test writes.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from symkin import cli


@pytest.mark.parametrize(("text", "line", "column", "code"),
                         [("name: x\nbodies:\n  b: {q0: [0, 0, 0]\x01}\n", 3, 20, "U+0001"),
                          ("name: x\n\x07\n", 2, 1, "U+0007")])
def test_a_control_character_is_located(text: str, line: int, column: int, code: str,
                                        tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "control.yaml"
    path.write_text(text, encoding="utf-8")
    assert cli.main(["show", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"control.yaml:{line}: this is not valid YAML: the character {code} at column " \
           f"{column} is not allowed" in err


def test_a_drawn_parameter_defined_from_another_is_blamed_at_its_line(
        capsys: pytest.CaptureFixture[str]) -> None:
    path = Path(__file__).resolve().parent / "drawn_parameter_from_parameter.yaml"
    line = path.read_text(encoding="utf-8").splitlines().index("  b: 5*a") + 1
    assert cli.main(["show", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"drawn_parameter_from_parameter.yaml:{line}: at parameters.b: in expression " \
           "'5*a' at column 3: unknown name 'a'" in err
    assert "A link too short" not in err
