"""The gallery runs an example with a table of inputs only where a driver's function is
written ``input``: a joint or body named ``input`` (the Cardan's input shaft) is no input
driver (the full build of .ci/run stopped on it)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from docs_support import DOCS, ROOT

_SPEC = importlib.util.spec_from_file_location(
    "symkin_docs_gallery", DOCS / "_ext" / "symkin_docs" / "gallery.py")
assert _SPEC is not None and _SPEC.loader is not None
gallery = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(gallery)


def test_input_drivers_are_found_by_their_function_alone() -> None:
    found = {p.stem for p in sorted((ROOT / "examples").glob("*.yaml")) if gallery.has_inputs(p)}
    assert found == {"crank_slider_input", "delta_fk", "stewart_fk", "stewart_legs_fk",
                     "three_rrr_fk"}


def test_a_joint_named_input_is_no_input_driver(tmp_path: Path) -> None:
    text = (ROOT / "examples" / "cardan.yaml").read_text(encoding="utf-8")
    assert "joint: input" in text  # the file this guards still names its joint so
    assert not gallery.has_inputs(ROOT / "examples" / "cardan.yaml")
    driven = tmp_path / "driven.yaml"
    driven.write_text(text.replace('theta: "2*pi*t"', "theta: input"), encoding="utf-8")
    assert gallery.has_inputs(driven)
