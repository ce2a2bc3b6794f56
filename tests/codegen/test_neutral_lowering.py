"""codegen.neutral: what lowering does the same for every backend (prepared expressions, each
part's CSE, op counts) is done once per System. A second backend of the same System makes no
CSE of its own and still writes its golden files byte for byte; the kept lowering is told apart
by the CSE switch and goes when its System is collected."""

from __future__ import annotations

import gc
from pathlib import Path

import pytest
import sympy as sp
from codegen_support import ROOT

import symkin
from symkin import backends
from symkin.codegen import lower, neutral

# masses and an applied torque: the dynamics step's "motion" routine is lowered too
NAME = "crank_slider_load"


def _fresh() -> symkin.System:
    return symkin.derive(symkin.load(ROOT / "examples" / f"{NAME}.yaml"))


def _files(folder: Path) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir())}


def test_a_second_backend_makes_no_cse_and_writes_its_golden(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch
                                                            ) -> None:
    system = _fresh()
    symkin.generate(system, backend="c", out_dir=tmp_path / "c")
    calls: list[int] = []
    real = sp.cse

    def counted(*args, **options):  # type: ignore[no-untyped-def]
        calls.append(1)
        return real(*args, **options)

    monkeypatch.setattr(sp, "cse", counted)
    symkin.generate(system, backend="numpy", out_dir=tmp_path / "numpy")
    assert calls == []
    for backend in ("c", "numpy"):
        assert _files(tmp_path / backend) == _files(ROOT / "generated" / NAME / backend)


def test_the_cse_switch_is_kept_apart() -> None:
    system, other = _fresh(), _fresh()
    numpy = backends.get("numpy")
    with_cse = lower.lower(system, numpy, cse=True)
    without = lower.lower(system, numpy, cse=False)
    assert without.ops == lower.lower(other, numpy, cse=False).ops
    assert without.ops != with_cse.ops


def test_the_kept_lowering_goes_with_its_system() -> None:
    system = _fresh()
    lower.lower(system, backends.get("numpy"))
    key = id(system)
    assert key in neutral._KEPT
    del system
    gc.collect()
    assert key not in neutral._KEPT
