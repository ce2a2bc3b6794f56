"""A performance guard for the inverse dynamics of a spatial mechanism: the instructions a
step of the generated grid loop adds when it writes the multipliers, efforts and reactions
(callgrind, bench/forces_instructions.py: the spatial slider-crank with masses, inertia
tensors, offset centres and four kinds of load), against the budget committed in
bench/budgets.json with its margin. It was 4,264 (0.70x the kinematic step) when M q̈ + h was
formed from the 7 x 7 blocks; a change that costs more says so by raising the budget.

Skipped only where valgrind is missing (CI installs it: .ci/run)."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest
from codegen_support import derived, sources

ROOT = Path(__file__).resolve().parents[2]
FORCES = ROOT / "bench" / "spatial_slider_crank_forces.yaml"
sys.path.insert(0, str(ROOT / "bench"))
import forces_instructions  # noqa: E402

BUDGET = json.loads((ROOT / "bench" / "budgets.json").read_text())["spatial_forces_extra"]

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(shutil.which("valgrind") is None,
                                 reason="valgrind (callgrind) is not installed")]


def test_spatial_forces_keep_their_budget() -> None:
    # the System and C files that tests/dynamics/test_spatial_forces.py and the 3D report's
    # tests build from the same file, derived and generated once per run
    _, kinematic, with_forces = forces_instructions.per_step(
        "spatial_slider_crank_forces", derived(FORCES), sources(FORCES, "c"))
    extra = with_forces - kinematic
    limit = BUDGET["budget"] * (1 + BUDGET["margin"])
    assert extra <= limit, (f"the spatial forces add {extra:.0f} instructions a step, over the "
                            f"budget {BUDGET['budget']} + {BUDGET['margin']:.0%} (measure: "
                            f"{BUDGET['measure']}); make them cheaper or raise the budget in "
                            "bench/budgets.json")
