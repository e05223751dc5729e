"""Grids on an NVIDIA GPU beside the same grids on all the host's CPU cores (device="cuda").

The cells of each grid run through the grid runner as ``Execution(device="cuda")`` runs them
(rockjit._engine.gpu: one cell per GPU thread, the CPU kernels' own step, events and
classification compiled by numba's CUDA target, transfers included) and as
``Execution(device="cpu")`` runs them on every core (rockjit.grids.runner: pieces on one thread
each, eight cells per thread in lockstep where there are no exponents). Cases: the study's
basin (h/b = 1, Housner, alpha = 0.66, omega = 1.3, 500 periods) at 100 x 100, 300 x 300 and
1000 x 1000, full length and early-stopped; the study's sweep (omega = 1.3, 501 amplitudes in
[0.5, 1], 500 periods, full length, with exponents); a 200 x 200 (alpha, omega) plane with
exponents (early-stopped); the transient kernel (rockjit._engine.gpu_transient) on a 400 x 400
overturning spectrum of the one-sine pulse (h/b = 4, the grid without the bisections) and on an
incremental dynamic analysis of 44 synthetic far-field-like records (20 s at 100 Hz, the FEMA
P695 set where it is installed) at 50 intensities under both laws; and a balanced yardstick,
one source compiled for both devices: 10^6 cells, each 2000 RK4 steps of a damped linear
oscillator in registers (what the devices' fp64 arithmetic gives with every cell the same work and no memory traffic). Times are medians
of repeats, GPU and CPU interleaved, compile excluded (a warm-up call first); the CPU's
1000 x 1000 full-length basin is extrapolated from its 300 x 300 cells per second (it would
take minutes). Agreement: the cells whose label or period differ between the devices, and
of those at 100 x 100 how many the uncertainty test (initial states moved by 1e-9, on the
CPU) does not flag; the largest difference of the stroboscopic samples of the cells both call
periodic (for the transient grids: the cells whose outcome differs, and the largest
difference of max |theta| / alpha_s).

    PYTHONPATH=. python benchmarks/bench_gpu.py           # full, on a machine with a GPU
    PYTHONPATH=. python benchmarks/bench_gpu.py --quick   # smoke: small grids, 60 periods

Writes gpu.{md,csv,json} to benchmarks/results/ (or to $OUT when set, or to --out DIR); on a
machine without a usable GPU the page says so ("not measured on a GPU yet") and lists the cases.
"""

from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import replace

import numpy as np

if not hasattr(np, "row_stack"):  # numba-cuda 0.30 still calls it; numpy 2.5 removed it
    np.row_stack = np.vstack

try:
    from numba import cuda
except Exception:  # numba-cuda absent: the page says the GPU was not measured
    cuda = None

import _common as H

import rockjit
from rockjit import Block, Classification, Execution, Harmonic, Integration
from rockjit._engine.cell import R_LABEL, R_PERIOD
from rockjit._engine.layout import I_SETTLE
from rockjit.grids import plan as gp
from rockjit.grids import runner
from rockjit.result import ASYMMETRIC, MULTIPERIODIC, SYMMETRIC
from rockjit.settings import cuda_missing

FULL = dict(basins=(100, 300, 1000), periods=500, alphas=501, plane=200, repeats=3,
            cpu_cells_max=100_000, budget_s=220.0, yard_cells=10**6, yard_steps=2000,
            spectrum=400, records=44, levels=50)
QUICK = dict(basins=(12, 20), periods=60, alphas=21, plane=10, repeats=1,
             cpu_cells_max=400, budget_s=120.0, yard_cells=1000, yard_steps=100,
             spectrum=12, records=2, levels=4)
#: Relative move of the initial states in the uncertainty test of the agreement.
EPS = 1e-9
HEADERS = ("case", "cells", "gpu_s", "cpu_s", "cpu_basis", "speedup", "cells_per_s_gpu",
           "labels_differ", "differ_unflagged", "max_strobe_diff", "measured")
PERIODIC = (SYMMETRIC, ASYMMETRIC, MULTIPERIODIC)


def cases(cfg):
    """``(key, plan)`` of every case, smallest first within each kind."""
    block, study = Block(hb=1.0, law="housner"), Harmonic(alpha=0.66, omega=1.3)
    integ = Integration(periods=cfg["periods"])
    out = []
    for g in cfg["basins"]:
        for early in (False, True):
            key = f"basin {g}x{g}, {'early-stopped' if early else 'full length'}"
            out.append((key, rockjit.basin.plan(
                block, study, grid=g, integration=integ,
                classification=Classification(early_stop=early))))
    n = cfg["alphas"]
    out.append((f"sweep of {n} amplitudes, exponents, full length", rockjit.sweep.plan(
        block, Harmonic(omega=1.3), np.linspace(0.5, 1.0, n), integration=integ,
        classification=Classification(early_stop=False), lyapunov=True)))
    g = cfg["plane"]
    out.append((f"plane {g}x{g}, exponents, early-stopped", rockjit.plane.plan(
        block, (0.2, 1.2), (0.8, 3.0), grid=(g, g), integration=integ, lyapunov=True)))
    return out


def transient_cases(cfg):
    """``(key, cells, run)`` of the transient grids: ``run(device)`` returns the result."""
    from bench_ground import records
    n = cfg["spectrum"]
    ratios, amplitudes = np.geomspace(0.5, 8.0, n), np.geomspace(1.02, 25.0, n)
    recs, what = records(cfg["records"])
    levels = np.linspace(1.25, 10.0, cfg["levels"])

    def ex(device):
        return Execution(device=device, progress=False)

    def spectrum(device):
        return rockjit.spectrum(Block(hb=4.0), rockjit.Pulse("sine"), ratios, amplitudes,
                                locate=False, execution=ex(device))

    def ida(device):
        return rockjit.fragility(Block(hb=4.0), recs, [1.0], levels, laws=("housner", "mao"),
                                 execution=ex(device))

    return [(f"spectrum {n}x{n}, one-sine pulse, no bisection", n * n, spectrum),
            (f"fragility, {len(recs)} {what.split(' (')[0]}, {len(levels)} intensities, both "
             f"laws", 2 * len(recs) * len(levels), ida)]


def measure_transient(cfg, t0):
    """The transient grids on both devices: rows as :func:`measure` gives them; for
    agreement, the cells whose outcome differs and the largest difference of
    ``max |theta| / alpha_s`` over the cells with the same outcome."""
    rows, raw = [], {}
    for key, _, run in transient_cases(cfg):
        reps = cfg["repeats"] if time.monotonic() - t0 < 0.5 * cfg["budget_s"] else 1
        t = H.side_by_side({"gpu": lambda run=run: run("cuda"),
                            "cpu": lambda run=run: run("cpu")}, reps)
        g, c = t.result["gpu"], t.result["cpu"]
        n = int(np.asarray(c.outcome).size)
        same = np.asarray(g.outcome) == np.asarray(c.outcome)
        d = np.abs(np.asarray(g.max_rotation) - np.asarray(c.max_rotation))[same]
        d = d[np.isfinite(d)]
        gpu_s, cpu_s = t.median("gpu"), t.median("cpu")
        rows.append((key, n, gpu_s, cpu_s, f"median of {reps}", cpu_s / gpu_s, n / gpu_s,
                     int((~same).sum()), "", float(d.max()) if d.size else math.nan, "yes"))
        raw[key] = dict(gpu=t.wall["gpu"], cpu=t.wall["cpu"])
        print(f"{key}: GPU {gpu_s:.3f} s, CPU {cpu_s:.3f} s", flush=True)
    return rows, raw


def cells(p, device):
    """The grid's cells through the runner on ``device``: its outputs by name."""
    return runner.run_grid(p.y0s, p.pars, p.ipar, p.cpar, tangent=p.tangent, n_pts=p.n_pts,
                           n_imp_pts=p.n_imp_pts, label=p.kind,
                           execution=Execution(device=device, progress=False))


def agreement(g, c):
    """``(cells whose label or period differ, their mask, the largest difference of the
    stroboscopic samples of the cells both devices call periodic with the same period)``."""
    lg, lc = g["res"][:, R_LABEL], c["res"][:, R_LABEL]
    differ = (lg != lc) | (g["res"][:, R_PERIOD] != c["res"][:, R_PERIOD])
    both = ~differ & np.isin(lc, PERIODIC)
    d = np.abs(g["pts"][both] - c["pts"][both])
    d = d[np.isfinite(d)]
    return int(differ.sum()), differ, float(d.max()) if d.size else math.nan


def unflagged(p, differ):
    """Of the cells that differ, those the uncertainty test (on the CPU) does not flag."""
    res = gp.run(replace(p, uncertainty=EPS), Execution(progress=False))
    return int((differ & ~np.asarray(res.uncertain).ravel()).sum())


def warm_up(cfg):
    """Compile (or load) every kernel either device runs, on tiny grids."""
    small = dict(cfg, basins=(3,), periods=12, alphas=3, plane=2, spectrum=2, records=1,
                 levels=2)
    for _, p in cases(small):
        for device in ("cuda", "cpu"):
            cells(p, device)
    for _, _, run in transient_cases(small):
        for device in ("cuda", "cpu"):
            run(device)


def measure(cfg, t0):
    rows, raw = [], {}
    rate300 = None
    for key, p in cases(cfg):
        n = p.y0s.shape[0]
        late = time.monotonic() - t0 > cfg["budget_s"]
        on_cpu = not late and (n <= cfg["cpu_cells_max"] or p.ipar[I_SETTLE] > 0)
        fns = {"gpu": lambda p=p: cells(p, "cuda")}
        if on_cpu:
            fns["cpu"] = lambda p=p: cells(p, "cpu")
        # past half its time budget the run takes one repeat a case, so that it ends in time
        reps = cfg["repeats"] if time.monotonic() - t0 < 0.5 * cfg["budget_s"] else 1
        t = H.side_by_side(fns, reps)
        gpu_s = t.median("gpu")
        cpu_s, basis = math.nan, "not measured (time)" if late else "extrapolated"
        if on_cpu:
            cpu_s, basis = t.median("cpu"), f"median of {reps}"
            c = t.result["cpu"]
            if "basin" in key and "full" in key:
                rate300 = n / cpu_s
        elif rate300 is not None and not late and "basin" in key:
            cpu_s = n / rate300
        else:
            basis = "not measured (time)"
        differ_n, unfl, diff = "", "", math.nan
        if on_cpu:
            differ_n, mask, diff = agreement(t.result["gpu"], c)
            if p.kind == "basin" and p.shape[0] == cfg["basins"][0]:
                unfl = unflagged(p, mask)
        rows.append((key, n, gpu_s, cpu_s, basis, cpu_s / gpu_s, n / gpu_s, differ_n, unfl,
                     diff, "yes"))
        raw[key] = dict(gpu=t.wall["gpu"], cpu=t.wall.get("cpu", []))
        print(f"{key}: GPU {gpu_s:.3f} s, CPU {cpu_s:.3f} s ({basis}), differ {differ_n}",
              flush=True)
    return rows, raw


#: Register caps tried on the largest basin (numba-cuda's ``max_registers``; None: the
#: compiler's own choice, the driver's default).
REGISTERS = (None, 128)


def registers(cfg, t0):
    """The largest basin, full length and early-stopped, in one call of the driver with each
    register cap of :data:`REGISTERS`: rows, and the cells whose label differs from the
    default's (a cap changes where values live, not the arithmetic: none should)."""
    from rockjit._engine import gpu
    rows, raw = [], {}
    for key, p in cases(cfg):
        if p.kind != "basin" or p.shape[0] != cfg["basins"][-1]:
            continue
        args = (p.tangent, p.y0s, p.pars, p.ipar, p.cpar, p.n_pts, p.n_imp_pts)
        fns = {r: (lambda r=r: gpu.run_chunk(*args, max_registers=r)) for r in REGISTERS}
        for r in REGISTERS:
            gpu.run_chunk(*args[:1], p.y0s[:8], p.pars[:8], *args[3:], max_registers=r)
        reps = cfg["repeats"] if time.monotonic() - t0 < 0.5 * cfg["budget_s"] else 1
        t = H.side_by_side(fns, reps)
        base = t.result[None]["res"][:, R_LABEL]
        for r in REGISTERS:
            n, g = p.y0s.shape[0], t.median(r)
            differ = int((t.result[r]["res"][:, R_LABEL] != base).sum())
            cap = "registers as the compiler chose" if r is None else f"at most {r} registers"
            name = f"{key}, one call, {cap}"
            rows.append((name, n, g, "", "", "", n / g, differ, "", "", "yes"))
            raw[name] = dict(gpu=t.wall[r])
            print(f"{name}: GPU {g:.3f} s", flush=True)
    return rows, raw


def yardsticks():
    """The balanced yardstick, one source compiled for the CPU's cores (``prange``) and for
    the GPU (one cell per thread): every cell the same work, in registers."""
    import numba
    from bench_cores import rk4_cell
    step = numba.njit(cache=True)(rk4_cell)

    @numba.njit(parallel=True, cache=True)
    def on_cpu(n_cells, n_steps, out):
        for i in numba.prange(n_cells):
            out[i] = step(1.0 + 1e-9 * i, 0.0, n_steps)

    @cuda.jit
    def kernel(n_steps, out):
        i = cuda.grid(1)
        if i < out.shape[0]:
            out[i] = step(1.0 + 1e-9 * i, 0.0, n_steps)

    def on_gpu(n_cells, n_steps, out):
        d = cuda.device_array(n_cells)
        kernel[(n_cells + 127) // 128, 128](n_steps, d)
        d.copy_to_host(out)

    return on_cpu, on_gpu


def yardstick(cfg):
    """The yardstick's row: both devices, median of the repeats, and the largest difference
    of the cells' final values."""
    n, steps = cfg["yard_cells"], cfg["yard_steps"]
    on_cpu, on_gpu = yardsticks()
    a, b = np.zeros(n), np.zeros(n)
    on_cpu(n, 2, a)
    on_gpu(n, 2, b)
    t = H.side_by_side({"gpu": lambda: on_gpu(n, steps, b), "cpu": lambda: on_cpu(n, steps, a)},
                       cfg["repeats"])
    g, c = t.median("gpu"), t.median("cpu")
    return (f"yardstick: {n} cells of {steps} RK4 steps in registers", n, g, c,
            f"median of {cfg['repeats']}", c / g, n / g, "", "", float(np.abs(a - b).max()),
            "yes"), dict(gpu=t.wall["gpu"], cpu=t.wall["cpu"])


def device_name():
    name = getattr(cuda.get_current_device(), "name", "numba's CUDA simulator")
    return name.decode() if isinstance(name, bytes) else str(name)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--out" not in argv and os.environ.get("OUT"):
        argv += ["--out", os.environ["OUT"]]
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    missing = cuda_missing()
    head = f"### Grids on a GPU{H.quick_note(b.quick)}\n\n"
    if missing is not None:
        rows = [(key, p.y0s.shape[0], "", "", "", "", "", "", "", "", "no")
                for key, p in cases(cfg)]
        rows += [(key, n, "", "", "", "", "", "", "", "", "no")
                 for key, n, _ in transient_cases(cfg)]
        rows.append((f"yardstick: {cfg['yard_cells']} cells of {cfg['yard_steps']} RK4 steps "
                     f"in registers", cfg["yard_cells"], "", "", "", "", "", "", "", "", "no"))
        md = (head + "Not measured on a GPU yet: this machine has none (" + missing + "). "
              "The cases a run on a machine with an NVIDIA GPU measures:\n\n"
              + H.md_table(("case", "cells"), [r[:2] for r in rows]))
        b.report("gpu", markdown=md, csv=(HEADERS, rows),
                 data=dict(measured=False, reason=missing, env=b.env,
                           cases=[r[0] for r in rows]))
        return 0
    t0 = time.monotonic()
    warm = time.monotonic()
    warm_up(cfg)
    warm = time.monotonic() - warm
    rows, raw = measure(cfg, t0)
    more, more_raw = measure_transient(cfg, t0)
    rows += more
    raw.update(more_raw)
    more, more_raw = registers(cfg, t0)
    rows += more
    raw.update(more_raw)
    row, raw["yardstick"] = yardstick(cfg)
    rows.append(row)
    gpu = device_name()
    md = (head + H.md_table(HEADERS[:8] + ("differ, not flagged", "max strobe diff"),
                            [r[:10] for r in rows])
          + f"\nOn {gpu} and all {os.cpu_count()} logical CPUs of its host; the cells through "
            f"the grid runner (device=\"cuda\" against device=\"cpu\"), transfers included, "
            f"compile excluded (the warm-up, {warm:.0f} s, compiled or loaded every kernel); "
            f"medians of {cfg['repeats']} repeats, or of one for the cases run past half the "
            f"run's time budget ({cfg['budget_s']:.0f} s; cpu_basis says which). "
            f"speedup: CPU time over GPU time. labels_differ: cells whose label or period "
            f"differ between the devices; differ, not flagged: of those, at the smallest "
            f"basin, the cells the uncertainty test (initial states moved by {EPS:g}, on the "
            f"CPU) does not flag. max strobe diff: the largest difference of the "
            f"stroboscopic samples of the cells both devices call periodic (for the spectrum "
            f"and the fragility analysis: the cells whose outcome differs, and the largest "
            f"difference of max |theta| / alpha_s where it does not). The rows 'one "
            f"call': the largest basin in one call of the driver (no chunks), with the "
            f"compiler's choice of registers a thread and with a cap (more threads resident, "
            f"more spilled); labels_differ there counts the cells whose label differs from "
            f"the uncapped call's. Load before: "
            f"{H.load_text()}.\n")
    b.report("gpu", markdown=md, csv=(HEADERS, rows),
             data=dict(measured=True, device=gpu, env=b.env, warm_up_s=warm, raw=raw,
                       rows=[dict(zip(HEADERS, r)) for r in rows]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
