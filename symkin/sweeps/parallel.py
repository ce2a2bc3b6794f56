"""Sweeps split over local processes or a Dask cluster.

What travels to a worker is the kernel's generated source, its manifest included (a few tens
of kB), never a compiled binary: each worker builds it into its own machine's cache, or finds
it there by the same content hash ``symkin.compile`` uses, and loads it once per process
(:func:`worker_kernel`). A worker on the machine that compiled it (local processes, a
LocalCluster) first tries the sender's cache folder, verified against the same sources, and so
needs neither a build nor the SymPy import a build would bring. Chunks of parameter sets then
go out, and come back as :class:`batch.Chunk`. Dask is imported only when a client is given.
"""

from __future__ import annotations

import concurrent.futures
import hashlib
import itertools
import json
import multiprocessing
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from symkin import backends
from symkin.build.cache import verified
from symkin.contract.manifest import MANIFEST_SUFFIX, manifest_name
from symkin.contract.options import Options
from symkin.errors import SolveError
from symkin.runtime.kernel import Kernel
from symkin.sweeps.batch import Chunk, solve_chunk

Array = NDArray[np.float64]
Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class Payload:
    """A kernel as its generated files: what a worker needs to build or find it."""

    files: dict[str, str]
    folder: str | None = None  # where the sender's build lives (useful on the same machine)

    @property
    def key(self) -> str:
        return hashlib.sha256(json.dumps(self.files, sort_keys=True).encode()).hexdigest()


def payload(kernel: Kernel) -> Payload:
    """The generated files of a compiled kernel, read from its cache folder."""
    folder = kernel.folder
    if folder is None:
        raise SolveError(f"the kernel of {kernel.name} has no build folder to send to workers; "
                         "compile it with symkin.compile")
    manifest = manifest_name(kernel.name)
    listed = json.loads((folder / manifest).read_text(encoding="utf-8"))["files"]
    names = [*sorted(listed), manifest]
    return Payload({name: (folder / name).read_text(encoding="utf-8") for name in names},
                   str(folder))


# One kernel per payload and process: loading verifies the files, so it is done once.
_LOADED: dict[str, Kernel] = {}


def worker_kernel(source: Payload) -> Kernel:
    """The kernel of ``source`` in this process: built or found in this machine's cache."""
    key = source.key
    if key not in _LOADED:
        _LOADED[key] = _same_machine(source) or _built(source)
    return _LOADED[key]


def _same_machine(source: Payload) -> Kernel | None:
    """The sender's own build, when this machine has it and it verifies against the sources."""
    if source.folder is None:
        return None
    folder = Path(source.folder)
    try:
        if not verified(folder, source.files):
            return None
        name = json.loads(source.files[next(n for n in source.files
                                            if n.endswith(MANIFEST_SUFFIX))])["name"]
        return backends.load(folder, name)
    except (OSError, ImportError, ValueError, KeyError, StopIteration):
        return None


def _built(source: Payload) -> Kernel:
    return backends.from_sources(source.files)


def run_chunk(source: Payload, params: Array, t: Array, q0: Array,
              options: Options | None) -> Chunk:
    """Solve one chunk in a worker (a local process or a Dask worker)."""
    return solve_chunk(worker_kernel(source), params, t, q0, options)


def split(m: int, pieces: int) -> list[slice]:
    """[0, m) in ``pieces`` contiguous slices of nearly equal size (none empty)."""
    bounds = np.linspace(0, m, min(max(pieces, 1), max(m, 1)) + 1).round().astype(int)
    return [slice(int(a), int(b)) for a, b in itertools.pairwise(bounds) if b > a]


def _q0_part(q0: Array, part: slice) -> Array:
    return q0[part] if q0.ndim == 2 else q0


def in_processes(source: Payload, params: Array, t: Array, q0: Array, options: Options | None,
                 workers: int, parts: Sequence[slice], progress: Progress | None
                 ) -> list[Chunk]:
    """The chunks solved by ``workers`` local processes (spawned: safe beside threads)."""
    context = multiprocessing.get_context("spawn")
    pool = concurrent.futures.ProcessPoolExecutor(
        max_workers=workers, mp_context=context, initializer=worker_kernel, initargs=(source,))
    try:
        futures = {pool.submit(run_chunk, source, params[part], t, _q0_part(q0, part),
                               options): k for k, part in enumerate(parts)}
        chunks = _collect(futures, concurrent.futures.as_completed(futures), parts, progress,
                          params.shape[0])
    except BaseException:  # Ctrl-C above all: drop the queued chunks, do not wait for them
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    return chunks


def on_dask(client: Any, source: Payload, params: Array, t: Array, q0: Array,
            options: Options | None, parts: Sequence[slice], progress: Progress | None
            ) -> list[Chunk]:
    """The chunks solved on a Dask cluster through ``client`` (a distributed.Client)."""
    try:
        from distributed import as_completed  # type: ignore[import-untyped,unused-ignore]
    except ImportError:  # pragma: no cover - a client cannot exist without distributed
        raise SolveError("client= needs dask.distributed: pip install 'symkin[distributed]'"
                         ) from None
    remote = client.scatter(source, broadcast=True)
    futures = {client.submit(run_chunk, remote, params[part], t, _q0_part(q0, part), options,
                             pure=False): k for k, part in enumerate(parts)}
    completed = as_completed(list(futures))  # type: ignore[no-untyped-call,unused-ignore]
    try:
        return _collect(futures, completed, parts, progress, params.shape[0])
    except BaseException:  # Ctrl-C above all: the cluster need not finish the sweep
        client.cancel(list(futures))
        raise


def _collect(futures: dict[Any, int], completed: Iterator[Any], parts: Sequence[slice],
             progress: Progress | None, total: int) -> list[Chunk]:
    chunks: list[Chunk | None] = [None] * len(parts)
    done = 0
    for future in completed:
        k = futures[future]
        chunks[k] = future.result()
        done += parts[k].stop - parts[k].start
        if progress is not None:
            progress(done, total)
    return [chunk for chunk in chunks if chunk is not None]
