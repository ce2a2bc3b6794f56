"""Compiled templates kept in the template root's __pycache__ (codegen.template_cache): a
later environment renders the same text from them, an edited template is compiled afresh,
and a root where nothing can be written renders as without a cache."""

from __future__ import annotations

from pathlib import Path

import jinja2

from symkin.codegen.template_cache import FOLDER, TemplateCache


def _render(root: Path, **context: object) -> str:
    environment = jinja2.Environment(loader=jinja2.FileSystemLoader(str(root)),
                                     undefined=jinja2.StrictUndefined,
                                     bytecode_cache=TemplateCache(str(root)))
    return environment.get_template("t.j2").render(context)


def test_a_later_environment_loads_what_the_first_compiled(tmp_path: Path) -> None:
    (tmp_path / "t.j2").write_text("{% for k in range(n) %}{{ k }};{% endfor %}")
    assert _render(tmp_path, n=3) == "0;1;2;"
    kept = list((tmp_path / FOLDER).iterdir())
    assert len(kept) == 1
    stamp = kept[0].stat().st_mtime_ns
    assert _render(tmp_path, n=4) == "0;1;2;3;"  # a fresh environment, from the cache
    assert kept[0].stat().st_mtime_ns == stamp  # loaded, not written again


def test_an_edited_template_is_compiled_afresh(tmp_path: Path) -> None:
    (tmp_path / "t.j2").write_text("a{{ n }}")
    assert _render(tmp_path, n=1) == "a1"
    (tmp_path / "t.j2").write_text("b{{ n }}")
    assert _render(tmp_path, n=1) == "b1"


def test_a_cache_folder_that_cannot_be_made_is_no_error(tmp_path: Path) -> None:
    (tmp_path / FOLDER).write_text("a file where the folder would be")
    (tmp_path / "t.j2").write_text("c{{ n }}")
    assert _render(tmp_path, n=2) == "c2"


def test_a_truncated_cache_file_is_compiled_again(tmp_path: Path) -> None:
    (tmp_path / "t.j2").write_text("d{{ n }}")
    assert _render(tmp_path, n=5) == "d5"
    for kept in (tmp_path / FOLDER).iterdir():
        kept.write_bytes(kept.read_bytes()[:20])
    assert _render(tmp_path, n=6) == "d6"
