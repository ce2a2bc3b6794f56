"""In a drawn pin-in-slot pair written with ``at: A`` where both bodies list A, the slotted
body's copy is a material point of that body that stays where it was drawn; it is named
``A@slot`` (symkin/spec/drawn_slots.py) so that results never show two points called A that
come apart (a user took their gap for a 1.6 m error)."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import yaml
from codegen_support import derived
from driver_support import kernel_for

import symkin

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _whitworth_with_a_on_the_lever() -> dict:
    data = yaml.safe_load((EXAMPLES / "whitworth_drawn.yaml").read_text())
    data["bodies"]["lever"]["points"]["A"] = [2, 1]
    return data


def test_the_slotted_copy_is_named_apart_and_stays_on_its_body(tmp_path: Path) -> None:
    system = symkin.derive(symkin.from_dict(_whitworth_with_a_on_the_lever()))
    assert ("lever", "A@slot") in [(body, name) for body, name, _ in system.points]
    assert ("lever", "A") not in [(body, name) for body, name, _ in system.points]
    run = symkin.solve(kernel_for(system, "numpy"))
    pin, _, _ = run.point("crank", "A")
    copy, _, _ = run.point("lever", "A@slot")
    # the copy is the lever's point at sqrt(5) from O4 along the slot; the pin slides past it
    assert np.abs(np.hypot(*copy.T) - math.sqrt(5)).max() < 1e-12
    assert np.abs(pin - copy).max() > 1.0
    header = next(csv.reader(run.save(tmp_path / "w.csv").open()))
    assert "lever.A@slot_x" in header and "crank.A_x" in header
    assert "lever.A_x" not in header


def test_without_the_copy_nothing_is_renamed() -> None:
    system = derived(EXAMPLES / "whitworth_drawn.yaml")  # the run's shared derivation
    assert not any("@" in name for _, name, _ in system.points)
