"""What the generated C and the runtime must agree on is defined once, in symkin.contract, and
the templates render it: the values in the rendered C equal the contract's, no template spells
one of them as a bare number, and the manifest's writer and readers use the declared keys."""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import pytest
from codegen_support import ROOT, system

from symkin import backends
from symkin.codegen import render
from symkin.codegen.lower import lower
from symkin.contract import manifest, options, status, tuning

TEMPLATES = ROOT / "symkin" / "backends"
# A contract value behind its C cast, e.g. ((crank_slider_real)0.05); F: a float literal.
_CAST = re.compile(r"^\(\(\w+\)(.+)\)$")


def _c_value(text: str) -> float:
    text = text.strip()
    match = _CAST.match(text)
    text = match.group(1) if match else text
    return float(text.rstrip("Ff"))


def _defines(source: str, prefix: str) -> dict[str, str]:
    """``#define PREFIX_NAME value /* ... */`` -> {NAME: value}."""
    found = re.findall(rf"^#define {prefix.upper()}_(\w+) (.*?)\s*(?:/\*.*)?$", source, re.M)
    return dict(found)


@pytest.fixture(scope="module", params=["double", "float"])
def rendered(request: pytest.FixtureRequest) -> tuple[str, dict[str, str]]:
    code = lower(system("crank_slider"), backends.get("c"), {"real": request.param})
    return request.param, render.render_sources(code)


def test_status_codes_are_the_contracts(rendered: tuple[str, dict[str, str]]) -> None:
    _, files = rendered
    defines = _defines(files["crank_slider_solver.h"], "crank_slider")
    assert {name: int(defines[name]) for name in status.CODES} == status.CODES


def test_tuning_constants_are_the_contracts(rendered: tuple[str, dict[str, str]]) -> None:
    _, files = rendered
    defines = _defines(files["crank_slider_solver.c"], "crank_slider")
    assert {name: _c_value(defines[name]) for name in tuning.SHARED} == tuning.SHARED


def test_unit_roundoff_is_the_contracts(rendered: tuple[str, dict[str, str]]) -> None:
    real, files = rendered
    macro = _defines(files["crank_slider_solver.c"], "crank_slider")["UNIT_ROUNDOFF"]
    epsilon = {"DBL_EPSILON": 2.0**-52, "FLT_EPSILON": 2.0**-23}  # IEEE 754, as C99 5.2.4.2.2
    assert epsilon[macro] == tuning.UNIT_ROUNDOFF[real]


def test_default_options_are_the_contracts(rendered: tuple[str, dict[str, str]]) -> None:
    real, files = rendered
    body = files["crank_slider_solver.c"].split("_default_options(", 1)[1].split("}", 1)[0]
    assigned = re.findall(r"options->(\w+) = (.*?);", body)
    assert [field for field, _ in assigned] == list(options.C_FIELDS)
    defaults = options.c_defaults(real)
    assert defaults[options.LENGTH_UNIT] == 1.0  # the mechanism's own unit
    for field, literal in assigned:
        assert _c_value(literal) == pytest.approx(defaults[field], rel=1e-6), field


def test_options_struct_has_the_solver_fields(rendered: tuple[str, dict[str, str]]) -> None:
    """The C struct and the contract's fields, in order (backends.c.csolver copies them by name):
    the Options, then the length unit."""
    _, files = rendered
    struct = files["crank_slider_solver.h"].split("typedef struct {", 1)[1].split("}", 1)[0]
    fields = re.findall(r"^\s+\w+ (\w+);", struct, re.M)
    assert fields == [*options.SOLVER_FIELDS, options.LENGTH_UNIT] == list(options.C_FIELDS)


def test_no_template_spells_a_contract_value() -> None:
    """Every #define of a contract name, and every default option, is rendered: a bare number
    there would be a copy that nothing keeps equal to the runtime's."""
    names = "|".join([*status.CODES, *tuning.SHARED])
    define = re.compile(rf"#define \{{\{{ PREFIX }}}}_({names}) (.*?)(?:/\*|$)")
    copies = []
    for template in sorted(TEMPLATES.rglob("*.j2")):
        for number, line in enumerate(template.read_text(encoding="utf-8").splitlines(), 1):
            match = define.search(line)
            value = match.group(2) if match else None
            if match is None and re.search(r"options->\w+ = ", line) and "{{" not in line:
                value = line
            # a cast to the real type, (({{ rt }})10), renders nothing of the contract
            if value is not None and "{{" not in re.sub(r"\(\{\{ \w+ \}\}\)", "", value):
                copies.append(f"{template.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not copies, "bare contract values in templates:\n" + "\n".join(copies)


def test_manifest_has_the_declared_keys(tmp_path: Path) -> None:
    paths = render.generate(system("crank_slider"), backends.get("c"), out_dir=tmp_path)
    written = paths[-1]
    assert written.name == manifest.manifest_name("crank_slider")
    keys = set(json.loads(written.read_text(encoding="utf-8")))
    assert keys == manifest.KEYS - manifest.OPTIONAL_KEYS
    assert manifest.OPTIONAL_KEYS <= manifest.KEYS
    # An over-constrained file's manifest has its removed rows.
    paths = render.generate(system("parallelogram_extra_bar"), backends.get("c"),
                            out_dir=tmp_path / "redundant")
    assert set(json.loads(paths[-1].read_text(encoding="utf-8"))) == \
        manifest.KEYS - manifest.OPTIONAL_KEYS | {"removed"}
    # One with input drivers has their names.
    inputs = render.generate(system("crank_slider_input"), backends.get("c"),
                             out_dir=tmp_path / "inputs")[-1]
    assert set(json.loads(inputs.read_text(encoding="utf-8"))) == \
        manifest.KEYS - manifest.OPTIONAL_KEYS | {"input_names"}


def test_a_spatial_manifest_says_its_space(tmp_path: Path) -> None:
    spatial = system("rssr")
    written = render.generate(spatial, backends.get("c"), out_dir=tmp_path)[-1]
    data = json.loads(written.read_text(encoding="utf-8"))
    assert set(data) == manifest.KEYS - manifest.OPTIONAL_KEYS | {"space", "senses"}
    assert data["space"] == "3d"
    # its revolutes' and its angle driver's senses (what their rows leave ambiguous)
    assert data["senses"] == ["joints[0] crank_pivot revolute ground-crank (sense)",
                              "joints[1] rocker_pivot revolute ground-rocker (sense)",
                              "drivers[0] angle ground-crank (sense)"]


# The modules that read a manifest, and the names their manifest dicts go by.
READERS = ["symkin/runtime/kernel.py", "symkin/build/cache.py", "symkin/build/index.py",
           "symkin/sweeps/parallel.py", "symkin/codegen/render.py", "symkin/backends/__init__.py",
           "symkin/backends/c/loader.py", "symkin/backends/numpy/__init__.py"]
MANIFEST_NAMES = {"meta", "wanted", "data"}


def _keys_read(tree: ast.AST) -> set[str]:
    """String keys of meta["k"], meta.get("k"), json.loads(...)["k"] and wanted = {"k": ...}."""
    keys: set[str] = set()
    for node in ast.walk(tree):
        target: ast.expr | None = None
        key: ast.expr | None = None
        if isinstance(node, ast.Subscript):
            target, key = node.value, node.slice
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr == "get" and node.args):
            target, key = node.func.value, node.args[0]
        elif (isinstance(node, ast.Assign) and isinstance(node.value, ast.Dict)
              and any(isinstance(t, ast.Name) and t.id in MANIFEST_NAMES for t in node.targets)):
            keys |= {k.value for k in node.value.keys
                     if isinstance(k, ast.Constant) and isinstance(k.value, str)}
            continue
        named = isinstance(target, ast.Name) and target.id in MANIFEST_NAMES
        loaded = (isinstance(target, ast.Call) and isinstance(target.func, ast.Attribute)
                  and target.func.attr == "loads")
        if (named or loaded) and isinstance(key, ast.Constant) and isinstance(key.value, str):
            keys.add(key.value)
    return keys


@pytest.mark.parametrize("module", READERS)
def test_manifest_readers_ask_only_for_declared_keys(module: str) -> None:
    keys = _keys_read(ast.parse((ROOT / module).read_text(encoding="utf-8")))
    assert keys, f"{module}: no manifest key found; has the reader's variable been renamed?"
    assert keys <= manifest.KEYS, f"{module} reads undeclared keys {sorted(keys - manifest.KEYS)}"


def test_manifest_of_a_mechanism_with_forces_has_every_key(tmp_path: Path) -> None:
    paths = render.generate(system("crank_slider_load"), backends.get("c"), out_dir=tmp_path)
    assert set(json.loads(paths[-1].read_text(encoding="utf-8"))) == \
        manifest.KEYS - manifest.OPTIONAL_KEYS | manifest.DYNAMICS_KEYS
