"""The gallery: every example mechanism, run with ``symkin run --plot`` when the docs are
built, its figure and the command that made it.

Pictures are cached by the SHA-256 of the example file and of symkin's own source, so a
rebuild with nothing changed runs nothing; ``SYMKIN_DOCS_GALLERY`` (a comma-separated list of
example names) limits the gallery, for the test suite's quick build."""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import yaml

TIMEOUT = 900  # seconds per example: the slowest (a cam, a six-legged platform) derive long


def _source_hash(root: Path) -> str:
    digest = hashlib.sha256()
    for path in sorted((root / "symkin").rglob("*.py")) + sorted((root / "symkin").rglob("*.j2")):
        if path.is_file():
            digest.update(path.read_bytes())
    return digest.hexdigest()


def selected(examples: Path) -> list[Path]:
    chosen = os.environ.get("SYMKIN_DOCS_GALLERY", "").strip()
    files = sorted(examples.glob("*.yaml"))
    if not chosen:
        return files
    names = {name.strip() for name in chosen.split(",")}
    return [path for path in files if path.stem in names]


# The keys of a driver that hold its function of time (a planar or spatial angle's theta,
# every other driver's f): only there does ``input`` mean an input driver; elsewhere it may
# name a joint or a body (the Cardan's input shaft).
FUNCTION_KEYS = ("theta", "f")


def has_inputs(example: Path) -> bool:
    """Whether a driver's function is written ``input`` (its values come from a table)."""
    data = yaml.safe_load(example.read_text(encoding="utf-8"))
    for driver in data.get("drivers") or []:
        for key in FUNCTION_KEYS:
            value = driver.get(key) if isinstance(driver, dict) else None
            if "input" in (value if isinstance(value, list) else [value]):
                return True
    return False


def command(example: Path) -> list[str]:
    """The command a reader types to make the same picture."""
    inputs = ["--inputs", f"{example.stem}_inputs.csv"] if has_inputs(example) else []
    return ["symkin", "run", f"examples/{example.name}", *inputs, "--plot", f"{example.stem}.png"]


WOBBLE = 0.03  # the gallery's inputs: their values at q0, times 1 + 3 % of a sine over the grid


def inputs_table(example: Path, target: Path) -> None:
    """A table of the file's inputs for the gallery: each at its value in the file's q0
    (where the mechanism is assembled), moved by a few per cent along one sine period."""
    import numpy as np

    import symkin
    from symkin.codegen.sample import input_values
    from symkin.runtime.arguments import grid

    system = symkin.derive(example)
    t = grid(*system.time_grid)  # the run's own grid: the table's t must be it
    phase = np.sin(2 * np.pi * (t - t[0]) / (t[-1] - t[0]))
    columns = {"t": t}
    # where the generated folder's example program holds them (a leg's length, not the 0
    # at which its row is flat)
    for name, value in zip(system.input_names, input_values(system)):
        columns[name] = value * (1 + WOBBLE * phase) if value else WOBBLE * phase
    rows = [",".join(columns)] + [",".join(f"{columns[k][n]:.12g}" for k in columns)
                                  for n in range(t.size)]
    target.write_text("\n".join(rows) + "\n", encoding="utf-8")


def _render(example: Path, root: Path, cache: Path, source: str) -> tuple[Path, str | None]:
    key = hashlib.sha256(example.read_bytes() + source.encode()).hexdigest()[:16]
    picture = cache / f"{example.stem}-{key}.png"
    if picture.exists():
        return picture, None
    work = cache / f"work-{example.stem}"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    shutil.copytree(root / "examples", work / "examples")
    if has_inputs(example):
        inputs_table(example, work / f"{example.stem}_inputs.csv")
        shutil.copyfile(work / f"{example.stem}_inputs.csv", picture.with_suffix(".csv"))
    env = {**os.environ, "PYTHONPATH": str(root), "MPLBACKEND": "Agg"}
    args = [sys.executable, "-m", *command(example)[0:1], *command(example)[1:]]
    done = subprocess.run(args, cwd=work, env=env, capture_output=True, text=True,
                          timeout=TIMEOUT, check=False)
    made = work / f"{example.stem}.png"
    if not made.exists():
        shutil.rmtree(work, ignore_errors=True)
        said = (done.stderr or done.stdout).strip().splitlines()
        return picture, said[-1] if said else f"exit {done.returncode}"
    shutil.move(made, picture)
    shutil.rmtree(work, ignore_errors=True)
    return picture, done.stdout.strip()


def _about(example: Path) -> tuple[str, str]:
    data = yaml.safe_load(example.read_text(encoding="utf-8"))
    space = "spatial" if data.get("space") == "3d" else "planar"
    layout = data.get("layout", "local")
    bodies = len(data.get("bodies") or {})
    return space, f"{space}, {layout} layout, {bodies} bodies"


def write(out: Path, root: Path, cache: Path) -> list[str]:
    """The gallery page and its pictures under ``out``; returns the examples that failed."""
    (out / "gallery").mkdir(parents=True, exist_ok=True)
    cache.mkdir(parents=True, exist_ok=True)
    source = _source_hash(root)
    examples = selected(root / "examples")
    with ThreadPoolExecutor(max_workers=2) as pool:
        rendered = list(pool.map(lambda e: _render(e, root, cache, source), examples))
    lines = ["# Gallery", "",
             "Every example mechanism of `examples/`, solved when these pages were built by "
             "the command above its figure (rows: position, velocity, acceleration). Run it "
             "from the repository's folder to get the same picture.", ""]
    failed = []
    for example, (picture, said) in zip(examples, rendered):
        _, about = _about(example)
        lines += [f"## {example.stem}", "", f"`examples/{example.name}`: {about}.", "",
                  "```console", "$ " + " ".join(command(example)), "```", ""]
        table = picture.with_suffix(".csv")
        if has_inputs(example) and table.exists():
            head = table.read_text(encoding="utf-8").splitlines()[:3]
            lines += [f"Its input drivers read `{example.stem}_inputs.csv`, made for the gallery: "
                      "each input at its value in the file's `q0`, moved by "
                      f"{WOBBLE:.0%} along one sine period (first rows):", "",
                      "```text", *head, "...", "```", ""]
        if picture.exists():
            shutil.copyfile(picture, out / "gallery" / f"{example.stem}.png")
            lines += [f"![{example.stem}: position, velocity and acceleration]"
                      f"(gallery/{example.stem}.png)", ""]
        else:
            failed.append(f"{example.name}: {said}")
            lines += [f"The example could not be solved when these pages were built: {said}", ""]
    target = out / "gallery.md"
    text = "\n".join(lines)
    if not target.exists() or target.read_text(encoding="utf-8") != text:
        target.write_text(text, encoding="utf-8")
    return failed
