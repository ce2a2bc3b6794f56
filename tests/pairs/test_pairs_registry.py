"""The pair registry is the one place that knows the pair and driver types: each type's name is
written in its own module only (elsewhere a few of the words mean something else, listed
below), every module under symkin/pairs/planar is registered, and the schema, the messages and
the derivation take every registered type."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import symkin
from symkin import pairs
from symkin.errors import MechanismError
from symkin.spec.validate import json_schema

PACKAGE = Path(symkin.__file__).resolve().parent
PLANAR = PACKAGE / "pairs" / "planar"
SPATIAL = PACKAGE / "pairs" / "spatial"

# Words that are also a type's name but mean something else where they are written.
OTHER_MEANINGS = {
    ("angle", "pairs/planar/prismatic.py"),  # the name of its first row
    ("angle", "spec/drawn.py"),  # a drawn frame's key
    ("angle", "present/series.py"),  # the kind of a plotted quantity
    ("slide", "present/html.py"),  # the legend group of slide axes
}


def _string_constants(path: Path) -> set[str]:
    return {node.value for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
            if isinstance(node, ast.Constant) and isinstance(node.value, str)}


def _spatial_modules() -> dict[str, set[str]]:
    """Type name -> the spatial modules that define a type of that name."""
    owners: dict[str, set[str]] = {}
    for path in SPATIAL.glob("*.py"):
        module = importlib.import_module(f"symkin.pairs.spatial.{path.stem}")
        if hasattr(module, "TYPE"):
            owners.setdefault(module.TYPE.name, set()).add(f"pairs/spatial/{path.stem}.py")
    return owners


def test_each_type_name_is_written_in_its_own_module_only() -> None:
    names = {kind.name for kind in (*pairs.TYPES, *pairs.SPATIAL_TYPES)}
    found: dict[str, set[str]] = {name: set() for name in names}
    for path in PACKAGE.rglob("*.py"):
        where = path.relative_to(PACKAGE).as_posix()
        for name in _string_constants(path) & names:
            if (name, where) not in OTHER_MEANINGS:
                found[name].add(where)
    planar = {kind.name for kind in pairs.TYPES}
    spatial = _spatial_modules()
    assert found == {name: ({f"pairs/planar/{name}.py"} if name in planar else set())
                     | spatial.get(name, set()) for name in names}


def test_every_spatial_module_with_a_type_is_registered() -> None:
    registered = {kind.model for kind in pairs.SPATIAL_TYPES}
    for path in SPATIAL.glob("*.py"):
        module = importlib.import_module(f"symkin.pairs.spatial.{path.stem}")
        if hasattr(module, "TYPE"):
            assert module.TYPE.model in registered, path.stem


def test_every_pair_module_is_registered_once() -> None:
    modules = sorted(path.stem for path in PLANAR.glob("*.py") if path.stem != "__init__")
    registered = [importlib.import_module(f"symkin.pairs.planar.{stem}").TYPE
                  for stem in modules]
    assert sorted(kind.name for kind in pairs.TYPES) == modules
    assert all(kind in pairs.TYPES for kind in registered)
    assert len({kind.name for kind in pairs.TYPES}) == len(pairs.TYPES)


def test_schema_offers_each_type_in_its_sections() -> None:
    schema = json_schema()
    text = repr(schema)
    for kind in pairs.TYPES:
        assert f"'const': '{kind.name}'" in text or f"'enum': ['{kind.name}']" in text


@pytest.mark.parametrize("section", pairs.SECTIONS)
def test_a_missing_type_lists_the_registered_ones(section: str) -> None:
    data = {"name": "m", "bodies": {"b": {}}, "time": {"t1": 1, "dt": 0.1},
            section: [{"i": "ground", "j": "b"}]}
    with pytest.raises(MechanismError) as caught:
        symkin.from_dict(data)
    listed = ", ".join(kind.name for kind in pairs.in_section(section))
    assert f"Add type: one of {listed}." in str(caught.value)
    assert ("distance" in listed) == (section == "joints")
