"""Mechanism input: YAML read the YAML 1.2 way, TOML, the Python API and the JSON Schema."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import jsonschema
import numpy as np
import pydantic
import pytest
import sympy as sp

import symkin
from symkin import cli
from symkin.errors import MechanismError
from symkin.spec import loader
from symkin.spec.validate import from_dict, json_schema, load

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.yaml"))
CORPUS = ROOT / "tests" / "bad_mechanisms"

CRANK_SLIDER_TOML = """\
name = "crank_slider"
parameters = { a = 1.0, b = 5.0, c = 4.0 }

[bodies.crank]
q0 = [0, 0, 0]
points = { tip = ["a", 0] }

[bodies.rod]
q0 = [0, 0, 0]
points = { P = ["b", 0] }

[bodies.slider]
q0 = [0, 0, 0]

[[joints]]
type = "revolute"
i = "ground"
j = "crank"
sA = [0, 0]
sB = [0, 0]

[[joints]]
type = "revolute"
i = "crank"
j = "rod"
sA = "tip"
sB = [0, 0]

[[joints]]
type = "revolute"
i = "rod"
j = "slider"
sA = ["b", 0]
sB = [0, 0]

[[joints]]
type = "prismatic"
i = "slider"
j = "ground"
sA = [0, 0]
sB = [0, "c"]
v = [0, 1]
phi0 = 0

[[drivers]]
type = "angle"
i = "crank"
j = "ground"
theta = "t**2 + pi/2"

[time]
t0 = 0
t1 = 1.5
dt = 0.05
"""

CRANK_SLIDER_DICT = {
    "name": "crank_slider",
    "parameters": {"a": 1.0, "b": 5.0, "c": 4.0},
    "bodies": {"crank": {"q0": [0, 0, 0], "points": {"tip": ["a", 0]}},
               "rod": {"q0": [0, 0, 0], "points": {"P": ["b", 0]}},
               "slider": {"q0": [0, 0, 0]}},
    "joints": [
        {"type": "revolute", "i": "ground", "j": "crank", "sA": [0, 0], "sB": [0, 0]},
        {"type": "revolute", "i": "crank", "j": "rod", "sA": "tip", "sB": [0, 0]},
        {"type": "revolute", "i": "rod", "j": "slider", "sA": ["b", 0], "sB": [0, 0]},
        {"type": "prismatic", "i": "slider", "j": "ground", "sA": [0, 0], "sB": [0, "c"],
         "v": [0, 1], "phi0": 0},
    ],
    "drivers": [{"type": "angle", "i": "crank", "j": "ground", "theta": "t**2 + pi/2"}],
    "time": {"t0": 0, "t1": 1.5, "dt": 0.05},
}


# ----- YAML scalars: the YAML 1.2 core schema, not PyYAML's YAML 1.1 ---------------------------

@pytest.mark.parametrize("text,value", [
    ("1e-10", 1e-10),        # YAML 1.1 (PyYAML) reads this as the string '1e-10'
    ("2E3", 2000.0),
    ("-1.5e+2", -150.0),
    (".5", 0.5),
    ("1.", 1.0),
    ("+7", 7),
    ("-0", 0),
    ("yes", "yes"),          # YAML 1.1: True
    ("No", "No"),            # YAML 1.1: False
    ("on", "on"),
    ("off", "off"),
    ("y", "y"),
    ("1:20", "1:20"),        # YAML 1.1: the sexagesimal number 80
    ("1_000", "1_000"),      # YAML 1.1: 1000
    ("true", True),
    ("~", None),
    ("null", None),
    ("'1e-10'", "1e-10"),    # quoted scalars stay text
    ('"true"', "true"),
    ("!!float 1", 1.0),
    ("!!str 12", "12"),
])
def test_yaml_scalars_follow_yaml_1_2(text: str, value: object) -> None:
    data = loader.read_yaml(f"key: {text}\n", "<test>").data
    assert data == {"key": value}
    assert type(data["key"]) is type(value)


def test_exponent_numbers_reach_the_model_as_exact_numbers(tmp_path: Path) -> None:
    text = (ROOT / "examples" / "crank_slider.yaml").read_text()
    path = tmp_path / "exponent.yaml"
    path.write_text(text.replace("dt: 0.05", "dt: 5e-2").replace("a: 1.0", "a: 1e0"))
    system = symkin.derive(path)
    assert system.time_grid == (0.0, 1.5, 0.05)
    assert system.p_values[0] == 1.0


def test_yes_is_a_name_not_a_boolean(tmp_path: Path) -> None:
    text = (ROOT / "examples" / "crank_slider.yaml").read_text()
    path = tmp_path / "yes.yaml"
    path.write_text(text.replace("name: crank_slider", "name: yes"))
    assert load(path).name == "yes"


@pytest.mark.parametrize("text", ["!!int 1.5", "!!float true", "!!int false", "!!bool 1",
                                  "!!null 0"])
def test_a_tag_that_does_not_match_its_value_is_refused(text: str) -> None:
    with pytest.raises(MechanismError, match="does not match its tag"):
        loader.read_yaml(f"key: {text}\n", "<test>")


@pytest.mark.parametrize("text,fragment", [
    ("key: !custom 1\n", "the YAML tag '!custom' is not allowed"),
    ("key: !!binary aGk=\n", "is not allowed"),
    ("key: !!set {a, b}\n", "is not allowed"),
    ("? [a, b]\n: 1\n", "is not a name"),
    ("!!binary name: x\n", "the YAML tag 'tag:yaml.org,2002:binary' is not allowed"),  # a key
    ("!custom key: 1\n", "the YAML tag '!custom' is not allowed"),
])
def test_other_unsafe_yaml_is_refused(text: str, fragment: str) -> None:
    with pytest.raises(MechanismError) as caught:
        loader.read_yaml(text, "<test>")
    assert fragment in str(caught.value)


def test_oversized_file_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "big.yaml"
    path.write_text("# " + "x" * loader.MAX_FILE_BYTES + "\n")
    with pytest.raises(MechanismError, match="larger than"):
        load(path)


# ----- the same mechanism three ways -----------------------------------------------------------

def test_toml_yaml_and_python_give_the_same_mechanism(tmp_path: Path) -> None:
    path = tmp_path / "crank_slider.toml"
    path.write_text(CRANK_SLIDER_TOML)
    from_yaml = load(ROOT / "examples" / "crank_slider.yaml")
    from_toml = load(path)
    from_python = from_dict(CRANK_SLIDER_DICT)
    assert from_toml.spec_hash() == from_yaml.spec_hash() == from_python.spec_hash()
    phi_yaml = symkin.derive(from_yaml).phi
    phi_toml = symkin.derive(from_toml).phi
    assert sp.simplify(phi_yaml - phi_toml) == sp.zeros(9, 1)


def _numpy_numbers(node: Any) -> Any:
    """The same data with every number a numpy scalar and every vector a numpy array."""
    if isinstance(node, dict):
        return {key: _numpy_numbers(value) for key, value in node.items()}
    if isinstance(node, list):
        if all(isinstance(value, (int, float)) for value in node):
            return np.array(node)
        return [_numpy_numbers(value) for value in node]
    if isinstance(node, float):
        return np.float64(node)
    return np.int64(node) if isinstance(node, int) else node


def test_numpy_numbers_from_python_give_the_same_mechanism() -> None:
    # a designer builds variants with numpy: np.float64(1.0) was a SymPy TypeError traceback
    from_numpy = from_dict(_numpy_numbers(CRANK_SLIDER_DICT))
    assert from_numpy.spec_hash() == from_dict(CRANK_SLIDER_DICT).spec_hash()
    assert symkin.derive(from_numpy).p_values == (1.0, 5.0, 4.0)


def test_numpy_numbers_in_a_drawn_mechanism_from_python() -> None:
    drawn = loader.read(ROOT / "examples" / "crank_slider_drawn.yaml").data
    from_numpy = from_dict(_numpy_numbers(drawn))
    assert from_numpy.spec_hash() == from_dict(drawn).spec_hash()


def test_a_mapping_that_contains_itself_is_refused() -> None:
    looped: dict[str, Any] = dict(CRANK_SLIDER_DICT)
    looped["parameters"] = {"a": looped}
    with pytest.raises(MechanismError, match="nested more than"):
        from_dict(looped)


def test_toml_errors_name_file_line_and_field(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(CRANK_SLIDER_TOML.replace('sA = "tip"', 'sA = "toe"'))
    with pytest.raises(MechanismError) as caught:
        load(path)
    line = CRANK_SLIDER_TOML.splitlines().index('sA = "tip"') + 1
    assert str(caught.value).startswith(f"{path}:{line}: at joints[1].sA: body 'crank' has no "
                                        "point named 'toe'")


def test_toml_nested_array_of_tables_lines() -> None:
    text = "[[joints]]\ntype = 'revolute'\n[[joints]]\ntype = 'prismatic'\nv = [0, 1]\n"
    lines = loader.read_toml(text, "<test>").lines
    assert lines[("joints", 1, "v")] == 5
    assert lines[("joints", 0, "type")] == 2


def test_python_api_errors_name_the_field() -> None:
    bad = {**CRANK_SLIDER_DICT, "bodies": {**CRANK_SLIDER_DICT["bodies"],
                                           "rod": {"q0": [0, 0]}}}
    with pytest.raises(MechanismError) as caught:
        from_dict(bad)
    assert caught.value.path == ("bodies", "rod", "q0")
    assert str(caught.value).startswith("<mechanism>: at bodies.rod.q0: expected a vector of 3")


def test_python_api_accepts_tuples_and_is_frozen() -> None:
    data = {**CRANK_SLIDER_DICT, "bodies": {**CRANK_SLIDER_DICT["bodies"],
                                            "slider": {"q0": (0, 0, 0)}}}
    mech = from_dict(data)
    with pytest.raises(pydantic.ValidationError):
        mech.name = "other"  # type: ignore[misc]


def test_python_api_rejects_non_mapping() -> None:
    with pytest.raises(MechanismError, match="must be a mapping"):
        from_dict([1, 2])  # type: ignore[arg-type]


def test_package_level_api(crank_slider_path: Path) -> None:
    mech = symkin.load(crank_slider_path)
    system = symkin.derive(mech)
    assert system.coordinates[-1] == "slider.phi"
    assert system.q0 == (0.0,) * 9
    assert system.dof == 1


# ----- JSON Schema -----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def schema() -> dict:
    return json_schema()


@pytest.fixture(scope="module")
def validator(schema: dict) -> jsonschema.Draft202012Validator:
    return jsonschema.Draft202012Validator(schema)


def test_cli_schema_prints_the_json_schema(schema: dict,
                                           capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["schema"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == schema
    jsonschema.Draft202012Validator.check_schema(printed)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_every_example_satisfies_the_schema(validator, path: Path) -> None:
    validator.validate(loader.read(path).data)


@pytest.mark.parametrize("name", ["unknown_top_key.yaml", "unknown_joint_key.yaml",
                                  "vector_too_short.yaml", "q0_wrong_length.yaml",
                                  "boolean_number.yaml", "unknown_type.yaml", "missing_sB.yaml",
                                  "time_missing_t1.yaml", "empty_poly.yaml", "no_bodies.yaml"])
def test_schema_rejects_shape_errors(validator, name: str) -> None:
    assert not validator.is_valid(loader.read(CORPUS / name).data)
