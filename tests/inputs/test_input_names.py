"""Each input's value, rate and acceleration are found by name (a column of the inputs table,
a key of inputs=), so a file whose inputs share a name, or name one as another's rate, is
refused where it is read: before, v and v_t were one SymPy symbol (v_t read v's rate), and a
vector driver's p_x and an angle driver named p_x read one value."""

from __future__ import annotations

from pathlib import Path

import pytest

import symkin
from symkin.errors import MechanismError

ROOT = Path(__file__).resolve().parents[2]


def _renamed(tmp_path: Path, *renames: tuple[str, str]) -> Path:
    text = (ROOT / "examples" / "three_rrr_fk.yaml").read_text()
    for old, new in renames:
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "renamed.yaml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("renames, says", [
    ((("name: theta1", "name: v"), ("name: theta2", "name: v_t")),
     "the input 'v_t' and the rate of the input 'v'"),
    ((("name: theta1", "name: v_t"), ("name: theta2", "name: v")),
     "the rate of the input 'v' and the input 'v_t'"),
    ((("name: theta1", "name: v"), ("name: theta2", "name: v_tt")),
     "the input 'v_tt' and the acceleration of the input 'v'"),
])
def test_inputs_named_as_another_inputs_rate_are_refused(tmp_path: Path, renames, says: str
                                                         ) -> None:
    with pytest.raises(MechanismError, match="share the name") as caught:
        symkin.derive(_renamed(tmp_path, *renames))
    assert says in str(caught.value) and "drivers[1]" in str(caught.value)


def test_a_vector_drivers_component_and_a_driver_of_that_name_are_refused(tmp_path: Path
                                                                         ) -> None:
    path = tmp_path / "pen.yaml"
    path.write_text(
        "name: pen\n"
        "bodies:\n  pen: {q0: [0, 0, 0]}\n"
        "drivers:\n"
        "  - {type: displacement, name: p, i: ground, j: pen, sA: [0, 0], sB: [0, 0], "
        "f: [input, input]}\n"
        "  - {type: angle, name: p_x, i: pen, j: ground, theta: input}\n"
        "time: {t0: 0, t1: 1, dt: 0.1}\n")
    with pytest.raises(MechanismError, match="the input 'p_x' and the input 'p_x' at "
                                             r"drivers\[0\].f\[0\] share the name"):
        symkin.derive(path)


def test_inputs_of_distinct_names_still_derive(tmp_path: Path) -> None:
    system = symkin.derive(_renamed(tmp_path, ("name: theta1", "name: v"),
                                    ("name: theta2", "name: w")))
    assert system.input_names == ("v", "w", "theta3")
