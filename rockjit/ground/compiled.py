"""The compiled kernel of the transient batches: pulses and records on the compiled path.

:func:`pack` turns a chunk of a :class:`rockjit.ground.batch.Batch` into arrays (one row per block,
one per cell's forcing, every excitation's coefficients in one flat array); :func:`compiled_kernel`
runs its cells in parallel in :func:`rockjit._engine.transient.run_cells` and :func:`cuda_kernel`
one per GPU thread (:mod:`rockjit._engine.gpu_transient`); they are ``KERNELS["rockjit"]`` and
``KERNELS["rockjit-cuda"]`` of :mod:`rockjit.ground.batch`, registered when a batch first asks for
them. :func:`run_compiled` is a single run (:func:`rockjit.simulate`) on the same code. The cells
follow the scipy reference path (:mod:`rockjit.ground.reference`) phase by phase; at the step
lengths below they agree with scipy's DOP853 at ``rtol = 1e-13`` to about 1e-11 in ``max |theta| /
alpha_s`` and 4e-11 in the overturning time of a pulse run (tests/ground/test_ground_compiled.py,
benchmarks/bench_ground.py).

Step lengths, in model time (``1/sqrt(g/R)``, about 0.32 s for a 1 m block): each excitation's
plug gives its grid (:meth:`rockjit.plugs.TransientPlug.grid`: a pulse in equal steps of at most
:data:`H_PULSE` and at least :data:`MIN_PULSE_STEPS` of them; a record's sample step in the
fewest equal steps of at most :data:`H_RECORD`, so that its samples, the kinks of the linear
interpolation, are step boundaries); free rocking after the excitation takes steps of
:data:`H_FREE`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._engine import transient as T
from ..model import damping_rate, initial_side
from ..plugs.pulse import H_PULSE, MIN_PULSE_STEPS
from ..plugs.record import H_RECORD
from ..validate import memory
from .response import STATUS_CODES, TransientResult, alpha_s, empty_outputs

__all__ = ["H_FREE", "H_PULSE", "H_RECORD", "MIN_PULSE_STEPS", "compiled_kernel", "cuda_kernel",
           "pack", "run_compiled"]

#: The step of free rocking after the excitation.
H_FREE = 0.01
#: The largest ``h 3/4 xi`` of a step: a heavily damped block (``xi`` up to 1e4) gets shorter
#: steps, inside the explicit tableau's region of stability (``rockjit.single.STABLE_DAMPING``
#: is 3).
DAMPED_STEP = 2.0

assert STATUS_CODES[T.ST_DECIDED] == "decided" and STATUS_CODES[T.ST_REST] == "rest"


def _block_row(block, theta_over):
    th_top = min(alpha_s(block.hb), theta_over)
    return (block.thc, block.xi, block.restitution, block.cot, th_top, alpha_s(block.hb),
            *block.impact_law)


def _sources(sources, shrink):
    """``(rows, coefficients)``: each source's forcing row (its plug's code, end and grid, with
    the step lengths multiplied by ``shrink``) and every source's coefficients in one flat
    array, where the rows point."""
    rows = np.zeros((len(sources), T.N_X))
    chunks = []
    off = 0
    for k, src in enumerate(sources):
        coef = np.asarray(src.coefficients(), dtype=float)
        steps, kink = src.grid(shrink)
        rows[k, T.X_CODE] = src.code
        rows[k, T.X_END] = src.end
        rows[k, T.X_DT] = kink
        rows[k, T.X_OFF] = off
        rows[k, T.X_N] = coef.size
        rows[k, T.X_STEPS] = steps
        chunks.append(coef)
        off += coef.size
    return rows, np.concatenate(chunks) if chunks else np.zeros(1)


def _shrink(blocks):
    """The factor on the step lengths for the most damped of ``blocks`` (:data:`DAMPED_STEP`)."""
    xi = max(b.xi for b in blocks)
    if xi <= 0.0:
        return 1.0
    return min(1.0, DAMPED_STEP / (damping_rate(xi) * max(H_PULSE, H_RECORD, H_FREE)))


def pack(blocks, sources, block_of, source_of, gain, settings):
    """A chunk of cells as the transient kernel reads them: the arguments of
    :func:`rockjit._engine.transient.run_cells` before the thread stride and outputs
    (``xpar, coefficients, bpar, block_of, spar, t_lim, max_impacts, decide``)."""
    bpar = np.array([_block_row(b, settings.theta_over) for b in blocks], dtype=float)
    shrink = _shrink(blocks)
    rows, samples = _sources(sources, shrink)
    source_of = np.asarray(source_of, dtype=np.int64)
    gain = np.asarray(gain, dtype=float)
    xpar = rows[source_of]
    xpar[:, T.X_AMP] = _amplitudes(sources, source_of, gain)
    t_lim = np.array([settings.limit(float(src.end)) for src in sources])[source_of]
    spar = np.array([settings.theta_over, settings.rest_speed, shrink * H_FREE])
    return (xpar, samples, bpar, np.asarray(block_of, dtype=np.int64), spar, t_lim,
            int(settings.impact_bound()), bool(settings.stop_when_decided))


def compiled_kernel(blocks, sources, block_of, source_of, gain, settings, method):
    """The compiled path on a chunk of cells (the kernel interface of
    :mod:`rockjit.ground.batch`): every cell from rest, in parallel on the CPU's threads."""
    def on_threads(cells, out_f, out_i):
        T.run_cells(*cells, numba.get_num_threads(), out_f, out_i)
    return _run_chunk(on_threads, blocks, sources, block_of, source_of, gain, settings)


def cuda_kernel(blocks, sources, block_of, source_of, gain, settings, method):
    """:func:`compiled_kernel` on the GPU, one cell per thread
    (:mod:`rockjit._engine.gpu_transient`): the same inputs and outputs."""
    from .._engine import gpu_transient

    def on_gpu(cells, out_f, out_i):
        gpu_transient.run_cells(*cells, out_f, out_i)
    return _run_chunk(on_gpu, blocks, sources, block_of, source_of, gain, settings)


def _run_chunk(run, blocks, sources, block_of, source_of, gain, settings):
    """A chunk packed (:func:`pack`) and run by ``run(cells, out_f, out_i)``: the batch's
    outputs by name."""
    n = len(gain)
    if n == 0:
        return empty_outputs(n)
    out_f = np.empty((n, T.N_TF))
    out_i = np.empty((n, T.N_TI), dtype=np.int64)
    run(pack(blocks, sources, block_of, source_of, gain, settings), out_f, out_i)
    return _outputs(out_f, out_i)


def _outputs(out_f, out_i):
    """The kernel's output arrays as the batch's outputs by name."""
    out = empty_outputs(out_f.shape[0])
    out["max_rotation"][:] = out_f[:, T.TF_MAXROT]
    out["t_overturn"][:] = out_f[:, T.TF_TOVER]
    out["t_end"][:] = out_f[:, T.TF_T]
    out["outcome"][:] = out_i[:, T.TI_OUTCOME]
    out["n_impacts"][:] = out_i[:, T.TI_IMPACTS]
    out["status"][:] = out_i[:, T.TI_STATUS]
    return out


def _amplitudes(sources, source_of, gain):
    """Every cell's amplitude, its source's :meth:`~rockjit.plugs.TransientPlug.amplitude_at` at
    the cell's gain (a pulse's ``accel`` once scaled, ``amplitude * gain / hb``, as the
    reference path forms it; a record's ``scale * gain``)."""
    out = np.empty(len(gain))
    for k, src in enumerate(sources):
        cells = np.flatnonzero(source_of == k)
        out[cells] = src.amplitude_at(gain[cells])
    return out


def run_compiled(block, excitation, state, settings) -> TransientResult:
    """One run of ``block`` under the bound transient ``excitation`` from ``state``
    (``(theta0, theta0')``) with the :class:`rockjit.Transient` ``settings``, on the compiled
    path: the trajectory at the grid's points and the events (``settings.record``), every
    impact."""
    shrink = _shrink((block,))
    rows, samples = _sources((excitation,), shrink)
    rows[0, T.X_AMP] = excitation.amplitude_at(np.ones(1))[0]
    bpar = np.array(_block_row(block, settings.theta_over), dtype=float)
    spar = np.array([settings.theta_over, settings.rest_speed, shrink * H_FREE])
    end = float(excitation.end)
    t_lim = float(settings.limit(end))
    max_imp = int(settings.impact_bound())
    th0, v0 = float(state[0]), float(state[1])
    side0 = int(initial_side(th0, v0))
    # buffers: the grid's points and a few per impact; a run that needs more runs again with
    # exactly what it needed (the run is deterministic)
    n_imp = min(max_imp, 1024)
    n_traj = 0
    if settings.record:
        kink = rows[0, T.X_DT]
        steps = rows[0, T.X_STEPS] * (round(end / kink) if kink > 0.0 else 1)
        n_traj = int(steps + (t_lim - min(end, t_lim)) / (shrink * H_FREE)) + 2 * n_imp + 16
    memory(f"a run recorded over {t_lim:.4g} time units (the Transient's free_time or "
           f"duration)", 24.0 * (float(n_traj) + float(n_imp)))
    out_f = np.empty(T.N_TF)
    out_i = np.zeros(T.N_TI, dtype=np.int64)
    for _ in range(2):
        imp = np.empty((n_imp, 3))
        traj = np.empty((n_traj, 3))
        T.run_cell(rows[0], samples, bpar, spar, t_lim, max_imp,
                   bool(settings.stop_when_decided), th0, v0, side0, imp, traj, out_f, out_i)
        got_imp, got_traj = int(out_i[T.TI_IMPACTS]), int(out_i[T.TI_TRAJ])
        if got_imp <= n_imp and (not settings.record or got_traj <= n_traj):
            break
        n_imp, n_traj = got_imp, (got_traj if settings.record else 0)
    return TransientResult(
        block=block, excitation=excitation, settings=settings, method="rockjit",
        status=STATUS_CODES[int(out_i[T.TI_STATUS])], t=float(out_f[T.TF_T]),
        state=np.array([out_f[T.TF_TH], out_f[T.TF_DTH]]), t_uplift=float(out_f[T.TF_TUP]),
        max_theta=float(out_f[T.TF_MAXTH]), impacts=imp[:got_imp].copy(),
        t_overturn=float(out_f[T.TF_TOVER]),
        trajectory=traj[:got_traj].copy() if settings.record else None,
        n_rhs=6 * int(out_i[T.TI_STEPS]), n_rest=int(out_i[T.TI_REST]))

