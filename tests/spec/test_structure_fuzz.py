"""Structurally mutated mechanisms never crash symkin: they load (and derive) or raise a
MechanismError that names the file and line.

Where test_model_fuzz.py edits characters, this fuzzer edits the parsed structure of the
examples (planar and spatial, local and drawn, higher pairs, forces, input drivers) the way a
user gets a file wrong: a key deleted or duplicated, a value of the wrong type, a list where a
mapping belongs and back, NaN, infinite, huge and subnormal numbers, numpy scalars, and names
that mean something else (E, I, pi, S, N, lambda, C keywords, non-ASCII). Each of these once
gave a traceback (a spatial drawn file's parameters as a list, a joint named by a list, an
infinite drawn coordinate). Seeded; the number of cases is bounded for CI, more with
SYMKIN_FUZZ_EXAMPLES.
"""

from __future__ import annotations

import copy
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from symkin.errors import MechanismError
from symkin.spec import loader
from symkin.spec.validate import from_dict, load
from symkin.symbolic.derivation import derive

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
# small and quick to derive; between them every section of the file format
NAMES = ("crank_slider.yaml", "crank_slider_drawn.yaml", "crank_slider_input.yaml",
         "crank_slider_load.yaml", "four_bar_dynamics.yaml", "rack_linkage.yaml",
         "planetary.yaml", "whitworth_drawn.yaml", "rssr.yaml", "spatial_slider_crank.yaml",
         "cardan.yaml", "custom_driver.yaml", "parallelogram_extra_bar_loads.yaml")
SOURCES = {name: loader.read(EXAMPLES / name).data for name in NAMES}
NAMES_THAT_MEAN_SOMETHING = ["E", "I", "pi", "S", "N", "lambda", "int", "while", "t", "ground",
                             "sin", "oo", "zoo", "nan", "double", "ż", "", "a b", "1a"]
ODD_VALUES = [float("nan"), float("inf"), -float("inf"), 1e308, 1e-300, 0, -1, True, None, "",
              "nan", "1e400", "t", "E**I", "acos(2)", "1/0", "x**", "2**2**2**2**2", [], {},
              [1], [1, 2, 3, 4], {"a": 1}, [[1, 2]], {"poly": [0, "t", -0.5]}, {"poly": []},
              {"input": None}, "input", np.float64(1.5), np.int64(2), np.float32(0.5)]
CASES = int(os.environ.get("SYMKIN_FUZZ_EXAMPLES", "100"))
FOLDER = tempfile.TemporaryDirectory(prefix="symkin-structure-fuzz-")


def _places(node: Any, path: tuple = ()) -> list[tuple]:
    """Every path to a value inside the data (not the root)."""
    found = [path] if path else []
    if isinstance(node, dict):
        for key, value in node.items():
            found += _places(value, path + (key,))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            found += _places(value, path + (index,))
    return found


def _renamed(node: Any, old: str, new: str) -> Any:
    """The data with the key ``old`` renamed everywhere and plain references to it too."""
    if isinstance(node, dict):
        return {(new if key == old else key): _renamed(value, old, new)
                for key, value in node.items()}
    if isinstance(node, list):
        return [_renamed(value, old, new) for value in node]
    return new if node == old else node


def _edit(draw: Any, data: Any) -> Any:
    place = draw(st.sampled_from(_places(data)))
    parent = data
    for part in place[:-1]:
        parent = parent[part]
    key, value = place[-1], parent[place[-1]]
    edit = draw(st.sampled_from(["delete", "duplicate", "odd", "flip", "rename", "scale"]))
    if edit == "delete":
        del parent[key]
    elif edit == "duplicate" and isinstance(parent, list):
        parent.insert(key, copy.deepcopy(value))
    elif edit == "flip":  # a list where a mapping belongs, and back
        parent[key] = ({str(k): v for k, v in enumerate(value)} if isinstance(value, list)
                       else [[k, v] for k, v in value.items()] if isinstance(value, dict)
                       else [value])
    elif edit == "rename" and isinstance(parent, dict) and isinstance(key, str):
        return _renamed(data, key, draw(st.sampled_from(NAMES_THAT_MEAN_SOMETHING)))
    elif edit == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
        parent[key] = value * draw(st.sampled_from([1e-9, -1, 0, 1e9, 1e200]))
    else:
        parent[key] = draw(st.sampled_from(ODD_VALUES))
    return data


@st.composite
def mutated(draw: Any) -> tuple[str, Any]:
    name = draw(st.sampled_from(NAMES))
    data = copy.deepcopy(SOURCES[name])
    for _ in range(draw(st.integers(1, 3))):
        data = _edit(draw, data)
    return name, data


def _as_yaml(data: Any) -> str:
    """YAML text of the data (numpy scalars written as the numbers they are)."""
    def plain(node: Any) -> Any:
        if isinstance(node, dict):
            return {key: plain(value) for key, value in node.items()}
        if isinstance(node, list):
            return [plain(value) for value in node]
        return node.item() if isinstance(node, np.generic) else node
    return yaml.safe_dump(plain(data), allow_unicode=True, sort_keys=False)


@seed(2029)
@settings(max_examples=CASES, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(mutated())
def test_mutated_structure_loads_or_is_refused_with_a_location(case: tuple[str, Any]) -> None:
    name, data = case
    path = Path(FOLDER.name) / name
    path.write_text(_as_yaml(data), encoding="utf-8")
    try:
        mech = load(path)
    except MechanismError as error:
        assert error.source == str(path) and error.line is not None, str(error)
        assert str(error).startswith(f"{path}:{error.line}: ")
        return
    system = derive(mech)
    assert len(system.rows) == len(system.q)


@seed(2030)
@settings(max_examples=CASES // 3, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(mutated())
def test_mutated_structure_from_python_is_refused_or_derived(case: tuple[str, Any]) -> None:
    # the same through symkin.from_dict, numpy scalars as they are: a MechanismError or a System
    _, data = case
    try:
        mech = from_dict(data, source="<designer's dict>")
    except MechanismError as error:
        assert error.source == "<designer's dict>", str(error)
        return
    derive(mech)
