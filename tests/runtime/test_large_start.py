"""The start check at every size: a regular mechanism of hundreds of bodies is not a singular
start although its condition grows with its size, and what a singular start of such a
mechanism says names at most ten joints and rows.

The reference is the lazy tongs of bench/scaling_limit.py, whose motion has a closed form
there (every bar's centre and angle from the driven angle alpha): its scaled condition grows
as the square of its size (0.44 n^2 for n coordinates, measured from 30 to 3000), with no
configuration anywhere near singular. To keep the test fast it is built at 50 units (300
coordinates, condition 3.9e4) and judged with max_cond = 1e5, whose small-mechanism threshold
(max_cond / 10 = 1e4) that condition exceeds, as the default's 1e5 is exceeded by the tongs
from 80 units on. Closed flat (alpha = pi/2) every scissor's three pins lie on one line:
singular.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import symkin
from symkin.contract.options import Options
from symkin.limits import MAX_LISTED, listed
from symkin.runtime.solving import edges, failures, start
from symkin.spec import validate

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import scaling_limit

UNITS = 50
OPTIONS = Options(max_cond=1e5)


@pytest.fixture(scope="module")
def tongs():
    return symkin.compile(symkin.derive(validate.from_dict(scaling_limit.tongs(UNITS))),
                          backend="numpy")


def _state(alpha: float) -> np.ndarray:
    """q of the tongs at the driven angle alpha (the closed form of bench/scaling_limit.py)."""
    h, c, s = scaling_limit.HALF, math.cos(alpha), math.sin(alpha)
    rows = [[(2 * k - 1) * h * c, h * s, sign * alpha]
            for k in range(1, UNITS + 1) for sign in (1.0, -1.0)]
    return np.array(rows).ravel()


def test_the_closed_form_is_the_kernels_order(tongs):
    """_state lists a1, b1, a2, ... as the kernel's coordinates do, and closes Phi at t = 0."""
    assert list(tongs.coordinates[:6]) == ["a1.x", "a1.y", "a1.phi", "b1.x", "b1.y", "b1.phi"]
    p = np.array(tongs.p_values, dtype=float)
    assert np.abs(tongs.phi(_state(0.7), 0.0, p)).max() < 1e-12


def test_a_regular_tongs_of_300_coordinates_is_no_singular_start(tongs):
    p = np.array(tongs.p_values, dtype=float)
    q = _state(0.7)
    scaled, _ = start.scaled_nonzeros(tongs, tongs.phi_q_nz(q, 0.0, p))
    cond = start.scaled_cond(tongs, scaled)
    # Above a small mechanism's threshold: a threshold blind to size refuses this start.
    assert edges.limit_threshold(OPTIONS) < cond < 1e5
    assert start.singular_start(tongs, q, 0.0, p, OPTIONS) is None


def test_a_regular_tongs_is_solved_from_its_start(tongs):
    trajectory = symkin.solve(tongs, t=np.linspace(0.0, 0.1, 3), options=OPTIONS)
    alpha = 0.7 + 0.2 * np.sin(trajectory.t)
    last = UNITS - 1
    x = trajectory.q[:, tongs.coordinates.index(f"a{UNITS}.x")]
    np.testing.assert_allclose(x, (2 * last + 1) * scaling_limit.HALF * np.cos(alpha),
                               atol=1e-9)
    assert not trajectory.flagged.any()


def test_the_tongs_closed_flat_is_singular_and_said_in_ten_names(tongs):
    p = np.array(tongs.p_values, dtype=float)
    found = start.singular_start(tongs, _state(math.pi / 2), 0.0, p, OPTIONS)
    assert found is not None and found.cond > 1e12
    message = failures.explain_start(found, 0.0)
    assert len(message) < 3000
    aligned = message.split(" become aligned")[0].split("): ")[-1]
    assert len(found.aligned) > MAX_LISTED
    assert aligned.count("revolute") == MAX_LISTED
    assert aligned.endswith(f" and {len(found.aligned) - MAX_LISTED} more")


def test_the_textbook_dead_centre_is_still_refused():
    """The small mechanism's threshold is kept: size 9 is judged as before."""
    assert start.start_threshold(Options(), 9) == edges.limit_threshold(Options())
    assert start.start_threshold(Options(), 3 * start.SIZE_FROM) == \
        9 * edges.limit_threshold(Options())


@pytest.mark.parametrize(("count", "said"), [
    (3, "j0, j1, j2"),
    (10, ", ".join(f"j{k}" for k in range(10))),
    (11, ", ".join(f"j{k}" for k in range(10)) + " and 1 more"),
    (1500, ", ".join(f"j{k}" for k in range(10)) + " and 1490 more"),
])
def test_listed_names_ten_and_counts_the_rest(count, said):
    assert listed(f"j{k}" for k in range(count)) == said
