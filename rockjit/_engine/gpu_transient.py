"""Grids of the transient kernel (spectra of pulses, fragility over records) on an NVIDIA GPU: one
cell per thread, through numba's CUDA target, from the CPU kernel's own cell.

Nothing of the integrator is written here. The CUDA kernel :func:`_cells` gives each thread one
cell and calls :func:`rockjit._engine.transient.run_cell`, the cell the CPU's
:func:`~rockjit._engine.transient.run_cells` runs in its ``prange`` loop: the same step, events,
physics (:mod:`rockjit.model`), restitution laws (:mod:`rockjit.laws`) and excitation plugs
(:mod:`rockjit.plugs`), compiled again for the device by numba's CUDA target. A cell allocates
nothing: it keeps neither its impacts nor its trajectory (buffers of no rows, shared), and its
outputs are its rows of two global arrays.

The inputs are the CPU kernel's (:func:`rockjit.ground.compiled.pack`): one forcing row per
cell, the plugs' coefficients in one flat array, one row per block. Results differ from the
CPU's in the last bits where the device's ``sin``, ``cos`` and ``exp`` (libdevice's) or its fused
multiply-adds round otherwise (:mod:`rockjit._engine.gpu` says where); an outcome can change
only for a cell on the edge of overturning.
"""

from __future__ import annotations

import numpy as np
from numba import cuda

from . import transient as T
from .gpu import BLOCK, SIMULATOR, _a

__all__ = ["kernels", "run_cells", "signatures"]


@cuda.jit(cache=not SIMULATOR)
def _cells(xpar, rec, bpar, block_of, spar, t_lim, max_impacts, decide, none, out_f, out_i):
    """Thread ``i``: cell ``i`` (forcing row ``xpar[i]``, block row ``bpar[block_of[i]]``, time
    limit ``t_lim[i]``) from rest, into ``out_f[i]`` and ``out_i[i]``
    (:func:`rockjit._engine.transient.run_cell`)."""
    i = cuda.grid(1)
    if i >= xpar.shape[0]:
        return
    b = block_of[i]
    T.run_cell(_a(xpar)[i], _a(rec), _a(bpar)[b], _a(spar), t_lim[i], max_impacts, decide,
               0.0, 0.0, 0, _a(none), _a(none), _a(out_f)[i], _a(out_i)[i])


def kernels():
    """The CUDA kernels this driver launches, by name."""
    return {"transient": _cells}


def signatures():
    """The argument types of each kernel of :func:`kernels` (C-contiguous arrays as
    :func:`run_cells` makes them), by name."""
    from numba import types as nt
    f1, f2 = nt.float64[::1], nt.float64[:, ::1]
    i1, i2 = nt.int64[::1], nt.int64[:, ::1]
    return {"transient": (f2, f1, f2, i1, f1, f1, nt.int64, nt.boolean, f2, f2, i2)}


def run_cells(xpar, rec, bpar, block_of, spar, t_lim, max_impacts, decide, out_f, out_i):
    """:func:`rockjit._engine.transient.run_cells` on the GPU: the same inputs, the outputs
    written into ``out_f`` and ``out_i`` (host arrays)."""
    n = xpar.shape[0]
    if n == 0:
        return
    c = np.ascontiguousarray
    d_in = [cuda.to_device(c(a, dtype=t)) for a, t in (
        (xpar, np.float64), (rec, np.float64), (bpar, np.float64), (block_of, np.int64),
        (spar, np.float64), (t_lim, np.float64))]
    none = cuda.to_device(np.zeros((0, 3)))
    d_f = cuda.device_array((n, T.N_TF))
    d_i = cuda.device_array((n, T.N_TI), dtype=np.int64)
    _cells[(n + BLOCK - 1) // BLOCK, BLOCK](*d_in, int(max_impacts), bool(decide), none, d_f,
                                            d_i)
    cuda.synchronize()
    out_f[:] = d_f.copy_to_host()
    out_i[:] = d_i.copy_to_host()
