"""How rockjit's grids scale from one thread to all of them, beside a perfectly balanced kernel.

A machine's cores do not each give a full core's speed: clocks drop as more cores run, and
two hardware threads share one core. So the speed-up of rockjit from 1 to t threads is set
beside the *yardstick*'s, measured in the same run at the same thread counts: a compute-bound
parallel kernel in which every cell does the same work in registers (a damped linear oscillator
stepped by RK4, no memory traffic), whose speed-up is what this host's threads can give. The
study's 100 x 100 Housner basin (h/b = 1, alpha = 0.66, omega = 1.3, 500 periods) runs at
each thread count full length and early-stopped: with the default chunks, with one chunk for
the whole grid, and (full length) with chunks of 64 cells, each run as pieces on one thread
each, as many at once as threads (rockjit.grids.runner); and, for comparison, as one call of
the parallel kernel on every cell with all the threads, which waits for its slowest block of
cells. Every case does the same work (the grid, then its attractors) and its labels must equal
the one-thread run's. Compile time is excluded (a warm-up call first).

    python benchmarks/bench_cores.py            # full: 1, 2, 4, ... threads up to all
    python benchmarks/bench_cores.py --quick    # smoke: 20 x 20, 60 periods, 1 repeat

Writes cores.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with --quick,
or --out DIR).
"""

from __future__ import annotations

import contextlib
import math
import sys

import numba
import numpy as np

import _common as H

import rockjit
from rockjit import Block, Classification, Execution, Harmonic, Integration
from rockjit.grids import runner

FULL = dict(grid=100, periods=500, repeats=3, yardstick_s=1.0)
QUICK = dict(grid=20, periods=60, repeats=1, yardstick_s=0.05)
#: The basin's cases: (key, early stopping, chunk: "default", "one" (the whole grid), cells,
#: or "call": one call of the parallel kernel on every cell, all the threads).
CASES = (("full, default chunks", False, "default"), ("full, one chunk", False, "one"),
         ("full, 64-cell chunks", False, 64), ("full, one kernel call", False, "call"),
         ("early-stopped, default chunks", True, "default"),
         ("early-stopped, one kernel call", True, "call"))
HEADERS = ("threads", "case", "median s", "speed-up", "yardstick speed-up",
           "share of the yardstick's", "labels as 1 thread")


def rk4_cell(y, v, n_steps):
    """The yardstick's cell: ``n_steps`` RK4 steps of ``y'' = -y - 0.1 y'`` in registers (plain
    Python, compiled for the CPU here and for the GPU by bench_gpu.py)."""
    h = 0.01
    for _ in range(n_steps):
        k1y, k1v = v, -y - 0.1 * v
        y2, v2 = y + 0.5 * h * k1y, v + 0.5 * h * k1v
        k2y, k2v = v2, -y2 - 0.1 * v2
        y3, v3 = y + 0.5 * h * k2y, v + 0.5 * h * k2v
        k3y, k3v = v3, -y3 - 0.1 * v3
        y4, v4 = y + h * k3y, v + h * k3v
        k4y, k4v = v4, -y4 - 0.1 * v4
        y += h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y)
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
    return y


_cell = numba.njit(cache=True)(rk4_cell)


@numba.njit(parallel=True, cache=True)
def yardstick(n_cells, n_steps, out):
    """Every cell the same work: :func:`rk4_cell` from ``(1 + 1e-9 i, 0)``."""
    for i in numba.prange(n_cells):
        out[i] = _cell(1.0 + 1e-9 * i, 0.0, n_steps)


def thread_counts():
    """1, 2, 4, ... up to numba's threads, the largest included."""
    top = numba.config.NUMBA_NUM_THREADS
    counts = [1 << k for k in range(int(math.log2(top)) + 1)]
    return counts if counts[-1] == top else counts + [top]


def calibrate(n_cells, seconds):
    """Steps per cell that make the yardstick take about ``seconds`` on one thread."""
    out = np.zeros(n_cells)
    numba.set_num_threads(1)
    try:
        yardstick(n_cells, 10, out)  # compiled (or loaded) here
        steps = 200
        while True:
            t, _ = H.timed(yardstick, n_cells, steps, out)
            if t > 0.2 * seconds or steps > 10**8:
                return max(1, int(steps * seconds / t))
            steps *= 4
    finally:
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)


@contextlib.contextmanager
def one_call_per_chunk():
    """Within the block, each chunk runs as one call of the parallel kernel on all the threads
    (no pieces): with one chunk, the whole grid in one call."""
    real = runner.local_plan
    runner.local_plan = lambda threads: (max(1, int(threads)), 1)
    try:
        yield
    finally:
        runner.local_plan = real


def basin(cfg, early_stop, threads, chunk):
    """The basin's labels, flat (the same work in every case: the grid, then its attractors)."""
    n = cfg["grid"] ** 2
    kw = dict(integration=Integration(periods=cfg["periods"]),
              classification=Classification(early_stop=early_stop))
    size = None if chunk == "default" else chunk if isinstance(chunk, int) else n
    ex = Execution(threads=threads, chunk=size)
    with one_call_per_chunk() if chunk == "call" else contextlib.nullcontext():
        return rockjit.basin(Block(1.0), Harmonic(alpha=0.66, omega=1.3), cfg["grid"], **kw,
                             execution=ex).label.ravel()


def measure(cfg):
    """Wall times by ``(threads, case)``, the labels of each, and the yardstick's steps."""
    n = cfg["grid"] ** 2
    steps = calibrate(n, cfg["yardstick_s"])
    out = np.zeros(n)
    for early in (False, True):  # warm: compile or load every kernel before timing
        basin(dict(cfg, grid=4, periods=20), early, 1, "default")
    wall, labels = {}, {}
    for t in thread_counts():
        def yard(t=t):
            numba.set_num_threads(t)
            try:
                yardstick(n, steps, out)
            finally:
                numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        cases = {"yardstick": yard}
        for key, early, chunk in CASES:
            cases[key] = lambda early=early, chunk=chunk, t=t: basin(cfg, early, t, chunk)
        got = H.side_by_side(cases, cfg["repeats"])
        for k, times in got.wall.items():
            wall[(t, k)] = times
            if k != "yardstick":
                labels[(t, k)] = got.result[k]
        print(f"{t} threads: " + ", ".join(f"{k} {H.median(v):.3f} s"
                                           for k, v in got.wall.items()), flush=True)
    return wall, labels, steps


def rows(wall, labels):
    counts = sorted({t for t, _ in wall})
    out = []
    for t in counts:
        ys = H.median(wall[(1, "yardstick")]) / H.median(wall[(t, "yardstick")])
        out.append((t, "yardstick", H.median(wall[(t, "yardstick")]), ys, ys, 1.0, "—"))
        for key, _, _ in CASES:
            s = H.median(wall[(1, key)]) / H.median(wall[(t, key)])
            same = np.array_equal(labels[(t, key)], labels[(1, key)])
            out.append((t, key, H.median(wall[(t, key)]), s, ys, s / ys,
                        "yes" if same else "NO"))
    return out


def plot(table, cfg):
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    keys = ["yardstick"] + [k for k, _, _ in CASES]
    for k in keys:
        pts = [(r[0], r[3]) for r in table if r[1] == k]
        ax.plot(*zip(*pts), marker="o", lw=2.5 if k == "yardstick" else 1.2,
                color="black" if k == "yardstick" else None, label=k)
    top = max(r[0] for r in table)
    ax.plot([1, top], [1, top], ls=":", color="grey", label="threads (ideal)")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log", base=2)
    ax.set_xlabel("threads")
    ax.set_ylabel("speed-up over one thread")
    ax.set_title(f"{cfg['grid']} x {cfg['grid']} basin, {cfg['periods']} periods, beside a "
                 f"balanced compute-bound kernel", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    load0 = H.load_text()
    wall, labels, steps = measure(cfg)
    table = rows(wall, labels)
    top = max(r[0] for r in table)
    n = cfg["grid"] ** 2
    per, at_once = runner.local_plan(top)
    worst = min((r[5] for r in table if r[0] > 1 and r[1] != "yardstick"
                 and "kernel call" not in r[1]), default=math.nan)
    md = (f"### Threads and chunks{H.quick_note(b.quick)}\n\n"
          + H.md_table(HEADERS, table) + "\n"
          + f"The study's {cfg['grid']} x {cfg['grid']} Housner basin (h/b = 1, alpha = 0.66, "
            f"omega = 1.3), {cfg['periods']} periods; median of {cfg['repeats']}, the cases of "
            f"each thread count interleaved, compile excluded. Speed-up: the one-thread time "
            f"over this one, of the same case. The yardstick: {n} cells of {steps} RK4 steps "
            f"each in registers (every cell the same work), its speed-up what this host's "
            f"threads give. The lowest share of the yardstick's speed-up, over every case "
            f"of the grid runner above one thread: {worst:.0%}. At {top} threads the cells "
            f"ran as pieces of {runner.PIECE_MIN} to {runner.PIECE_MAX} cells on {per} thread "
            f"each, {at_once} at once. "
            f"Threading layer: {numba.threading_layer()}. Load average (1, 5, 15 min) at "
            f"the start {load0}, at the end {H.load_text()}: a yardstick that gains little "
            f"from more threads means the host's cores were busy with other work. "
            f"{H.env_line(b.env)}\n")
    data = dict(rows=[dict(zip(HEADERS, r)) for r in table], env=b.env, config=cfg,
                yardstick_steps=steps, threading_layer=numba.threading_layer(),
                raw_wall_s={f"{t}|{k}": v for (t, k), v in wall.items()})
    b.report("cores", markdown=md, csv=(HEADERS, table), data=data,
             figures=[("cores.png", plot(table, cfg), 120)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
