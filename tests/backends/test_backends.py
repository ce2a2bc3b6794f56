"""A backend is one object handed down by the registry (symkin/backends/__init__.py).

A backend written here, through the protocol only (codegen.target.Target and
build.backend.Backend: a Python class and one template in tmp_path, reusing NumPy's printer),
is registered, generates, builds, loads and solves the crank-slider through the public API and
the CLI, and gives the NumPy backend's numbers. No module of symkin compares a backend's name.
"""

from __future__ import annotations

import ast
import sys
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from codegen_support import ROOT, system

import symkin
from symkin import backends, cli
from symkin.backends.numpy import naming
from symkin.build.cache import build_unless_verified, content_key
from symkin.codegen.target import Option, rendered_templates
from symkin.runtime.kernel import Kernel, import_file

# The whole template of the test backend: a module with META (what the runtime Kernel needs)
# and one function per routine the Kernel calls.
TEMPLATE = '''\
# {{ header | join("\\n# ") }}
import numpy

META = {"name": {{ name_literal }}, "coordinates": [{{ coordinate_literals | join(", ") }}],
        "parameter_names": [{{ parameter_literals | join(", ") }}],
        "p_values": [{{ p_literals | join(", ") }}], "q0": [{{ q0_literals | join(", ") }}],
        "time_grid": [{{ time_literals | join(", ") }}], "rows": [{{ row_literals | join(", ") }}],
        "pattern_rows": {{ pattern_rows }}, "pattern_cols": {{ pattern_cols }},
        "points": [{{ point_literals | join(", ") }}]}
{% for routine in routines if routine.name in ("phi", "phi_q", "phi_t", "gamma", "points",
                                               "phi_p") %}


def {{ routine.name }}({{ routine.arguments | join(", ") }}):
{% for name, value in routine.temporaries %}
    {{ name }} = {{ value }}
{% endfor %}
    return numpy.array([{{ routine.outputs | join(", ") }}], dtype=float)
{% endfor %}
'''


class _Functions:
    """The generated module as the runtime Kernel's functions."""

    def __init__(self, module: Any) -> None:
        self.phi, self.phi_q_nz, self.phi_t = module.phi, module.phi_q, module.phi_t
        self.gamma, self.points, self.phi_p_nz = module.gamma, module.points, module.phi_p


class TinyBackend:
    """A backend of its own: NumPy's printer, one template, a module per mechanism."""

    name = "tiny"
    title = "Tiny"
    options: tuple[Option, ...] = (Option("real", ("double",), "double", "double only"),)
    template_folder = "tiny"

    def __init__(self, root: Path) -> None:
        self._root = root

    @property
    def template_root(self) -> Path:
        return self._root

    def printer(self, options: Mapping[str, str]) -> Any:
        return backends.get("numpy").printer(options)

    def literal(self, options: Mapping[str, str]) -> Callable[[float], str]:
        return repr

    def precision(self, options: Mapping[str, str]) -> str:
        return options["real"]

    def templates(self, code: Any) -> list[str]:
        return rendered_templates(self._root / self.template_folder)

    def output_name(self, template: str, prefix: str) -> str:
        return f"{prefix}_tiny.py"

    def purpose(self, template: str) -> str:
        return "the tiny backend's kernel of {name}"

    def plans_lu(self, options: Mapping[str, str]) -> bool:
        return False

    def template_context(self, code: Any) -> dict[str, Any]:
        # Python string literals of the names: what NumPy's template also needs
        return naming.template_context(code)

    def routine_context(self, code: Any, routine: dict[str, Any]) -> dict[str, Any]:
        return {}

    def unavailable(self) -> str | None:
        return None

    def require(self) -> None:
        return None

    def fingerprint(self) -> dict[str, Any]:
        return {"python": sys.version}

    def build(self, files: dict[str, str], cache: Path) -> Kernel:
        name = next(n for n in files if n.endswith("_tiny.py")).removesuffix("_tiny.py")
        folder = cache / f"_symkin_{name}_tiny_{content_key({'files': files})[:20]}"
        build_unless_verified(cache, folder, files, lambda target: [
            (target / n).write_text(text, encoding="utf-8") for n, text in files.items()])
        return self.load(folder, {"name": name})

    def load(self, folder: Path, meta: Mapping[str, Any]) -> Kernel:
        module = import_file(folder.name, folder / f"{meta['name']}_tiny.py", None)
        return Kernel(self.name, module.META, _Functions(module), folder=folder)

    def loaded_files(self, folder: Path, name: str) -> list[str]:
        return [f"{name}_manifest.json", f"{name}_tiny.py"]


@pytest.fixture
def tiny(tmp_path: Path) -> Iterator[TinyBackend]:
    (tmp_path / "tiny").mkdir()
    (tmp_path / "tiny" / "kernel.py.j2").write_text(TEMPLATE)
    backend = TinyBackend(tmp_path)
    backends.register(backend)
    yield backend
    backends.unregister(backend.name)


def test_a_backend_registered_from_outside_solves_like_numpy(tiny: TinyBackend,
                                                             tmp_path: Path) -> None:
    crank_slider = system("crank_slider")
    kernel = symkin.compile(crank_slider, "tiny", cache_dir=tmp_path / "cache")
    assert kernel.backend == "tiny" and kernel.folder is not None
    reference = symkin.solve(symkin.compile(crank_slider, "numpy", cache_dir=tmp_path / "cache"))
    trajectory = symkin.solve(kernel)
    assert trajectory.q.shape == reference.q.shape
    for mine, theirs in ((trajectory.q, reference.q), (trajectory.dq, reference.dq),
                         (trajectory.d2q, reference.d2q)):
        np.testing.assert_allclose(mine, theirs, rtol=1e-12, atol=1e-12)
    # A built folder loads again by its manifest, through the registry.
    assert np.array_equal(backends.load(kernel.folder).phi(kernel.q0, 0.1),
                          kernel.phi(kernel.q0, 0.1))
    written = symkin.generate(crank_slider, "tiny", out_dir=tmp_path / "out")
    assert [p.name for p in written] == ["crank_slider_tiny.py", "crank_slider_manifest.json"]


def test_the_cli_offers_the_registered_backends(tiny: TinyBackend, tmp_path: Path) -> None:
    example = ROOT / "examples" / "crank_slider.yaml"
    assert cli.main(["generate", str(example), "--backend", "tiny", "-o",
                     str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "crank_slider_tiny.py").is_file()


def test_an_unknown_backend_is_refused_plainly(capsys: pytest.CaptureFixture[str],
                                               tmp_path: Path) -> None:
    with pytest.raises(symkin.BuildError, match="unknown backend 'fortran'; choose one of auto, c"):
        symkin.compile(system("crank_slider"), "fortran")
    example = ROOT / "examples" / "crank_slider.yaml"
    with pytest.raises(SystemExit) as exited:
        cli.main(["run", str(example), "--backend", "fortran", "-o", str(tmp_path / "r.npz")])
    assert exited.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'fortran'" in err and "Traceback" not in err
    with pytest.raises(symkin.BuildError, match="already registered"):
        backends.register(backends.get("c"))


# ----- no stage compares a backend's name ----------------------------------------------------

def name_comparisons(source: str, names: tuple[str, ...]) -> list[int]:
    """Lines of ``source`` that compare with (==, !=, in, not in) or match on a string literal
    naming a backend, alone or inside a literal tuple, list or set."""
    def names_one(node: ast.AST) -> bool:
        if isinstance(node, ast.Constant):
            return node.value in names
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            return any(names_one(e) for e in node.elts)
        return False

    lines = []
    for node in ast.walk(ast.parse(source)):
        compared = (isinstance(node, ast.Compare)
                    and any(map(names_one, [node.left, *node.comparators])))
        if compared or (isinstance(node, ast.MatchValue) and names_one(node.value)):
            lines.append(node.lineno)
    return lines


def test_the_check_finds_a_comparison() -> None:
    found = name_comparisons('if backend == "c" or kind in ("numpy", "x"):\n    pass\n'
                             'match b:\n    case "numpy":\n        pass\n', ("c", "numpy"))
    assert found == [1, 1, 4]
    assert not name_comparisons('real == "float"\nx = {"c": 1}\nf(modules="numpy")\n',
                                ("c", "numpy"))


def test_no_module_compares_a_backend_name() -> None:
    found = {f"{path.relative_to(ROOT)}:{line}"
             for path in sorted((ROOT / "symkin").rglob("*.py"))
             for line in name_comparisons(path.read_text(encoding="utf-8"), backends.names())}
    assert not found, f"ask the backend object instead of comparing its name: {sorted(found)}"
