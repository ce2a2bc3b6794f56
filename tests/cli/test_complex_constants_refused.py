"""A constant that is not real (acos(2 pi)) inside Max, Min, Heaviside or asin is refused where
it is written, exit 2 with the file, line and field, wherever an expression may stand: a
parameter, a point, a drawn point, a frame angle, q0, a vector, a time function, a
polynomial's coefficient, the time grid, a custom equation. (Reported as a TypeError in C
generation; each place is tried with `generate --backend c`.)"""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_support import symkin_main

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
BAD = "Max(acos(2*pi), 1)"

CASES = [
    ("crank_slider.yaml", "a: 1.0", f'a: "asin({BAD})"', "parameters.a"),
    ("crank_slider.yaml", "tip: [a, 0]", f'tip: ["a*{BAD}", 0]', "bodies.crank.points.tip[0]"),
    ("crank_slider.yaml", 'theta: "t**2 + pi/2"', f'theta: "t + {BAD}"', "drivers[0].theta"),
    ("crank_slider.yaml", 'theta: "t**2 + pi/2"', f'theta: {{poly: [0, "{BAD}"]}}',
     "drivers[0].theta.poly[1]"),
    ("crank_slider.yaml", "t1: 1.5", f't1: "{BAD}"', "time.t1"),
    ("crank_slider.yaml", "v: [0, 1]", f'v: [0, "{BAD}"]', "joints[3].v[1]"),
    ("crank_slider.yaml", 'theta: "t**2 + pi/2"', 'theta: "t + Heaviside(acos(2*pi))"',
     "drivers[0].theta"),
    ("crank_slider_drawn.yaml", "A: [0, a]}", f'A: [0, "a*{BAD}"]}}',
     "bodies.crank.points.A[1]"),
    ("crank_slider_drawn.yaml", "angle: pi/2", f'angle: "asin({BAD}/2)"',
     "bodies.crank.frame.angle"),
    ("custom_driver.yaml", "q0: [0, 0, 0.785]", f'q0: [0, 0, "asin({BAD})"]',
     "bodies.crank.q0[2]"),
    ("custom_driver.yaml", "*(crank.y + a*sin(crank.phi))\"",
     f"*(crank.y + a*sin(crank.phi))*{BAD}\"", "drivers[0].equations[0]"),
]


@pytest.mark.parametrize(("example", "old", "new", "field"), CASES)
def test_refused_at_its_field_with_exit_2(tmp_path, example, old, new, field):
    text = (EXAMPLES / example).read_text()
    assert text.count(old) >= 1, old
    path = tmp_path / example
    path.write_text(text.replace(old, new, 1))
    done = symkin_main("generate", str(path), "--backend", "c", "-o", str(tmp_path / "out"),
                       cwd=ROOT)
    assert done.returncode == 2, done.stderr
    assert f"{path}:" in done.stderr and f"at {field}:" in done.stderr
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
