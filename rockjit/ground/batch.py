"""A batch of cells under transient excitations, the kernels that compute their outcomes, and the
method they run on (the compiled path or which scipy path).

Every grid of this package (a pulse's overturning spectrum, each step of its bisections, an
incremental dynamic analysis) is a :class:`Batch`: cell ``i`` is the block
``blocks[block_of[i]]``, at rest at ``t = 0``, under the excitation
``sources[source_of[i]].scaled(gain[i])``. A source is a bound transient excitation at unit
gain: a pulse of one kind and frequency ratio on one block (``gain`` is then its amplitude
ratio), or a record played on one block size (``gain`` is then its scale factor). The
integration settings (:class:`rockjit.Transient`, with ``stop_when_decided`` on) and the method
are the batch's.

A **kernel** computes a chunk of cells::

    kernel(blocks, sources, block_of, source_of, gain, settings, method) -> dict

returning one array per name of :data:`OUTPUTS`, each of the chunk's length:

- ``outcome`` (int8): :data:`rockjit.ground.response.OUTCOMES`' code;
- ``max_rotation`` (float64): ``max |theta| / alpha_s``;
- ``t_overturn`` (float64): when ``|theta|`` reached ``theta_over``, ``nan`` if never;
- ``t_end`` (float64): the model time the run stopped;
- ``n_impacts`` (int64): the impacts before it stopped;
- ``status`` (int8): the index of the run's status in :data:`STATUS_CODES`.

Two kernels: :func:`scipy_kernel` runs the cells one after another on the scipy reference path;
the compiled kernel (:func:`rockjit.ground.compiled.compiled_kernel`, the default) runs a
chunk's cells in parallel threads, or one per GPU thread with ``Execution(device="cuda")``
(:func:`~rockjit.ground.compiled.cuda_kernel`); :func:`kernel_for` registers them in
:data:`KERNELS` when first asked for them. :func:`run_batch`
cuts a batch into chunks and runs them through a kernel, in this process or on a Dask cluster
(``Execution.client`` or ``Execution.scheduler``), with progress, resumable from a chunk store
(``Execution.store``).
"""

from __future__ import annotations

import contextlib
import math
import uuid
from dataclasses import dataclass

import numpy as np

from .response import OUTPUTS, STATUS_CODES, empty_outputs

__all__ = ["Batch", "KERNELS", "OUTPUTS", "STATUS_CODES", "check_method", "grid_method",
           "kernel_for", "run_batch", "scipy_kernel", "transient_scipy"]

@dataclass(frozen=True, eq=False)
class Batch:
    """Cells to compute: cell ``i`` is ``blocks[block_of[i]]`` under
    ``sources[source_of[i]].scaled(gain[i])``, from rest."""

    blocks: tuple
    sources: tuple
    block_of: np.ndarray
    source_of: np.ndarray
    gain: np.ndarray

    def __post_init__(self):
        n = len(self.gain)
        for name in ("block_of", "source_of"):
            a = np.asarray(getattr(self, name), dtype=np.int64)
            if a.shape != (n,):
                raise ValueError(f"{name} must have one entry per cell ({n})")
            object.__setattr__(self, name, a)
        object.__setattr__(self, "gain", np.asarray(self.gain, dtype=float))
        object.__setattr__(self, "blocks", tuple(self.blocks))
        object.__setattr__(self, "sources", tuple(self.sources))

    def __len__(self):
        return int(self.gain.size)

    def cell(self, i):
        """``(block, excitation)`` of cell ``i``."""
        return (self.blocks[self.block_of[i]],
                self.sources[self.source_of[i]].scaled(float(self.gain[i])))


def scipy_kernel(blocks, sources, block_of, source_of, gain, settings, method):
    """The scipy reference path on each cell in turn (:func:`rockjit.ground.reference.
    run_scipy`), from rest."""
    from .reference import run_scipy
    n = len(gain)
    out = empty_outputs(n)
    for i in range(n):
        block = blocks[block_of[i]]
        exc = sources[source_of[i]].scaled(float(gain[i]))
        r = run_scipy(block, exc, (0.0, 0.0), settings, method)
        out["outcome"][i] = r.outcome
        out["max_rotation"][i] = r.max_rotation
        out["t_overturn"][i] = r.t_overturn
        out["t_end"][i] = r.t
        out["n_impacts"][i] = r.n_impacts
        out["status"][i] = STATUS_CODES.index(r.status)
    return out


#: The kernels by method: ``"scipy"`` (any :class:`rockjit.Scipy`) and, once
#: :func:`kernel_for` has been asked for them, ``"rockjit"`` and ``"rockjit-cuda"`` (the
#: compiled path on the GPU).
KERNELS = {"scipy": scipy_kernel}


def kernel_for(method, device="cpu"):
    """The kernel of ``method`` (``"rockjit"`` or a :class:`rockjit.Scipy`) on ``device``
    (``"cpu"``, or ``"cuda"`` for the compiled path on the GPU; the scipy path runs on the CPU
    only: ``ValueError``)."""
    if method != "rockjit":
        if device == "cuda":
            from ..settings import scipy_on_cuda
            raise ValueError(scipy_on_cuda())
        return KERNELS["scipy"]
    name = "rockjit-cuda" if device == "cuda" else "rockjit"
    if name not in KERNELS:
        from .compiled import compiled_kernel, cuda_kernel  # numba only when asked for
        KERNELS.update({"rockjit": compiled_kernel, "rockjit-cuda": cuda_kernel})
    return KERNELS[name]


def transient_scipy():
    """The scipy path the spectra and fragility curves use by default: DOP853 at
    ``rtol = 1e-10, atol = 1e-12`` (an explicit method suits the non-stiff block; the tight
    tolerances keep the bisections' outcomes a property of the model, not of the solver)."""
    from ..single import Scipy
    return Scipy("DOP853", rtol=1e-10, atol=1e-12)


def check_method(method):
    """``"rockjit"`` (the compiled path), or the :class:`rockjit.Scipy` of ``method``
    (``"scipy"``, ``"scipy:<M>"`` or a Scipy)."""
    from ..single import _method
    return _method(method)


def grid_method(method):
    """The method of a grid: ``"rockjit"`` (the compiled kernel, the default), else the
    :class:`rockjit.Scipy` of ``method`` (:func:`transient_scipy` is the one the checks use:
    DOP853 at ``rtol = 1e-10, atol = 1e-12``)."""
    if method is None or method == "rockjit":
        kernel_for("rockjit")
        return "rockjit"
    return check_method(method)


#: The fewest cells of a chunk of the compiled kernel in this process: each call starts the
#: kernel's threads, which costs up to about ten milliseconds on a loaded machine, as much as
#: a hundred pulse runs.
MIN_COMPILED_CHUNK = 2048


def default_chunk(n, compiled=False):
    """Cells per chunk: about a twentieth of the batch (the unit of progress and of Dask
    tasks), at least one; with ``compiled`` (the compiled kernel in this process) at least
    :data:`MIN_COMPILED_CHUNK`."""
    return max(MIN_COMPILED_CHUNK if compiled else 1, math.ceil(n / 20))


@contextlib.contextmanager
def _threads(threads):
    """numba's threads set to ``threads`` (``Execution.threads``) for the block, if given."""
    if threads is None:
        yield
        return
    import numba
    old = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        yield
    finally:
        numba.set_num_threads(old)


def run_batch(batch, settings, method, execution=None, label="cells"):
    """Every cell of ``batch`` through the kernel of ``method``, chunk by chunk, as
    ``execution`` (a :class:`rockjit.Execution`) says: in this process (the compiled kernel on
    ``threads`` numba threads) or on a Dask cluster, with progress, and with a chunk store
    (``store``) where finished chunks are kept, so that the same batch run again with the same
    store computes only the chunks missing (:class:`rockjit.storage.chunkstore.ChunkStore`:
    a store of another computation is refused). Returns the outputs by name
    (:data:`OUTPUTS`)."""
    from ..grids.runner import _client, run_chunks
    from ..settings import Execution
    from ..storage import chunkstore
    ex = Execution() if execution is None else execution
    kernel = kernel_for(method, ex.device)
    n = len(batch)
    outputs = empty_outputs(n)
    if n == 0:
        return outputs
    # task keys unique to this call: a bisection runs many batches on one cluster
    prefix = f"rockjit-{label.replace(' ', '-')}-{uuid.uuid4().hex[:12]}"
    with _client(ex) as client, _threads(ex.threads if client is None else None):
        local = client is None and method == "rockjit"
        if ex.chunk is not None:
            chunk = ex.chunk
        elif ex.device == "cuda":  # few, large launches (rockjit._engine.gpu.default_chunk)
            from .._engine.gpu import default_chunk as gpu_chunk
            chunk = gpu_chunk(n)
        else:
            chunk = default_chunk(n, local)
        store = None
        if ex.store is not None:  # every input of every cell, and the kernel's outputs
            key = chunkstore.fingerprint_of("transient batch", batch.blocks, batch.sources,
                                            batch.block_of, batch.source_of, batch.gain,
                                            settings, method, sorted(OUTPUTS))
            store = chunkstore.ChunkStore(ex.store, key, n, chunk, message=ex.message)
        run_chunks(kernel, (batch.blocks, batch.sources, batch.block_of, batch.source_of,
                            batch.gain, settings, method), n, chunk, outputs, client=client,
                   store=store, progress=ex.progress, label=label, task_prefix=prefix,
                   message=ex.message, ahead=ex.device == "cuda")
    return outputs
