"""Write examples/stewart_fk.yaml and examples/stewart_legs_fk.yaml: the benchmark's
Stewart-Gough platform (the geometry of stewart.c: base radius 1, platform radius 0.6, joints
in pairs 20 and 40 degrees apart) with its six leg lengths read as inputs.

    python3 bench/stewart/make_fk_examples.py

The home pose is the platform level at height 1 (pose {0, 0, 1, 0, 0, 0} of stewart.h); the
files are drawn there (layout: drawn). In stewart_fk.yaml each input is a leg length (a
`distance` driver); in stewart_legs_fk.yaml each is the ram's slide from its home length.
"""

from __future__ import annotations

import math
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HEIGHT = 1.0
TIME = "time: {t0: 0, t1: 1, dt: 0.01}   # the grid of a run; the inputs come with it"


def geometry() -> tuple[list[list[float]], list[list[float]]]:
    """Base and platform points as stewart_default_geometry computes them (platform at home)."""
    base, top = [], []
    for i in range(6):
        pair, side = i // 2, (1 if i % 2 else -1)
        base_angle = pair * 2 * math.pi / 3 + side * 10 * math.pi / 180
        top_angle = pair * 2 * math.pi / 3 + math.pi / 3 - side * 40 * math.pi / 180
        base.append([math.cos(base_angle), math.sin(base_angle), 0.0])
        top.append([0.6 * math.cos(top_angle), 0.6 * math.sin(top_angle), HEIGHT])
    return base, top


def vec(v) -> str:
    return "[" + ", ".join(repr(round(x, 17) + 0.0) for x in v) + "]"


def points(prefix: str, vectors) -> str:
    return "{" + ", ".join(f"{prefix}{i + 1}: {vec(v)}" for i, v in enumerate(vectors)) + "}"


def header(name: str, what: str) -> list[str]:
    return [f"name: {name}", "space: 3d", "layout: drawn",
            "# The Stewart-Gough platform of the forward-kinematics benchmark (bench/stewart/",
            "# stewart.c: base radius 1, platform radius 0.6, joints in pairs 20 and 40 degrees",
            "# apart), drawn at its home pose (level, at height 1). " + what,
            "# Written by bench/stewart/make_fk_examples.py.",
            "bodies:"]


def one_body() -> str:
    base, top = geometry()
    lines = header("stewart_fk", "The six leg lengths are inputs\n"
                   "# (leg1..leg6, |P_i - B_i|): solving them is the forward kinematics.")
    lines += [f"  ground: {{points: {points('B', base)}}}",
              "  platform:", f"    frame: {{origin: [0, 0, {HEIGHT!r}]}}",
              f"    points: {points('P', top)}", "joints: []", "drivers:"]
    lines += [f"  - {{type: distance, name: leg{i}, i: ground, j: platform, A: B{i}, B: P{i},"
              " f: input}" for i in range(1, 7)]
    return "\n".join(lines + [TIME]) + "\n"


def with_legs() -> str:
    base, top = geometry()
    lines = header("stewart_legs_fk", "With its 12 leg bodies (6-UPS:\n"
                   "# universal joint at the base, prismatic ram, ball joint at the platform);"
                   " the\n# inputs leg1..leg6 are the rams' slides from their home lengths.")
    lines += [f"  ground: {{points: {points('B', base)}}}",
              "  platform:", f"    frame: {{origin: [0, 0, {HEIGHT!r}]}}",
              f"    points: {points('P', top)}"]
    joints, drivers = [], []
    for k, (b, p) in enumerate(zip(base, top), start=1):
        mid = [(x + y) / 2 for x, y in zip(b, p)]
        leg = [y - x for x, y in zip(b, p)]
        across = [-leg[1], leg[0], 0.0]  # horizontal, perpendicular to the leg
        third = [leg[1] * across[2] - leg[2] * across[1], leg[2] * across[0] - leg[0] * across[2],
                 leg[0] * across[1] - leg[1] * across[0]]
        lines.append(f"  cylinder{k}: {{points: {{B{k}: {vec(b)}, M{k}: {vec(mid)}}}}}")
        lines.append(f"  piston{k}: {{points: {{M{k}: {vec(mid)}, P{k}: {vec(p)}}}}}")
        joints += [f"  - {{type: universal, name: base{k}, i: ground, j: cylinder{k}, at: B{k},"
                   f" axes: [{vec(third)}, {vec(across)}]}}",
                   f"  - {{type: prismatic, name: ram{k}, i: cylinder{k}, j: piston{k}, at: M{k},"
                   f" axis: {vec(leg)}}}",
                   f"  - {{type: spherical, name: top{k}, i: piston{k}, j: platform, at: P{k}}}"]
        drivers.append(f"  - {{type: slide, name: leg{k}, joint: ram{k}, f: input}}")
    return "\n".join(lines + ["joints:"] + joints + ["drivers:"] + drivers + [TIME]) + "\n"


def main() -> None:
    (ROOT / "examples" / "stewart_fk.yaml").write_text(one_body())
    (ROOT / "examples" / "stewart_legs_fk.yaml").write_text(with_legs())


if __name__ == "__main__":
    main()
