"""Grids of the harmonic kernels on an NVIDIA GPU: one cell per thread, through numba's CUDA
target, from the CPU kernels' own step, events, physics and classification.

Nothing of the integrator is written here. A CUDA kernel (:func:`_cells_plain`, and
:func:`_cells_tangent` with the exponents' tangent vectors) gives each thread one cell and
calls the compiled pieces the CPU kernels call: :func:`rockjit._engine.integrate.start_state`,
:func:`~rockjit._engine.integrate.grid_step` (the Dormand–Prince step of
:mod:`rockjit._engine.step`, the events of :mod:`rockjit._engine.events`, the physics of
:mod:`rockjit.model`) and :func:`~rockjit._engine.integrate.finish`, through :func:`run_cell`
(the loop of :func:`rockjit._engine.integrate.drive`, its tables made beforehand), then the
cell's classification and samples (:func:`rockjit._engine.cell._classify`,
:func:`~rockjit._engine.cell._collect`), as :func:`rockjit._engine.kernel._grid` does. numba's
CUDA target compiles those ``numba.njit`` functions again for the device from their Python
source.

Memory: a step's work arrays (stages, states, step table, stage forcing) are each thread's
``cuda.local.array`` scratch; the step table of a grid step and the forcing table of a period
are made once per distinct forcing (:func:`_tables`; one for all cells of a basin) and read by
every cell of that forcing; the stroboscopic samples, impact ring, running exponents and
impact counts that the classification reads are preallocated global scratch, one slice per
thread, reused from one launch to the next (a launch holds as many cells as
:func:`batch_cells` lets fit in the device's memory).

Results differ from the CPU's in the last bits: the device's ``sin``, ``cos``, ``exp`` and
``log`` are libdevice's, not the host's libm, and NVVM may fuse a multiplication and an
addition into one ``fma`` where the CPU code rounds twice (the explicit fused multiply-adds of
the stage chain are ``fma.rn.f64`` on both). Periodic cells agree to rounding; a cell on a basin
boundary or in chaos may take another branch.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import config, cuda, float64, int64

from . import integrate as ig
from .cell import _classify, _collect
from .layout import (I_N, I_PERIODS, N_FOUT, N_FTAB, N_IOUT, N_PAR, N_PARW, Outputs, P_AW2,
                     P_CTHC, P_H, P_OMEGA, P_PHI, P_STHC, P_THC, Work)
from .stages import compile_step
from .tableau import N_STAGES, N_TAB
from .._jit import jit
from ..model import initial_side

__all__ = ["BLOCK", "GPU_CHUNK", "SIMULATOR", "batch_cells", "cell_bytes", "cells_kernel",
           "default_chunk", "kernels", "run_cell", "run_chunk", "signatures"]

#: Threads per block of the cells' kernels.
BLOCK = 128
#: Rows of a step's stage table (stages and the step's end): a literal for ``cuda.local.array``.
NK = N_STAGES + 1
#: The forcing's columns of a parameter row: cells that agree in them share their tables.
FORCING_COLS = (P_AW2, P_OMEGA, P_PHI, P_H)
#: Whether numba runs CUDA kernels in its simulator (``NUMBA_ENABLE_CUDASIM=1``), as Python.
SIMULATOR = bool(getattr(config, "ENABLE_CUDASIM", False))

if SIMULATOR:
    def _a(x):
        """The simulator hands a kernel its arrays wrapped; the CPU-compiled pieces it calls
        take numpy's."""
        while not isinstance(x, np.ndarray):
            x = x._item._ary if hasattr(x, "_item") else x._ary
        return x
else:
    @cuda.jit(device=True, inline=True)
    def _a(x):
        """The array itself (on the simulator, the numpy array within its wrapper)."""
        return x


@jit(nrt=False)
def run_cell(TANGENT, y0, side0, par, ipar, out, w):
    """One cell's run with the tables ``w.tab_h`` and ``w.ftab`` already made
    (:func:`rockjit._engine.integrate.tables`, once per forcing): the start and the driver loop
    of a run on the CPU (:func:`~rockjit._engine.integrate.drive`);
    returns the status code."""
    status = ig.start_state(None, TANGENT, y0, side0, par, ipar, out, w)
    # recording is the CPU loop's run-time switch (off here: one trajectory row), so that the
    # CPU's compilation of the loop serves this one too
    return ig.drive(None, TANGENT, out.traj.shape[0] > 1, status, side0, par, ipar, out, w)


# ---- the kernels -----------------------------------------------------------------------------

@cuda.jit(cache=not SIMULATOR)
def _tables(fpars, ipar, tab_hs, ftabs):
    """Thread ``f``: the step table of a grid step and the forcing table of a period of the
    forcing row ``fpars[f]`` (:func:`rockjit._engine.integrate.tables`)."""
    f = cuda.grid(1)
    if f >= fpars.shape[0]:
        return
    par = cuda.local.array(N_PARW, float64)
    for m in range(N_PARW):
        par[m] = 0.0
    for m in range(N_PAR):
        par[m] = fpars[f, m]
    v = cuda.local.array(1, float64)
    v2 = cuda.local.array((1, 1), float64)
    w = Work(v2, v, v, v, v, v, _a(tab_hs[f]), v2, v, v, v, _a(ftabs[f]))
    ig.tables(None, par, _a(ipar), w)


#: The cells' kernel, rendered for each set of switches: ``{TANGENT}`` (``None`` or ``True``),
#: ``{NY}`` (the state's length: 2, or 6 with the tangent matrix).
_CELLS = """\
i = cuda.grid(1)
if i >= y0s.shape[0]:
    return
par = cuda.local.array(N_PARW, float64)
for m in range(N_PAR):
    par[m] = pars[i, m]
par[P_STHC] = math.sin(pars[i, P_THC])
par[P_CTHC] = math.cos(pars[i, P_THC])
K = cuda.local.array((NK, {NY}), float64)
states = cuda.local.array((4, {NY}), float64)
for r in range(NK):
    for m in range({NY}):
        K[r, m] = 0.0
for r in range(4):
    for m in range({NY}):
        states[r, m] = 0.0
lam = cuda.local.array(4, float64)
trig = cuda.local.array(4, float64)
for m in range(4):
    lam[m] = 0.0
    trig[m] = 0.0
tab = cuda.local.array((N_TAB, NK), float64)
for r in range(N_TAB):
    for m in range(NK):
        tab[r, m] = 0.0
fr = cuda.local.array(NK, float64)
jac = cuda.local.array(NK, float64)
for m in range(NK):
    fr[m] = 0.0
    jac[m] = 0.0
traj = cuda.local.array((1, 5), float64)
for m in range(5):
    traj[0, m] = 0.0
iout = cuda.local.array(N_IOUT, int64)
for m in range(N_IOUT):
    iout[m] = 0
fout = cuda.local.array(N_FOUT, float64)
for m in range(N_FOUT):
    fout[m] = 0.0
imp = _a(impacts[i])
for r in range(imp.shape[0]):
    for m in range(3):
        imp[r, m] = 0.0
f = fidx[i]
w = Work(K, states[0], states[1], states[2], states[3], lam, _a(tab_hs[f]), tab, fr, jac,
         trig, _a(ftabs[f]))
out = Outputs(_a(strobe[i]), _a(half[i]), imp, traj, _a(lam_run[i]), _a(per_imp[i]), iout,
              fout)
y0 = _a(y0s[i])
ip = _a(ipar)
status = run_cell({TANGENT}, y0, initial_side(y0[0], y0[1]), par, ip, out, w)
_classify({TANGENT}, status, ip, _a(cpar), out, _a(res[i]))
_collect(i, par[P_H] * ip[I_N], n_pts, n_imp_pts, out, _a(res), _a(pts), _a(imp_pts),
         _a(n_got), _a(n_imp_got))"""

_CELL_ARGS = ("y0s, pars, fidx, tab_hs, ftabs, ipar, cpar, n_pts, n_imp_pts, strobe, half, "
              "impacts, lam_run, per_imp, res, pts, imp_pts, n_got, n_imp_got")

_DOC = """Thread ``i``: cell ``i`` from ``y0s[i]`` with the parameter row ``pars[i]`` and the
    tables ``tab_hs[fidx[i]]``, ``ftabs[fidx[i]]``; its samples in the scratch ``strobe[i]``,
    ``half[i]``, ``impacts[i]``, ``lam_run[i]``, ``per_imp[i]``; its results in ``res[i]``,
    ``pts[i]``, ``imp_pts[i]``, ``n_got[i]``, ``n_imp_got[i]`` (:func:`rockjit._engine.kernel.
    _grid`'s outputs)."""

_cells_plain = compile_step("_cells_plain", _CELL_ARGS,
                            _CELLS.format(TANGENT="None", NY=2).split("\n"), globals(),
                            cuda.jit(cache=not SIMULATOR), doc=_DOC)
_cells_tangent = compile_step("_cells_tangent", _CELL_ARGS,
                              _CELLS.format(TANGENT="True", NY=6).split("\n"), globals(),
                              cuda.jit(cache=not SIMULATOR), doc=_DOC)


@functools.lru_cache(maxsize=None)
def cells_kernel(tangent, max_registers=None):
    """The cells' kernel with or without tangent vectors; ``max_registers`` caps the registers
    a thread may use (more threads resident on a multiprocessor, more values spilled to local
    memory: which is faster depends on the device, ``benchmarks/bench_gpu.py`` measures it);
    ``None``, as many as the compiler takes (all 255 for the kernel without exponents)."""
    if max_registers is None or SIMULATOR:
        return _cells_tangent if tangent else _cells_plain
    r = int(max_registers)
    name = f"_cells_{'tangent' if tangent else 'plain'}_r{r}"
    lines = _CELLS.format(TANGENT="True" if tangent else "None", NY=6 if tangent else 2)
    return compile_step(name, _CELL_ARGS, lines.split("\n"), globals(),
                        cuda.jit(cache=True, max_registers=r), doc=_DOC)


def kernels():
    """The CUDA kernels the driver launches, by name: ``tables``, ``cells`` (no tangent
    vectors), ``cells+tangent``."""
    return {"tables": _tables, "cells": _cells_plain, "cells+tangent": _cells_tangent}


def signatures():
    """The argument types each kernel of :func:`kernels` is launched with (C-contiguous
    arrays as :func:`run_chunk` makes them), by name."""
    from numba import types as nt
    f1, f2, f3 = nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    i1, i2 = nt.int64[::1], nt.int64[:, ::1]
    cells = (f2, f2, i1, f3, f3, i1, f1, nt.int64, nt.int64, f3, f3, f3, f3, i2, f2, f3, f3,
             i1, i1)
    return {"tables": (f2, i1, f3, f3), "cells": cells, "cells+tangent": cells}


# ---- the host's side -------------------------------------------------------------------------

def cell_bytes(periods, n_imp_pts, tangent):
    """Bytes of global scratch a cell holds while it runs (its samples, impact ring, running
    exponents, impact counts)."""
    p1 = periods + 1
    return 8 * (4 * p1 + 4 * p1 + 3 * max(n_imp_pts, 1) + 3 * (p1 if tangent else 1) + p1)


def batch_cells(n, periods, n_imp_pts, tangent, free_bytes):
    """Cells per launch: all ``n``, or as many as half the device's free memory holds in
    scratch (at least one block of threads)."""
    fit = int(0.5 * free_bytes // cell_bytes(periods, n_imp_pts, tangent))
    return max(1, min(n, max(BLOCK, fit)))


#: The fewest cells of a chunk on the GPU by default (:func:`default_chunk`).
GPU_CHUNK = 1 << 20


def default_chunk(n):
    """Cells per chunk on the GPU when none is given: the whole grid up to
    :data:`GPU_CHUNK` cells, else about a twentieth of it
    (:func:`rockjit._engine.kernel.default_chunk`). A chunk's launch ends with its slowest
    cell, while the device empties: fewer, larger chunks pay that tail fewer times (an
    early-stopped basin's slowest cells run the full length), and a small one leaves most of a
    large GPU idle."""
    from .kernel import default_chunk as cpu_chunk
    return max(GPU_CHUNK, cpu_chunk(n))


def _forcings(pars):
    """The distinct forcings of the parameter rows: ``(rows, index)`` with ``rows`` a parameter
    row of each and ``index[i]`` the one of row ``i``."""
    key = pars[:, list(FORCING_COLS)]
    if (key == key[0]).all():
        return pars[:1], np.zeros(pars.shape[0], dtype=np.int64)
    _, first, index = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return pars[first], np.ascontiguousarray(index.reshape(-1), dtype=np.int64)


def _free_bytes():
    """The device's free memory, once the arrays of earlier calls numba still holds for
    deferred freeing are freed."""
    if SIMULATOR:
        return 1 << 30
    ctx = cuda.current_context()
    ctx.deallocations.clear()
    free, _ = ctx.get_memory_info()
    return free


def run_chunk(tangent, y0s, pars, ipar, cpar, n_pts, n_imp_pts, threads=None, lanes=None,
              batch=None, max_registers=None):
    """:func:`rockjit._engine.kernel.run_chunk` on the GPU: the same inputs, the same outputs
    by name (``threads`` and ``lanes`` are the CPU's and ignored here); ``batch`` cells at
    most per launch (default :func:`batch_cells`); ``max_registers``, as
    :func:`cells_kernel` takes it."""
    from .kernel import grid_outputs
    y0s = np.ascontiguousarray(y0s, dtype=np.float64)
    pars = np.ascontiguousarray(pars, dtype=np.float64)
    ipar = np.ascontiguousarray(ipar, dtype=np.int64)
    cpar = np.ascontiguousarray(cpar, dtype=np.float64)
    n = y0s.shape[0]
    out = grid_outputs(n, n_pts, n_imp_pts)
    if n == 0:
        return out
    periods = int(ipar[I_PERIODS])
    fpars, fidx = _forcings(pars)
    nf = fpars.shape[0]
    d_fpars = cuda.to_device(np.ascontiguousarray(fpars))
    d_ipar = cuda.to_device(ipar)
    tab_hs = cuda.to_device(np.zeros((nf, N_TAB, NK)))
    ftabs = cuda.to_device(np.zeros((nf, max(int(ipar[I_N]), 1), N_FTAB)))
    _tables[(nf + BLOCK - 1) // BLOCK, BLOCK](d_fpars, d_ipar, tab_hs, ftabs)
    d_in = [cuda.to_device(a) for a in (y0s, pars, fidx)]
    d_cpar = cuda.to_device(cpar)
    names = ("res", "pts", "imp", "n_got", "n_imp_got")
    d_out = {k: cuda.to_device(out[k]) for k in names}
    b = batch_cells(n, periods, n_imp_pts, tangent, _free_bytes()) if batch is None \
        else max(1, min(n, int(batch)))
    p1 = periods + 1
    strobe = cuda.device_array((b, p1, 4))
    half = cuda.device_array((b, p1, 4))
    impacts = cuda.device_array((b, max(n_imp_pts, 1), 3))
    lam_run = cuda.device_array((b, p1 if tangent else 1, 3))
    per_imp = cuda.device_array((b, p1), dtype=np.int64)
    cells = cells_kernel(bool(tangent), max_registers)
    for a in range(0, n, b):
        e = min(n, a + b)
        m = e - a
        cells[(m + BLOCK - 1) // BLOCK, BLOCK](
            d_in[0][a:e], d_in[1][a:e], d_in[2][a:e], tab_hs, ftabs, d_ipar, d_cpar,
            int(n_pts), int(n_imp_pts), strobe, half, impacts, lam_run, per_imp,
            *(d_out[k][a:e] for k in names))
    cuda.synchronize()
    return {k: d_out[k].copy_to_host() for k in names}
