"""Chunked, resumable execution of grid computations, in-process or on a Dask cluster.

A grid (the cells of a sweep, a basin or a parameter plane) is cut into chunks of consecutive
cells. Each chunk is one call of a runner function (``rockjit.analysis.run_chunk``: the compiled
parallel kernel on those cells), in this process or as a task on a ``dask.distributed.Client``,
whose workers run the same compiled kernels. Results are placed into the full output arrays as
chunks arrive.

With a store directory, every finished chunk is written there atomically (a temporary file, then
a rename) beside a manifest holding a fingerprint of the whole computation (inputs, settings,
chunking, rockjit's version). Running the same computation again with the same directory loads
the finished chunks and computes only the missing ones, so an interrupted run, or one that lost
workers, resumes; the result equals an uninterrupted run's bit for bit, because each cell is
computed independently of the chunking and of where it runs. A directory that holds another
computation's chunks is refused rather than mixed in.

Dask is optional and imported only when a client is given.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["ChunkStore", "fingerprint", "run_chunks"]


def fingerprint(arrays, settings):
    """SHA-256 over the arrays' bytes (with dtype and shape) and the settings as JSON."""
    from . import __version__

    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    h.update(json.dumps(settings, sort_keys=True, default=str).encode())
    h.update(__version__.encode())
    return h.hexdigest()


class ChunkStore:
    """Finished chunks of one computation in a directory (see the module docstring)."""

    MANIFEST = "manifest.json"

    def __init__(self, directory, key, n, chunk):
        self.dir = Path(directory)
        self.key = key
        self.n = int(n)
        self.chunk = int(chunk)
        self.dir.mkdir(parents=True, exist_ok=True)
        man = self.dir / self.MANIFEST
        want = {"key": key, "n": self.n, "chunk": self.chunk}
        if man.exists():
            try:
                have = json.loads(man.read_text())
            except ValueError:
                have = None
            if have != want:
                raise ValueError(
                    f"{self.dir} holds the chunks of a different computation (other inputs or "
                    f"settings); use another output directory or delete {self.dir}")
        else:
            self._write_bytes(man, json.dumps(want).encode())

    def _path(self, a, b):
        return self.dir / f"cells-{a:010d}-{b:010d}.npz"

    def _write_bytes(self, path, data):
        fd, tmp = tempfile.mkstemp(dir=self.dir, prefix=".tmp-", suffix=path.suffix)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def has(self, a, b):
        return self._path(a, b).exists()

    def load(self, a, b):
        with np.load(self._path(a, b)) as z:
            return {k: z[k] for k in z.files}

    def save(self, a, b, out):
        fd, tmp = tempfile.mkstemp(dir=self.dir, prefix=".tmp-", suffix=".npz")
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, **out)
            os.replace(tmp, self._path(a, b))
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise


class _Progress:
    """A one-line progress report on stderr."""

    def __init__(self, total, label, enabled, done=0):
        self.total, self.label, self.enabled = total, label, enabled
        self.t0 = time.perf_counter()
        self.done = self.start = done

    def update(self, n):
        self.done += n
        if not self.enabled:
            return
        el = time.perf_counter() - self.t0
        fresh = self.done - self.start
        eta = el / fresh * (self.total - self.done) if fresh else float("nan")
        sys.stderr.write(f"\r{self.label}: {self.done}/{self.total} cells, {el:6.1f} s"
                         f" elapsed, ~{eta:5.1f} s left ")
        sys.stderr.flush()

    def close(self):
        if self.enabled:
            sys.stderr.write("\n")
            sys.stderr.flush()


def run_chunks(runner, inputs, n, chunk, outputs, *, client=None, store=None, progress=False,
               label="cells", task_prefix="rockjit"):
    """Run ``runner`` over chunks of ``n`` cells and fill ``outputs`` in place.

    Parameters
    ----------
    runner : callable
        ``runner(*inputs_of_chunk) -> dict name -> array`` for cells ``a:b``; module-level, so
        that Dask can send it to workers.
    inputs : tuple
        Arguments of ``runner``; arrays whose first axis has length ``n`` are sliced per chunk,
        everything else is passed whole.
    outputs : dict name -> ndarray
        Preallocated results, first axis ``n``; chunk ``a:b`` is written to ``[a:b]``.
    client : dask.distributed.Client, optional
        Run the chunks as tasks on this cluster (retried if a worker is lost).
    store : ChunkStore, optional
        Load finished chunks from it and save new ones to it.
    """
    bounds = [(a, min(n, a + chunk)) for a in range(0, n, chunk)]
    todo = []
    for a, b in bounds:
        if store is not None and store.has(a, b):
            for k, v in store.load(a, b).items():
                outputs[k][a:b] = v
        else:
            todo.append((a, b))
    bar = _Progress(n, label, progress, done=n - sum(b - a for a, b in todo))

    def args(a, b):
        return tuple(x[a:b] if isinstance(x, np.ndarray) and x.ndim and x.shape[0] == n else x
                     for x in inputs)

    def place(a, b, out):
        if store is not None:
            store.save(a, b, out)
        for k, v in out.items():
            outputs[k][a:b] = v
        bar.update(b - a)

    try:
        if client is None:
            for a, b in todo:
                place(a, b, runner(*args(a, b)))
        else:
            from dask.distributed import as_completed

            futures = {}
            for a, b in todo:
                fut = client.submit(runner, *args(a, b), key=f"{task_prefix}-{a}-{b}",
                                    retries=3, pure=False)
                futures[fut] = (a, b)
            for fut in as_completed(futures):
                place(*futures[fut], fut.result())
    finally:
        bar.close()
    return outputs
