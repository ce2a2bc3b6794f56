"""Pytest helpers: put a hand derivation of a mechanism's kinematics under test in one line.

    from symkin.testing import assert_kinematics_match

    def test_my_derivation():
        assert_kinematics_match("four_bar.yaml", "four_bar_hand.py")

The comparison is :func:`symkin.verify.numeric.verify`; a mismatch fails with the report that
``symkin verify`` prints (every differing entry, its joint or driver, both values).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from symkin.spec.validate import Mechanism
from symkin.symbolic.derivation import System
from symkin.verify import numeric
from symkin.verify.report import Report


def assert_kinematics_match(mechanism: Mechanism | System | numeric.Derived | str | Path,
                            hand_module: Any, *, samples: int = numeric.DEFAULT_SAMPLES,
                            seed: int = 0, spread: float = numeric.DEFAULT_SPREAD,
                            tolerance: float = numeric.DEFAULT_TOLERANCE) -> Report:
    """Fail (AssertionError) unless the hand functions match the derived ones.

    Args:
        mechanism: a mechanism file, Mechanism, System or
            :func:`symkin.verify.numeric.derived_functions`.
        hand_module: a module (or any object) with some of ``phi``, ``phi_q``, ``phi_t``,
            ``gamma``, or the path of a Python file defining them.
        samples, seed, spread, tolerance: as for :func:`symkin.verify.numeric.verify`.

    Returns:
        The report, when everything matches.

    Raises:
        AssertionError: some entries differ; the message is the full report.
        symkin.verify.hand.HandModuleError: the hand module cannot be loaded, raises or returns the
            wrong shape (the original exception is its ``__cause__``).
    """
    __tracebackhide__ = True  # pytest shows the caller's line, not this helper's
    report = numeric.verify(mechanism, hand_module, samples=samples, seed=seed, spread=spread,
                            tolerance=tolerance)
    if not report.ok:
        raise AssertionError("hand derivation does not match the derived kinematics\n"
                             + report.text())
    return report
