"""Mutated mechanism files never crash symkin: they load (and derive), or raise MechanismError.

Hypothesis applies random edits to the text of the example files (delete, duplicate or insert
characters, swap lines) and checks that nothing but a MechanismError with a location comes out
of loading, and that whatever loads also derives.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from symkin.errors import MechanismError
from symkin.spec.validate import load
from symkin.symbolic.derivation import derive

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SOURCES = [(EXAMPLES / name).read_text() for name in ("crank_slider.yaml", "quick_return.yaml")]
PIECES = [":", " ", "\n", "-", "[", "]", "{", "}", ",", "'", '"', "&a", "*a", "!!", "#", "0",
          "1e-3", "yes", "t", "pi", "ground", "__", ".inf", "\t", "ż", "type: ", "crank"]


@st.composite
def mutated(draw) -> str:
    text = draw(st.sampled_from(SOURCES))
    for _ in range(draw(st.integers(1, 3))):
        position = draw(st.integers(0, len(text)))
        edit = draw(st.sampled_from(["delete", "insert", "duplicate", "swap"]))
        if edit == "delete":
            text = text[:position] + text[position + draw(st.integers(1, 8)):]
        elif edit == "insert":
            text = text[:position] + draw(st.sampled_from(PIECES)) + text[position:]
        elif edit == "duplicate":
            text = text[:position] + text[position:position + 12] + text[position:]
        else:
            lines = text.splitlines()
            k = draw(st.integers(0, len(lines) - 2))
            lines[k], lines[k + 1] = lines[k + 1], lines[k]
            text = "\n".join(lines) + "\n"
    return text


FOLDER = tempfile.TemporaryDirectory(prefix="symkin-fuzz-")


@settings(max_examples=120, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(mutated())
def test_mutated_file_loads_or_is_refused_with_a_location(text: str) -> None:
    path = Path(FOLDER.name) / "mutated.yaml"
    path.write_text(text, encoding="utf-8")
    try:
        mech = load(path)
    except MechanismError as error:
        assert error.source == str(path)
        assert str(error).startswith(str(path))
        return
    system = derive(mech)
    assert len(system.rows) == len(system.q)
