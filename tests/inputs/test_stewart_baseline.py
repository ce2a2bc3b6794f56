"""The LinuxCNC-style Stewart-Gough forward-kinematics baseline of bench/stewart is right
before it is timed: compiled with the strict flags, it recovers the prescribed poses of the
trajectory (whose leg lengths come from the closed-form inverse kinematics) at small and large
tilt; the closed-form leg lengths are checked here against NumPy's own."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench" / "stewart"
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror"]

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")


def _build(tmp_path: Path) -> Path:
    exe = tmp_path / "fk_bench"
    sources = [str(BENCH / f) for f in ("fk_bench.c", "linuxcnc_style_fk.c", "stewart.c")]
    subprocess.run(["gcc", *FLAGS, "-o", str(exe), *sources, "-lm"], check=True)
    return exe


def test_baseline_recovers_the_prescribed_poses(tmp_path: Path) -> None:
    out = subprocess.run([str(_build(tmp_path)), "400", "1"], check=True, capture_output=True,
                         text=True).stdout
    rows = [dict(item.split("=") for item in line.split()) for line in out.splitlines()]
    assert [float(r["tilt_rad"]) for r in rows] == [0.05, 0.5]
    for row in rows:
        assert row["failures"] == "0"
        assert float(row["max_leg_error"]) < 1e-9  # its own convergence test
        assert float(row["max_position_error"]) < 1e-8
        assert float(row["max_angle_error"]) < 1e-8
        assert int(row["max_iterations"]) <= 120
    # The orientation update without the angle-rate mapping costs iterations at large tilt.
    assert float(rows[1]["mean_iterations"]) > float(rows[0]["mean_iterations"])


def test_closed_form_leg_lengths(tmp_path: Path) -> None:
    """stewart_legs against R = Rz Ry Rx built by NumPy from elementary rotations."""
    probe = tmp_path / "probe.c"
    probe.write_text('#include <stdio.h>\n#include "stewart.h"\nint main(void) {\n'
                     '    stewart_geometry g; double pose[6] = {0.1, -0.05, 0.9, 0.3, -0.2, 0.4};'
                     '\n    double legs[6]; int i;\n    stewart_default_geometry(&g);\n'
                     '    stewart_legs(&g, pose, legs);\n'
                     '    for (i = 0; i < 6; ++i) printf("%.17g\\n", legs[i]);\n'
                     '    for (i = 0; i < 6; ++i) printf("%.17g %.17g %.17g %.17g\\n", '
                     'g.base[i][0], g.base[i][1], g.platform[i][0], g.platform[i][1]);\n'
                     '    return 0;\n}\n')
    exe = tmp_path / "probe"
    subprocess.run(["gcc", *FLAGS, f"-I{BENCH}", "-o", str(exe), str(probe),
                    str(BENCH / "stewart.c"), "-lm"], check=True)
    run = subprocess.run([str(exe)], check=True, capture_output=True, text=True)
    lines = run.stdout.split("\n")
    legs = np.array([float(v) for v in lines[:6]])
    joints = np.array([[float(v) for v in line.split()] for line in lines[6:12]])
    x, a, b, c = np.array([0.1, -0.05, 0.9]), 0.3, -0.2, 0.4
    rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rz = np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])
    rotation = rz @ ry @ rx
    for i in range(6):
        base = np.array([joints[i, 0], joints[i, 1], 0.0])
        top = np.array([joints[i, 2], joints[i, 3], 0.0])
        assert abs(np.linalg.norm(x + rotation @ top - base) - legs[i]) < 1e-14
    # the 6-6 layout: base radius 1, platform radius 0.6
    assert np.allclose(np.hypot(joints[:, 0], joints[:, 1]), 1.0, atol=1e-15)
    assert np.allclose(np.hypot(joints[:, 2], joints[:, 3]), 0.6, atol=1e-15)
