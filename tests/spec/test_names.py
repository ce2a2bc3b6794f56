"""Names designers use (issue 10): each kind of name has its own namespace.

Points, joints and drivers are labels: A ... H, E, p and q are fine there. Parameters and bodies
meet expressions, so only what an expression means otherwise is refused (t, pi, E, function
names, Python literals and keywords), all clashes in one message. The mechanism's name becomes
the C prefix and file names: C/Python keywords, libm names and system headers are refused.
"""

from __future__ import annotations

import numpy as np
import pytest

import symkin
from symkin.errors import MechanismError

# A crank-slider: parameters a and A (different), p, q and hypot (the rod length); a crank
# named int with points E and p; joints named E and q; a driver named p.
DESIGNER_NAMES = {
    "name": "names_demo",
    "parameters": {"a": 1.0, "A": 0.5, "p": 2.0, "q": 0.25, "hypot": 3.0},
    "bodies": {
        "int": {"q0": [0, 0, 0], "points": {"E": ["a", 0], "p": ["A", "q"]}},
        "rod": {"q0": [1, 0, 0]},
        "slider": {"q0": [4, 0, 0]},
    },
    "joints": [
        {"name": "E", "type": "revolute", "i": "ground", "j": "int", "sA": [0, 0], "sB": [0, 0]},
        {"name": "q", "type": "revolute", "i": "int", "j": "rod", "sA": "E", "sB": [0, 0]},
        {"type": "revolute", "i": "rod", "j": "slider", "sA": ["hypot", 0], "sB": [0, 0]},
        {"type": "prismatic", "i": "slider", "j": "ground", "sA": [0, 0], "sB": [0, 0],
         "v": [0, 1], "phi0": 0},
    ],
    "drivers": [{"name": "p", "type": "angle", "i": "int", "j": "ground",
                 "theta": "p*t + q"}],
    "time": {"t0": 0, "t1": 1, "dt": 0.25},
}


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_names_designers_use_are_accepted_and_solved(backend: str) -> None:
    kernel = symkin.compile(symkin.derive(symkin.from_dict(DESIGNER_NAMES)), backend=backend)
    assert kernel.backend == backend
    trajectory = symkin.solve(kernel)
    angle = 2.0 * trajectory.t + 0.25  # theta = p t + q
    # Closed forms of the crank-slider (crank a = 1, rod hypot = 3, slide through the pivot),
    # independent of symkin's constraints.
    np.testing.assert_allclose(trajectory.point("int", "E")[0][:, 0], np.cos(angle), atol=1e-12)
    np.testing.assert_allclose(trajectory.body("slider")[0][:, 0],
                               np.cos(angle) + np.sqrt(9 - np.sin(angle) ** 2), atol=1e-12)
    np.testing.assert_allclose(trajectory.body("int")[0][:, 2], angle, atol=1e-12)
    np.testing.assert_allclose(trajectory.point("int", "p")[0][:, 0],
                               0.5 * np.cos(angle) - 0.25 * np.sin(angle), atol=1e-12)
    # The names label the rows of Phi (and nothing else).
    assert kernel.rows[0] == "joints[0] E revolute ground-int (x)"
    assert kernel.rows[-1] == "drivers[0] p angle int-ground (angle)"


@pytest.mark.parametrize("section, name, meaning", [
    ("parameters", "t", "'t' is the time in expressions"),
    ("parameters", "E", "'E' is a constant in expressions"),
    ("parameters", "Heaviside", "'Heaviside' is a function in expressions"),
    ("parameters", "None", "'None' is a Python literal in expressions"),
    ("parameters", "while", "'while' is a Python keyword"),
])
def test_parameter_names_that_mean_something_else_are_refused(section: str, name: str,
                                                             meaning: str) -> None:
    data = {**DESIGNER_NAMES, "parameters": {**DESIGNER_NAMES["parameters"], name: 1.0}}
    with pytest.raises(MechanismError, match=meaning):
        symkin.from_dict(data)


def test_every_clash_is_listed_at_once() -> None:
    data = {**DESIGNER_NAMES,
            "parameters": {**DESIGNER_NAMES["parameters"], "t": 1, "pi": 2, "sin": 3},
            "bodies": {**DESIGNER_NAMES["bodies"], "Min": {"q0": [0, 0, 0]}}}
    with pytest.raises(MechanismError) as caught:
        symkin.from_dict(data)
    message = str(caught.value)
    assert "4 names cannot be used" in message
    for where in ("parameters.t:", "parameters.pi:", "parameters.sin:", "bodies.Min:"):
        assert where in message


@pytest.mark.parametrize("name", ["string", "limits", "stddef", "math", "stdio", "int", "sqrt",
                                  "lambda"])
def test_mechanism_names_that_would_shadow_c_or_python_are_refused(name: str) -> None:
    with pytest.raises(MechanismError, match="at name: "):
        symkin.from_dict({**DESIGNER_NAMES, "name": name})
