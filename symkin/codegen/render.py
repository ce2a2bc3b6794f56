"""Stage 4 — render: jinja2 templates turn the plain data of codegen into files.

Every template the backend (a ``codegen.target.Target``) lists becomes one file of the
generated folder, named by the backend (``Target.output_name``); the templates, their file
names and whatever they need of the language (signatures, literals, the real type) are the
backend's. Templates whose name starts with ``_`` are partials and are not written out. The
folder also gets ``<prefix>_manifest.json`` (symkin.contract.manifest): the files with their
sha256, the op counts and the metadata a runtime needs. The output
depends only on the input: the same mechanism gives the same bytes on every run and machine.
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import jinja2

from symkin.codegen import lower
from symkin.codegen.lower import Code, Routine
from symkin.codegen.target import Target
from symkin.codegen.template_cache import TemplateCache
from symkin.contract import status
from symkin.contract.loads import load_count, reaction_parts
from symkin.contract.manifest import GENERATOR, MANIFEST_SUFFIX, Manifest, Metadata, manifest_name
from symkin.errors import BuildError, UsageError
from symkin.symbolic.derivation import System

# Templates rendered only for a file with masses (Code.forward_dynamics).
DYNAMICS_TEMPLATES = ("dynamics",)
# The output arrays of each routine, as every backend's templates name them: values ("out")
# or the non-zeros of a sparse matrix ("nz"); the fused routine writes three, in order
# (Routine.sizes). How a backend spells a routine's name and signature is its own
# (Target.routine_context).
OUTPUT_ARRAYS: dict[str, tuple[str, ...]] = {
    **{name: ("out",) for name in lower.ROUTINE_ARGUMENTS},
    "phi_q": ("nz",), "phi_p": ("nz",), "mass": ("nz",),
    "phi_phi_q": ("out", "nz", "shared"),
    "motion": ("mass", "nz", "rhs", "gamma"),
}


@functools.cache
def environment(root: str) -> jinja2.Environment:
    """The strict jinja2 environment over a backend's template root (cached per folder)."""
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(root),
        undefined=jinja2.StrictUndefined, keep_trailing_newline=True, trim_blocks=True,
        lstrip_blocks=True, autoescape=False, bytecode_cache=TemplateCache(root))


def template_names(code: Code) -> list[str]:
    """The templates of ``code.backend`` that each render to one file, sorted."""
    return code.backend.templates(code)


def render_sources(code: Code) -> dict[str, str]:
    """Render every template of the backend: ``{file name: text}``, sorted by name."""
    context = template_context(code)
    files = {}
    backend = code.backend
    for template in template_names(code):
        if template.split(".")[0] in DYNAMICS_TEMPLATES and not code.forward_dynamics:
            continue  # the dynamics step is for a file with masses only
        name = backend.output_name(template, code.name)
        text = _render(backend, template,
                       {**context, "template": template, "file_name": name,
                        "header": header_lines(code, template, name)})
        if text.strip():  # a template for what this mechanism lacks renders to nothing
            files[name] = text
    return dict(sorted(files.items()))


def _render(backend: Target, name: str, context: dict[str, Any]) -> str:
    template = f"{backend.template_folder}/{name}"
    try:
        root = str(backend.template_root)
        return environment(root).get_template(template).render(context)
    except jinja2.TemplateError as error:
        line = getattr(error, "lineno", None)
        where = f" (line {line})" if line else ""
        raise BuildError(f"template {template}{where} failed to render: {error}") from None


def generate(system: System, backend: Target, out_dir: str | Path = "generated",
             options: Mapping[str, str] | None = None, cse: bool = True,
             force: bool = False) -> list[Path]:
    """Generate the source files of one backend into ``out_dir``.

    Args:
        system: the derived kinematics.
        backend: the target (``symkin.generate`` takes its name; ``symkin.backends``
            lists them).
        out_dir: the folder to write; created when missing. It may hold earlier output of
            symkin (this mechanism's is replaced, other mechanisms' is left alone); any other
            file makes it refuse, unless ``force``.
        options: the backend's own options, by name (``backend.options`` declares them;
            the rest take their defaults).
        cse: eliminate common subexpressions.
        force: write even where files symkin did not write are present (they are never
            deleted; one with the name of a generated file is replaced: a symlink itself,
            never the file it points to).

    Returns:
        The paths written, sorted, the manifest last.

    Raises:
        BuildError: an option the backend does not take.
        UsageError: the folder holds files symkin did not write (and not ``force``), or it
            cannot be written.
    """
    code = lower.lower(system, backend, options, cse)
    return write(code, Path(out_dir), force=force)


def rendered(code: Code) -> dict[str, str]:
    """Every file of ``code`` by name, as written and built: its rendered sources, then its
    manifest (which records their digests)."""
    files = render_sources(code)
    files[manifest_name(code.name)] = manifest(code, files)
    return files


def write(code: Code, out_dir: Path, force: bool = False) -> list[Path]:
    """Write the rendered files of ``code`` and its manifest into ``out_dir``: symkin's own
    earlier output of this mechanism is replaced (files it no longer has are removed), and a
    file symkin did not write (or that was edited since) is never deleted."""
    files = rendered(code)
    paths = [out_dir / name for name in files]
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        ours, theirs = _generated_here(out_dir, code.name)
        foreign = sorted(_files_in(out_dir) - ours - theirs)
        if foreign and not force:
            shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
            raise UsageError(f"{out_dir} holds files symkin did not write ({shown}); generate "
                             "into an empty folder, or pass --force (force=True) to write "
                             "beside them")
        for name in sorted(ours - set(files)):  # e.g. the dense LU after switching to sparse
            (out_dir / name).unlink(missing_ok=True)
        for path, text in zip(paths, files.values()):
            if path.is_symlink():  # (foreign, so --force): replace the link, not its target
                path.unlink()
            path.write_text(text, encoding="utf-8", newline="\n")
    except OSError as error:
        raise UsageError(f"cannot write the generated files into {out_dir}: "
                         f"{error.strerror or error}. Choose a folder you can write to.") from None
    return paths


def _files_in(folder: Path) -> set[str]:
    return {path.name for path in folder.iterdir() if path.is_file() or path.is_symlink()}


def _generated_here(folder: Path, prefix: str) -> tuple[set[str], set[str]]:
    """The files symkin generated in ``folder`` and nobody changed since: (this mechanism's,
    other mechanisms'), each with its manifest. A manifest symkin did not write, or a listed
    file whose bytes differ from the recorded sha256, counts as not symkin's."""
    ours: set[str] = set()
    theirs: set[str] = set()
    for path in sorted(folder.glob("*" + MANIFEST_SUFFIX)):
        listed = _intact_files(folder, path)
        if listed is None:
            continue
        owner = ours if path.name == manifest_name(prefix) else theirs
        owner.update(listed | {path.name})
    return ours, theirs


def _intact_files(folder: Path, manifest_path: Path) -> set[str] | None:
    """The files a symkin manifest lists that still have their recorded hash; None when the
    manifest is not one symkin wrote. symkin writes no symlinks: a symlink is never intact."""
    try:
        data = json.loads(manifest_path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("generator") != GENERATOR:
        return None
    listed = data.get("files")
    if not isinstance(listed, dict) or \
            manifest_path.name != manifest_name(str(data.get("name"))):
        return None
    return {name for name, digest in listed.items()
            if isinstance(name, str) and Path(name).name == name
            and not (folder / name).is_symlink() and _sha256_file(folder / name) == digest}


def _sha256_file(path: Path) -> str | None:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


def manifest(code: Code, files: dict[str, str]) -> str:
    """The manifest: file hashes, op counts and the metadata a runtime needs, as JSON."""
    data = Manifest(
        generator=GENERATOR, backend=code.backend.name,
        real=code.backend.precision(code.options), cse=code.cse,
        name=code.name, spec_sha256=code.spec_sha256,
        files={name: hashlib.sha256(text.encode()).hexdigest() for name, text in files.items()},
        ops=code.ops, ops_before_cse=code.ops_before_cse, **metadata(code),
    )
    return json.dumps(data, indent=1, sort_keys=True) + "\n"


def metadata(code: Code) -> Metadata:
    """What the runtime Kernel needs besides the compiled functions (plain JSON data); the
    optional keys only where they apply (a planar manifest without them is as it always was)."""
    data: Metadata = {
        "coordinates": list(code.coordinates), "parameter_names": list(code.parameter_names),
        "p_values": list(code.p_values), "q0": list(code.q0), "time_grid": list(code.time_grid),
        "rows": list(code.rows), "pattern_rows": list(code.pattern_rows),
        "pattern_cols": list(code.pattern_cols), "points": [list(p) for p in code.points],
        "phi_p_rows": list(code.phi_p_rows), "phi_p_cols": list(code.phi_p_cols),
        "nq": code.nq, "n_params": code.n_params, "nnz": code.nnz, "npoints": code.npoints,
        "nshared": len(code.shared), "nonlinear": list(code.nonlinear),
    }
    if code.removed:  # only then: every other manifest stays as it was
        data["removed"] = list(code.removed)
    if code.senses:  # likewise
        data["senses"] = list(code.senses)
    if code.space == "3d":
        data["space"] = code.space
    if code.dynamics:
        data["driver_names"] = list(code.driver_names)
        data["joint_names"] = list(code.joint_names)
    if code.input_names:  # only then: the other mechanisms' manifests stay the same
        data["input_names"] = list(code.input_names)
    if code.input_lengths:  # likewise
        data["input_lengths"] = [code.input_names[k] for k in code.input_lengths]
    if code.ranges:  # likewise
        data["ranges"] = [list(entry) for entry in code.ranges]
    return data


# ----- template context ----------------------------------------------------------------------

def template_context(code: Code) -> dict[str, Any]:
    """The plain data every template of ``code.backend`` receives."""
    literal = code.backend.literal(code.options)
    return {
        "prefix": code.name, "PREFIX": code.name.upper(),
        "name_comment": lower.comment(code.name),
        "nq": code.nq, "n_params": code.n_params, "nnz": code.nnz, "npoints": code.npoints,
        "nshared": len(code.shared),
        "cse": code.cse, "spec_sha256": code.spec_sha256,
        "pattern_rows": list(code.pattern_rows), "pattern_cols": list(code.pattern_cols),
        "nonlinear_mask": [int(k in code.nonlinear) for k in range(code.nq)],
        "nnz_p": code.nnz_p,
        "phi_p_rows": list(code.phi_p_rows), "phi_p_cols": list(code.phi_p_cols),
        "ops": sorted(code.ops.items()),
        "p_literals": [literal(v) for v in code.p_values],
        "q0_literals": [literal(v) for v in code.q0],
        "time_literals": [literal(v) for v in code.time_grid],
        "coordinate_comments": [f"q[{k}] {lower.comment(n)}"
                                for k, n in enumerate(code.coordinates)],
        "parameter_comments": [f"p[{k}] {lower.comment(n)} = {v!r}" for k, (n, v)
                               in enumerate(zip(code.parameter_names, code.p_values))],
        "row_comments": [f"{k}: {lower.comment(r)}" for k, r in enumerate(code.rows)],
        "point_comments": [f"{k}: {lower.comment(f'{body}.{name}')}"
                           for k, (body, name) in enumerate(code.points)],
        "point_names": [lower.comment(f"{body}.{name}") for body, name in code.points],
        "point_bodies": [_body_index(code, body) for body, _ in code.points],
        "nu": len(code.input_names),
        "input_comments": [f"u[{k}] {lower.comment(n)}: {lower.comment(place)}" for k, (n, place)
                           in enumerate(zip(code.input_names, code.input_places))],
        "input_literals": [repr(n) for n in code.input_names],
        "input_lengths": list(code.input_lengths),
        "input_length_literals": [repr(code.input_names[k]) for k in code.input_lengths],
        "input_value_literals": [literal(v) for v in code.input_values],
        "routines": [_routine_context(code, r) for r in code.routines],
        "nremoved": len(code.removed),
        "removed_comments": [f"{k}: {lower.comment(r)}" for k, r in enumerate(code.removed)],
        "nsenses": len(code.senses),
        "sense_comments": [f"{k}: {lower.comment(r)}" for k, r in enumerate(code.senses)],
        "point_size": len(code.point_axes),
        "point_tuples": "(x, y, z) triples" if code.space == "3d" else "(x, y) pairs",
        # Inverse dynamics (only when the file has masses or forces).
        "dynamics": code.dynamics, "n_efforts": len(code.driver_names),
        "n_joints": len(code.joint_names),
        "n_loads": load_count(len(code.driver_names), len(code.joint_names), code.space),
        "reaction_size": len(reaction_parts(code.space)),
        "reaction_text": ("Fx, Fy, Fz and Mx, My, Mz (global)" if code.space == "3d"
                          else "Fx, Fy (global) and M"),
        # a spatial driver's effort is conjugate to its function (symbolic.dynamics3d)
        "effort_text": "lam dPhi/df" if code.space == "3d" else "-lam",
        # Forward dynamics (only when the file gives masses).
        "forward_dynamics": code.forward_dynamics, "nrows": code.nrows,
        "nnz_m": len(code.mass_rows), "mass_rows": list(code.mass_rows),
        "kept": list(code.augmented.kept) if code.augmented else [],
        "mass_cols": list(code.mass_cols),
        # What must equal the runtime's, rendered from symkin.contract (never copied):
        "status": {**status.CODES, **status.INPUT_CODES},
        **code.backend.template_context(code),
    }


def _body_index(code: Code, body: str) -> int:
    """Where a body's x is in q[] (-1: the ground, which has no coordinates)."""
    name = f"{body}.x"
    return code.coordinates.index(name) if name in code.coordinates else -1


def _routine_context(code: Code, routine: Routine) -> dict[str, Any]:
    names = OUTPUT_ARRAYS[routine.name]
    sizes = routine.sizes or (len(routine.outputs),)
    labels = _labels(code, routine.name)
    arrays, start, place = [], 0, []
    for name, size in zip(names, sizes):
        arrays.append({"name": name, "size": size, "slots": [
            (k, routine.outputs[start + k], labels[start + k] if labels else "")
            for k in range(size)]})
        place += [(name, k) for k in range(size)]
        start += size
    parts = []
    for part in routine.parts:
        written = {place[k][0] for k in part.slots}
        parts.append({
            "temporaries": list(part.temporaries),
            "unused": list(part.unused),
            "unwritten": [n for n in names if n not in written],
            "slots": [(*place[k], routine.outputs[k], labels[k] if labels else "")
                      for k in part.slots]})
    common = {
        "name": routine.name, "arguments": list(routine.arguments),
        "unused": list(routine.unused), "output": names[0], "arrays": arrays, "parts": parts,
        "temporaries": list(routine.temporaries), "outputs": list(routine.outputs),
        "labels": labels, "size": len(routine.outputs),
    }
    return {**common, **code.backend.routine_context(code, common)}


def _labels(code: Code, routine: str) -> list[str]:
    """A short comment per output slot: the row of Phi, or the (row, column) of Phi_q."""
    if routine == "phi_q":
        return [f"({r}, {c})" for r, c in zip(code.pattern_rows, code.pattern_cols)]
    if routine == "phi_p":
        return [lower.comment(f"({r}, {code.parameter_names[k]})")
                for r, k in zip(code.phi_p_rows, code.phi_p_cols)]
    if routine == "phi_phi_q":
        return [*_labels(code, "phi"), *_labels(code, "phi_q"),
                *(lower.comment(f) for f in code.shared)]
    if routine == "removed":
        return [lower.comment(row) for row in code.removed]
    if routine == "senses":
        return [lower.comment(label) for label in code.senses]
    if routine.endswith("_shared") and routine[:-len("_shared")] in lower.DYNAMICS:
        return _labels(code, routine[:-len("_shared")])
    if routine in ("dynamics_rhs", "applied"):
        return [lower.comment(name) for name in code.coordinates]
    if routine == "mass":
        return [f"({r}, {c})" for r, c in zip(code.mass_rows, code.mass_cols)]
    if routine == "motion":
        return [label for part in ("mass", "phi_q", "applied", "gamma")
                for label in _labels(code, part)]
    if routine == "removed_q":
        return [lower.comment(f"({row}, {name})") for row in code.removed
                for name in code.coordinates]
    if routine in ("loads", "loads_full"):
        return [lower.comment(f"{name}.effort") for name in code.driver_names] + [
            lower.comment(f"{name}.{part}") for name in code.joint_names
            for part in reaction_parts(code.space)]
    if routine == "points":
        return [lower.comment(f"{body}.{point}.{axis}") for body, point in code.points
                for axis in code.point_axes]
    return [lower.comment(row) for row in code.rows]


def header_lines(code: Code, template: str, file_name: str) -> list[str]:
    """The header every generated file starts with, in one style for every template: what the
    file is, which template made it, the spec's sha256, the real type and op counts; never a
    date, host or version, so the same input gives the same bytes."""
    purpose = code.backend.purpose(template).format(
        name=lower.comment(code.name))
    ops = ", ".join(f"{name} {count}" for name, count in sorted(code.ops.items()))
    precision = code.backend.precision(code.options)
    after = ", after CSE" if code.cse else ""
    return [f"{file_name}: {purpose}",
            f"Generated by symkin from the template {template}. Do not edit: regenerate instead.",
            f"Mechanism spec sha256: {code.spec_sha256}",
            f"Real type: {precision}. Operations (SymPy count_ops{after}): {ops}"]
