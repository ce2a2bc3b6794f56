"""A performance guard: instruction counts (callgrind; they do not move with the machine's
load, unlike times) of the crank-slider's generated step, of one ``symkin.solve`` call and of
the generated ``<prefix>_dynamics_step`` of the two examples with masses and drivers,
against the budgets committed in bench/budgets.json with their margins. A change that costs
more fails here and says so in its diff by raising the budget.

Skipped only where valgrind is missing (CI installs it: .ci/run)."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
import dynamics_instructions  # noqa: E402
import instructions  # noqa: E402

BUDGETS = json.loads((ROOT / "bench" / "budgets.json").read_text())

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(shutil.which("valgrind") is None or
                                 shutil.which("callgrind_annotate") is None,
                                 reason="valgrind (callgrind) is not installed")]


def _within(name: str, count: float) -> None:
    entry = BUDGETS[name]
    limit = entry["budget"] * (1 + entry["margin"])
    assert count <= limit, (f"{name}: {count:.0f} instructions, over the budget "
                            f"{entry['budget']} + {entry['margin']:.0%} (measure: "
                            f"{entry['measure']}); make it cheaper or raise the budget in "
                            "bench/budgets.json")


def test_the_crank_slider_step_keeps_its_budget():
    _, _, count = instructions.per_step("crank_slider")
    _within("crank_slider_step", count)


def test_one_solve_call_keeps_its_budget(tmp_path):
    _within("crank_slider_solve_call", instructions.per_solve_call("crank_slider", tmp_path))


@pytest.mark.parametrize(("example", "name"), [
    ("four_bar_dynamics", "four_bar_dynamics_step"),
    ("crank_slider_load", "crank_slider_load_dynamics_step")])
def test_the_dynamics_step_keeps_its_budget(example: str, name: str, tmp_path: Path) -> None:
    built = dynamics_instructions.program(example, tmp_path)
    _within(name, dynamics_instructions.count(built, 100, "dynamics"))
